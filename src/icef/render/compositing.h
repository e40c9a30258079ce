// Volume compositing (docs/design.md §3), forward and hand-written backward, templated on the scalar
// type (float for training, double for gradient checks). Per ray with samples i = 0..n-1 (sorted
// by t, as RaySamples lays them out):
//   alpha_i = 1 - exp(-sigma_i dt_i),  T_i = prod_{j<i} (1 - alpha_j),  w_i = T_i alpha_i
//   color   = sum_i w_i rgb_i + T_m background        (T_m: transmittance after the last used sample)
//   opacity = sum_i w_i = 1 - T_m
//   depth   = sum_i w_i t_i                             (expected depth; the background adds 0)
// Early termination: marching stops after the first sample i whose T_{i+1} < transmittance_eps;
// m = i + 1 samples are "used", later samples get weight 0. The backward treats m as fixed (it
// is recorded by the forward in num_used), so it is the exact derivative of the function the
// forward computed: samples past m get zero gradient, and the residual T_m still multiplies the
// background. Set transmittance_eps = 0 to disable termination.
//
// Backward: given per-ray dL/dcolor [3], dL/dopacity, dL/ddepth and optionally per-sample
// dL/dweight (from an auxiliary loss on the weights, e.g. DistortionLoss), produces dL/dsigma and
// dL/drgb per sample. With v_j = dL/dcolor . rgb_j + dL/ddepth t_j + dL/dw_j and
// b = dL/dcolor . background - dL/dopacity:
//   dL/drgb_i   = dL/dcolor w_i
//   dL/dsigma_i = dt_i (T_{i+1} v_i - sum_{j>i} w_j v_j - T_m b)
#pragma once

#include <cmath>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "icef/core/parallel.h"
#include "icef/core/status.h"

namespace icef {

struct CompositeOptions {
  double transmittance_eps = 1e-4;  // stop marching a ray once its transmittance falls below this (0 = never)

  bool operator==(const CompositeOptions&) const = default;
  Status Validate() const;
  std::string ToString() const;
};

// Per-ray forward. sigma [n], rgb [n,3], t [n], dt [n], background [3]. Writes color [3], opacity,
// depth, and weights [n] when non-null (zero past the used samples). Returns the number of used
// samples m.
template <typename T>
int CompositeRayForward(int n, const T* sigma, const T* rgb, const T* t, const T* dt, const T* background,
                        T transmittance_eps, T* color, T* opacity, T* depth, T* weights) {
  T trans = T(1);
  T c[3] = {T(0), T(0), T(0)};
  T d = T(0);
  int m = 0;
  for (; m < n;) {
    const T alpha = T(1) - std::exp(-sigma[m] * dt[m]);
    const T w = trans * alpha;
    for (int k = 0; k < 3; ++k) c[k] += w * rgb[3 * m + k];
    d += w * t[m];
    if (weights) weights[m] = w;
    trans *= T(1) - alpha;
    ++m;
    if (trans < transmittance_eps) break;
  }
  if (weights)
    for (int i = m; i < n; ++i) weights[i] = T(0);
  for (int k = 0; k < 3; ++k) color[k] = c[k] + trans * background[k];
  *opacity = T(1) - trans;
  *depth = d;
  return m;
}

// The number of samples CompositeRayForward uses (its return value m) from sigma [n] and dt [n]
// alone, by the same arithmetic: what a caller needs before it computes any colour, since the
// samples past m add nothing to the ray nor to any gradient through it.
template <typename T>
int CompositeRayUsed(int n, const T* sigma, const T* dt, T transmittance_eps) {
  T trans = T(1);
  for (int m = 0; m < n;) {
    const T alpha = T(1) - std::exp(-sigma[m] * dt[m]);
    trans *= T(1) - alpha;
    ++m;
    if (trans < transmittance_eps) return m;
  }
  return n;
}

// Per-ray backward for the first m = num_used samples (from the forward). d_weights may be null.
// Overwrites d_sigma [n] and d_rgb [n,3] (zero past m).
template <typename T>
void CompositeRayBackward(int n, int num_used, const T* sigma, const T* rgb, const T* t, const T* dt,
                          const T* background, const T* d_color, T d_opacity, T d_depth, const T* d_weights,
                          T* d_sigma, T* d_rgb) {
  const int m = num_used;
  // Pass 1: total = sum_j w_j v_j + T_m b.
  T trans = T(1);
  T total = T(0);
  for (int i = 0; i < m; ++i) {
    const T alpha = T(1) - std::exp(-sigma[i] * dt[i]);
    const T w = trans * alpha;
    T v = d_depth * t[i] + (d_weights ? d_weights[i] : T(0));
    for (int k = 0; k < 3; ++k) v += d_color[k] * rgb[3 * i + k];
    total += w * v;
    trans *= T(1) - alpha;
  }
  T b = -d_opacity;
  for (int k = 0; k < 3; ++k) b += d_color[k] * background[k];
  total += trans * b;
  // Pass 2: suffix_i = total - prefix_{<=i}.
  trans = T(1);
  T prefix = T(0);
  for (int i = 0; i < m; ++i) {
    const T alpha = T(1) - std::exp(-sigma[i] * dt[i]);
    const T w = trans * alpha;
    const T next_trans = trans * (T(1) - alpha);
    T v = d_depth * t[i] + (d_weights ? d_weights[i] : T(0));
    for (int k = 0; k < 3; ++k) {
      v += d_color[k] * rgb[3 * i + k];
      d_rgb[3 * i + k] = d_color[k] * w;
    }
    prefix += w * v;
    d_sigma[i] = dt[i] * (next_trans * v - (total - prefix));
    trans = next_trans;
  }
  for (int i = m; i < n; ++i) {
    d_sigma[i] = T(0);
    for (int k = 0; k < 3; ++k) d_rgb[3 * i + k] = T(0);
  }
}

// Batched inputs: samples of all rays in RaySamples layout.
template <typename T>
struct CompositeInputs {
  std::span<const T> sigma;             // [n]
  std::span<const T> rgb;               // [n, 3]
  std::span<const T> t;                 // [n]
  std::span<const T> dt;                // [n]
  std::span<const int32_t> ray_offset;  // [num_rays]
  std::span<const int32_t> ray_count;   // [num_rays]
  std::span<const T> background;        // [3] shared by all rays, or [num_rays, 3] per ray
};

template <typename T>
struct CompositeOutputs {
  std::vector<T> color;           // [num_rays, 3]
  std::vector<T> opacity;         // [num_rays]
  std::vector<T> depth;           // [num_rays]
  std::vector<T> weights;         // [n]
  std::vector<int32_t> num_used;  // [num_rays] samples used before early termination
};

// Incoming gradients; empty spans mean zero.
template <typename T>
struct CompositeOutputGradients {
  std::span<const T> d_color;    // [num_rays, 3]
  std::span<const T> d_opacity;  // [num_rays] or empty
  std::span<const T> d_depth;    // [num_rays] or empty
  std::span<const T> d_weights;  // [n] or empty
};

template <typename T>
void CompositeForward(const CompositeInputs<T>& in, const CompositeOptions& options, const Executor& executor,
                      CompositeOutputs<T>* out);

// Needs the forward's num_used. Resizes and overwrites d_sigma [n], d_rgb [n, 3].
template <typename T>
void CompositeBackward(const CompositeInputs<T>& in, const CompositeOutputs<T>& forward,
                       const CompositeOutputGradients<T>& grads, const Executor& executor,
                       std::vector<T>* d_sigma, std::vector<T>* d_rgb);

}  // namespace icef
