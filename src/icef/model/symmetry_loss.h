// Left-right symmetry prior of the static field (a few-shot prior: K views of a face see each
// side from few angles, the mirror image of one side is good evidence for the other). For m
// canonical-space samples x_j and their mirror images x'_j = P x_j across the face's symmetry
// plane (field/symmetry_plane.h), with view directions mirrored alike (a symmetric scene has
// c(P x, P d) = c(x, d)):
//   alpha_j = 1 - exp(-sigma_j dt_j),  alpha'_j = 1 - exp(-sigma'_j dt_j)
//   L_sym = (1/m) sum_j (alpha_j - alpha'_j)^2  +  colour (1/m) sum_j [alpha_j alpha'_j] ||c_j - c'_j||^2
// Opacities rather than densities are compared, so two solid points agree however large their
// densities; the colour term's weight [alpha_j alpha'_j] is held constant (it only asks the two
// sides to agree in colour where both are matter, and never changes the geometry). Both sides get
// gradients: the prior is soft, the photometric loss overrules it where the views disagree.
#pragma once

#include <cmath>
#include <cstdint>

namespace icef {

// sigma_a, sigma_b, dt [m]; rgb_a, rgb_b [m, 3]. Returns L_sym; writes scale * dL/d(inputs) into
// d_sigma_a, d_sigma_b [m] and d_rgb_a, d_rgb_b [m, 3] (OVERWRITTEN) unless d_sigma_a is null.
template <typename T>
T SymmetryLoss(int64_t m, const T* sigma_a, const T* rgb_a, const T* sigma_b, const T* rgb_b, const T* dt,
               T colour, T scale, T* d_sigma_a, T* d_rgb_a, T* d_sigma_b, T* d_rgb_b) {
  if (m == 0) return T(0);
  T loss = T(0);
  const T g = T(2) * scale / T(m);
  for (int64_t j = 0; j < m; ++j) {
    const T ta = std::exp(-sigma_a[j] * dt[j]), tb = std::exp(-sigma_b[j] * dt[j]);
    const T diff = tb - ta;  // alpha_a - alpha_b
    const T both = (T(1) - ta) * (T(1) - tb);
    T colour_sq = T(0);
    for (int c = 0; c < 3; ++c) {
      const T e = rgb_a[3 * j + c] - rgb_b[3 * j + c];
      colour_sq += e * e;
      if (d_sigma_a) {
        d_rgb_a[3 * j + c] = g * colour * both * e;
        d_rgb_b[3 * j + c] = -g * colour * both * e;
      }
    }
    loss += diff * diff + colour * both * colour_sq;
    if (d_sigma_a) {
      d_sigma_a[j] = g * diff * dt[j] * ta;
      d_sigma_b[j] = -g * diff * dt[j] * tb;
    }
  }
  return loss / T(m);
}

}  // namespace icef
