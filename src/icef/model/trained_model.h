// A trained AvatarModel loaded for inference (icef render, icef eval): from a checkpoint file (or
// MODEL_DIR/checkpoint.icef, io/checkpoint.h's container), the model part of the stored run config
// ("model" block), the dataset-derived setup, the parameters and the occupancy grid, with the
// coarse-to-fine schedules at the checkpoint's step. The optimiser and trainer state are not
// read; train/model_io.h's LoadModel builds on this and adds them for training and --resume.
//
// Inference-only model keys (InferenceModelKeys()) may be overridden before the model is built
// (`--set model.render.supersample=4`); keys that fix the architecture or the trained parameters
// may not.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "icef/core/parallel.h"
#include "icef/core/status.h"
#include "icef/io/checkpoint.h"
#include "icef/model/avatar_model.h"
#include "icef/model/model_config.h"

namespace icef {

// The checkpoint file of a model directory.
inline constexpr const char* kCheckpointFile = "checkpoint.icef";

// Largest step count a checkpoint may hold (exact in a double, far beyond any real run).
inline constexpr int64_t kMaxCheckpointStep = int64_t(1) << 53;

struct TrainedModel {
  ModelConfig config;                  // the checkpoint's "model" block, inference overrides applied
  std::unique_ptr<AvatarModel> model;  // built from `config`, parameters and occupancy grid loaded
  int64_t step = 0;                    // optimiser steps the checkpoint was written after
};

// `given` when it is a file, MODEL_DIR/checkpoint.icef when it is a directory; an error naming the
// path when there is no checkpoint.
Result<std::filesystem::path> ResolveCheckpointPath(const std::filesystem::path& given);

// The checkpoint's "trainer" section as far as inference needs it: step (an integer in
// [0, kMaxCheckpointStep]) and config_hash, which must equal the hash of `config_text`, the
// checkpoint's "config" section, byte for byte as stored. Errors name `origin` and the field
// ("model/checkpoint.icef: trainer.step: ...").
Result<int64_t> ParseCheckpointStep(const std::string& trainer_text, const std::string& config_text,
                                    const std::string& origin);

// The model keys that change how a trained model is rendered but not its architecture or
// parameters: render.supersample, sampler.num_samples, render.transmittance_eps, bf16_inference.
const std::vector<std::string>& InferenceModelKeys();

// Applies one "model.KEY=VALUE" override of an inference-only key (VALUE as for `icef train
// --set`, io/config_override.h) to `config`. Any other key is refused with one line naming it.
Status ApplyInferenceOverride(const std::string& assignment, ModelConfig* config);

// Reads a checkpoint file, or MODEL_DIR/checkpoint.icef when given a directory, applies
// `overrides` ("model.KEY=VALUE", see ApplyInferenceOverride) and builds the model. Errors name
// the file and what is wrong (corrupt, truncated, from another version, missing section, field).
Result<TrainedModel> LoadTrainedModel(const std::filesystem::path& path, const Executor& executor,
                                      const std::vector<std::string>& overrides = {});

// The same from a checkpoint already read; `origin` (its path) prefixes every error.
Result<TrainedModel> LoadTrainedModel(const Checkpoint& checkpoint, const std::string& origin,
                                      const Executor& executor,
                                      const std::vector<std::string>& overrides = {});

}  // namespace icef
