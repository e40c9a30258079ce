// Model directories and checkpoints. A model directory holds
//   checkpoint.icef   parameters, optimiser state, occupancy grid, trainer state, resolved config and
//                     dataset-derived setup (io/checkpoint.h container: versioned, checksummed,
//                     written atomically)
//   config.json       the effective run config (also inside the checkpoint)
//   summary.json      written when training ends
//   train_log.jsonl   one JSON line per logged step
// Rendering and evaluation rebuild everything from checkpoint.icef alone, through
// model/trained_model.h (the model without the optimiser and trainer state); LoadModel here builds
// on it for training and --resume.
#pragma once

#include <filesystem>
#include <memory>
#include <string>

#include "icef/io/json_util.h"
#include "icef/model/avatar_model.h"
#include "icef/model/trained_model.h"
#include "icef/nn/adam.h"
#include "icef/train/train_config.h"

namespace icef {

struct TrainerState {
  int64_t step = 0;            // completed optimiser steps
  double elapsed_seconds = 0;  // training wall time so far (over all resumed runs)
  int64_t skipped_steps = 0;   // steps skipped for a non-finite loss or gradient (train.on_nonfinite = skip)
  std::vector<std::string> log;  // train_log.jsonl lines so far
};

Status SaveCheckpoint(const std::filesystem::path& path, const RunConfig& config, const AvatarModel& model,
                      const nn::Adam* adam, const TrainerState& state);

struct LoadedModel {
  RunConfig config;
  std::unique_ptr<AvatarModel> model;
  std::string adam_state;  // serialised Adam state (empty when the checkpoint has none)
  TrainerState state;
};

// The checkpoint's "trainer" section: step (an integer in [0, kMaxCheckpointStep]), elapsed_seconds
// (finite, >= 0), skipped_steps (optional, in [0, step]) and config_hash, which must equal the hash
// of `config_text`, the checkpoint's "config" section, byte for byte as stored (step and
// config_hash: model/trained_model.h's ParseCheckpointStep). Errors name `origin` and the field
// ("model/checkpoint.icef: trainer.step: ...").
Result<TrainerState> ParseTrainerSection(const std::string& trainer_text, const std::string& config_text,
                                         const std::string& origin);

// Reads a checkpoint file, or MODEL_DIR/checkpoint.icef when given a directory: the whole run config,
// the trainer state, the Adam state and the model (LoadTrainedModel). Errors name the file and what
// is wrong (corrupt, truncated, from another version, missing section). Inference needs only
// LoadTrainedModel.
Result<LoadedModel> LoadModel(const std::filesystem::path& path, const Executor& executor);

}  // namespace icef
