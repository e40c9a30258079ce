// Distortion loss of mip-NeRF 360 (Barron et al. 2022, eq. 15) on the compositing weights of one
// ray, with intervals [t_i - dt_i/2, t_i + dt_i/2] (RaySamples layout, sorted by t):
//   L = sum_{i,j} w_i w_j |t_i - t_j| + 1/3 sum_i w_i^2 dt_i
// computed in O(n) with prefix sums. It pulls the weight of a ray together into one compact
// interval (fewer floaters). Distances are in world units; callers wanting mip-NeRF 360's
// normalised distances scale t and dt (and the loss weight) themselves.
// Backward: dL/dw_k = 2 sum_j w_j |t_k - t_j| + 2/3 w_k dt_k; chain it to sigma through
// CompositeBackward's d_weights.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "icef/core/parallel.h"

namespace icef {

// One ray: weights [n], t [n] (non-decreasing), dt [n]. Returns the loss.
template <typename T>
T DistortionLossRay(int n, const T* weights, const T* t, const T* dt) {
  T w_before = T(0), wt_before = T(0), pair = T(0), self = T(0);
  for (int i = 0; i < n; ++i) {
    pair += weights[i] * (t[i] * w_before - wt_before);
    w_before += weights[i];
    wt_before += weights[i] * t[i];
    self += weights[i] * weights[i] * dt[i];
  }
  return T(2) * pair + self / T(3);
}

// Overwrites d_weights [n] with scale * dL/dw.
template <typename T>
void DistortionLossRayBackward(int n, const T* weights, const T* t, const T* dt, T scale, T* d_weights) {
  T w_total = T(0), wt_total = T(0);
  for (int i = 0; i < n; ++i) {
    w_total += weights[i];
    wt_total += weights[i] * t[i];
  }
  T w_before = T(0), wt_before = T(0);
  for (int i = 0; i < n; ++i) {
    const T w_after = w_total - w_before - weights[i];
    const T wt_after = wt_total - wt_before - weights[i] * t[i];
    const T abs_sum = t[i] * w_before - wt_before + wt_after - t[i] * w_after;
    d_weights[i] = scale * (T(2) * abs_sum + T(2) / T(3) * weights[i] * dt[i]);
    w_before += weights[i];
    wt_before += weights[i] * t[i];
  }
}

// Batched over rays in RaySamples layout: returns the mean loss over rays (0 when there are none)
// and, when d_weights is non-null, resizes it to [n] and writes d(mean loss)/dw scaled by `scale`.
template <typename T>
T DistortionLoss(std::span<const T> weights, std::span<const T> t, std::span<const T> dt,
                 std::span<const int32_t> ray_offset, std::span<const int32_t> ray_count, T scale,
                 const Executor& executor, std::vector<T>* d_weights);

}  // namespace icef
