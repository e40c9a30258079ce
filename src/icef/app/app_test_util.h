// Test helpers for the app module: a trained-model checkpoint of the tiny model (no training; the
// initial parameters), as `icef train` would have written it.
#pragma once

#include <filesystem>

#include "icef/model/model_test_util.h"
#include "icef/testing/tiny_dataset.h"
#include "icef/train/model_io.h"

namespace icef::testing_app {

// Writes dir/checkpoint.icef of the tiny "icef" model on `setup` (the tiny setup by default); returns dir.
inline std::filesystem::path WriteTinyModelDir(const std::filesystem::path& dir,
                                               const ModelSetup& setup = testing_model::TinySetup()) {
  const Executor executor(1);
  RunConfig config;
  config.model = testing_model::TinyModelConfig("icef");
  config.train.steps = 10;
  auto model = AvatarModel::Create(config.model, setup, executor);
  ICEF_CHECK(model.ok(), model.status().message());
  std::filesystem::create_directories(dir);
  TrainerState state;
  state.step = 10;
  ICEF_CHECK(SaveCheckpoint(dir / kCheckpointFile, config, **model, nullptr, state).ok());
  return dir;
}

}  // namespace icef::testing_app
