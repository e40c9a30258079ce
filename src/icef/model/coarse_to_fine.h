// Coarse-to-fine schedules: how much of the deformation encoding's frequencies and of the static
// field's hash-grid levels are switched on after a number of training steps. Training sets them
// every step (train.anneal_steps, train.grid_anneal_steps); a loaded model gets the values of the
// step its checkpoint was written at, so every later render matches the trained model.
#pragma once

#include <cstdint>
#include <vector>

#include "icef/model/model_config.h"

namespace icef {

// The defaults of train.anneal_steps and train.grid_anneal_steps (TrainConfig uses them; a
// checkpoint config without the keys gets them too).
inline constexpr int kDefaultAnnealSteps = 500;
inline constexpr int kDefaultGridAnnealSteps = 0;

// The deformation encoding's coarse-to-fine parameter alpha after `step` steps (all
// model.deformation.num_frequencies on once step >= anneal_steps, or when anneal_steps is 0).
double DeformationAnnealing(const ModelConfig& model, int anneal_steps, int64_t step);

// Per-level weights of the static field's hash grid after `step` steps (all ones once step >=
// grid_anneal_steps, or when it is 0).
std::vector<float> GridLevelWeights(const ModelConfig& model, int grid_anneal_steps, int64_t step);

}  // namespace icef
