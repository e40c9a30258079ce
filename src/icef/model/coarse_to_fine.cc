#include "icef/model/coarse_to_fine.h"

#include <algorithm>
#include <cmath>

namespace icef {

double DeformationAnnealing(const ModelConfig& model, int anneal_steps, int64_t step) {
  const double n = model.deformation.num_frequencies;
  return anneal_steps > 0 ? std::min(n, n * double(step) / anneal_steps) : n;
}

std::vector<float> GridLevelWeights(const ModelConfig& model, int grid_anneal_steps, int64_t step) {
  const int levels = model.static_field.grid.num_levels, anneal = grid_anneal_steps;
  std::vector<float> w(levels, 1.f);
  if (anneal <= 0 || step >= anneal) return w;
  constexpr double kFirst = 4;  // levels on from the start
  const double alpha = kFirst + (levels - kFirst) * double(step) / anneal;
  for (int l = 0; l < levels; ++l) {
    const double x = std::clamp(alpha - l, 0.0, 1.0);
    w[l] = static_cast<float>(0.5 * (1.0 - std::cos(M_PI * x)));
  }
  return w;
}

}  // namespace icef
