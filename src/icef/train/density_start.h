// A start for the static field's density seeded from the fitted face model (train.density_start_steps):
// before training, the density is fitted for a few steps to the fitted head's neutral surface,
// so the field starts with the head already in place instead of nearly empty everywhere.
//
// Why: the field starts nearly empty (sigma = exp(h + density_bias), bias -4) and the gradient on a
// density is proportional to the density, so how long the face takes to become opaque depends on
// the random draw; late starts carve grooves that held-out views see
// (docs/results/density_bias_start/). A uniform higher bias removes the late start but adds density
// everywhere; this start adds it only where the face model says the head is.
//
// Target log-density at a canonical point x (world frame; the prior's canonical space is the
// neutral head in the dataset's world):
//   d(x) = Distance_neutral(S x)                     signed distance bound in head units, S = head_from_world
//   t(x) = bias + (inside - bias) * sigmoid(-(d(x) + erosion) / width)
// The head is eroded: the fit pins down what the landmarks see, not the cranium or the neck, and
// density seeded outside the subject's surface can stay as a shell that held-out views see;
// density inside it is hidden. Each step draws `points` uniform points of the aabb and takes one
// Adam step on mean (log sigma(x) - t(x))^2 over the static field's grid and density MLP.
#pragma once

#include <cmath>
#include <cstdint>

#include "icef/core/parallel.h"
#include "icef/core/status.h"
#include "icef/face/face_fit.h"
#include "icef/model/avatar_model.h"

namespace icef {

struct DensityStartOptions {
  int steps = 0;                   // 0 = no seeded start
  int points = 8192;               // points per step
  float inside_log_density = 3.f;  // log sigma the target reaches inside the eroded head
  float width = 0.01f;             // head units over which the target crosses the eroded surface
  float erosion = 0.04f;           // head units the seeded head lies inside the fitted surface
  double learning_rate_grid = 1e-2;
  double learning_rate_mlp = 1e-3;
};

// The start's loss over n points, mean (log sigma - t)^2, and its gradient d_sigma (sigma > 0).
// A template so that its gradient check runs in double precision.
template <typename T>
T LogDensityLoss(int64_t n, const T* sigma, const T* targets, T* d_sigma) {
  T sum = 0;
  for (int64_t i = 0; i < n; ++i) {
    const T err = std::log(sigma[i]) - targets[i];
    sum += err * err;
    d_sigma[i] = T(2) * err / (T(n) * sigma[i]);
  }
  return sum / T(n);
}

// The target log-density t(x) of the header comment for `count` world points [count, 3].
void DensityStartTargets(const face::FaceFit& fit, float density_bias, const DensityStartOptions& options,
                         int64_t count, const float* positions, float* targets, const Executor& executor);

// Fits the model's static-field density to the targets for options.steps Adam steps of its own
// (the store's gradients are used and left zero; no other block moves). Returns the final mean
// squared log-density error. Deterministic in `seed` and the thread count.
Result<double> SeedDensityFromFaceModel(const face::FaceFit& fit, const DensityStartOptions& options,
                                        uint64_t seed, AvatarModel* model, const Executor& executor);

}  // namespace icef
