// Test helpers for the app module: a trained-model checkpoint of the tiny model (no training; the
// initial parameters), as `icef train` would have written it.
#pragma once

#include <filesystem>
#include <random>
#include <string>

#include "icef/model/model_test_util.h"
#include "icef/testing/tiny_dataset.h"
#include "icef/train/model_io.h"

namespace icef::testing_app {

// Writes dir/checkpoint.icef of the tiny model of `method` on `setup` (the tiny setup by default);
// returns dir. noise > 0: the static field's parameters get N(0, noise) added (seeded), so that its
// density varies over space as a trained model's does (the initial one is the same everywhere); the
// deformation's stay as initialised (near zero, as a trained residual is small).
inline std::filesystem::path WriteTinyModelDir(const std::filesystem::path& dir,
                                               const ModelSetup& setup = testing_model::TinySetup(),
                                               const std::string& method = "icef", float noise = 0.f) {
  const Executor executor(1);
  RunConfig config;
  config.model = testing_model::TinyModelConfig(method);
  config.train.steps = 10;
  auto model = AvatarModel::Create(config.model, setup, executor);
  ICEF_CHECK(model.ok(), model.status().message());
  if (noise > 0.f) {
    std::mt19937 rng(7);
    std::normal_distribution<float> normal(0.f, noise);
    nn::ParameterStore& store = (*model)->store();
    for (int b = 0; b < store.num_blocks(); ++b)
      if (store.block(b).name.starts_with("static/"))
        for (float& p : store.params(b)) p += normal(rng);
  }
  std::filesystem::create_directories(dir);
  TrainerState state;
  state.step = 10;
  ICEF_CHECK(SaveCheckpoint(dir / kCheckpointFile, config, **model, nullptr, state).ok());
  return dir;
}

}  // namespace icef::testing_app
