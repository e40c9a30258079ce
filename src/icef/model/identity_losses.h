// The identity-preservation terms of docs/design.md §2, on per-sample warp offsets g = D_phi(x) - x
// (world frame) and mask values M(x) at observation-space samples x. Offsets are measured in
// half-extent units of the aabb (u = g / half_extent per axis), so the weights do not depend on
// the scene's scale.
//
//   L_id     = (1/n) sum_i (1 - M_i) ||u_i||^2
//   L_smooth = (1/m) sum_j w_j 3 ||(u(x_j + eps e_j) - u(x_j)) / eps||^2,  w_j = 4 M_j (1 - M_j)
// L_smooth estimates E[w_b ||J_x D - I||_F^2]: for a random unit e, E ||J e||^2 = ||J||_F^2 / 3,
// and J e is taken by a forward difference of the warp in half-extent units.
// Both return the loss and write scale * dL/d(offsets) (world frame).
#pragma once

#include <cstdint>

namespace icef {

// offsets, d_offsets [n, 3]; mask [n]; inv_half2[a] = 1 / half_extent[a]^2. d_offsets is ADDED to.
template <typename T>
T IdentityLoss(int64_t n, const T* offsets, const float* mask, const T inv_half2[3], T scale, T* d_offsets) {
  if (n == 0) return T(0);
  T loss = T(0);
  const T g_scale = T(2) * scale / T(n);
  for (int64_t i = 0; i < n; ++i) {
    const T w = T(1) - T(mask[i]);
    for (int a = 0; a < 3; ++a) {
      const T o = offsets[3 * i + a];
      loss += w * o * o * inv_half2[a];
      if (d_offsets) d_offsets[3 * i + a] += g_scale * w * o * inv_half2[a];
    }
  }
  return loss / T(n);
}

// Boundary weight w_b = 4 M (1 - M).
inline float BoundaryWeight(float m) { return 4.f * m * (1.f - m); }

// offsets [2m, 3]: rows 0..m-1 at x_j, rows m..2m-1 at x_j + eps e_j (e_j in half-extent units);
// weights [m] = w_b; half[a] = half-extent. d_offsets [2m, 3] is OVERWRITTEN.
template <typename T>
T SmoothnessLoss(int64_t m, const T* offsets, const float* weights, const T half[3], T eps, T scale,
                 T* d_offsets) {
  if (m == 0) return T(0);
  T loss = T(0);
  const T g_scale = scale * T(6) / (T(m) * eps * eps);
  for (int64_t j = 0; j < m; ++j) {
    T s = T(0);
    for (int a = 0; a < 3; ++a) {
      const T diff = (offsets[3 * (m + j) + a] - offsets[3 * j + a]) / half[a];
      s += diff * diff;
      if (d_offsets) {
        const T g = g_scale * T(weights[j]) * diff / half[a];
        d_offsets[3 * (m + j) + a] = g;
        d_offsets[3 * j + a] = -g;
      }
    }
    loss += T(weights[j]) * T(3) * s / (eps * eps);
  }
  return loss / T(m);
}

}  // namespace icef
