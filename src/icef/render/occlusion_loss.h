// Occlusion sparsity prior: density behind what a training ray has already hit is invisible in
// every training view, so nothing but the network's extrapolation puts it there, and it shows up
// as floaters from new viewpoints. For one ray with samples i (sorted by t), compositing weights
// w_i and opacities alpha_i = 1 - exp(-sigma_i dt_i):
//   L = sum_i o_i alpha_i,   o_i = sum_{j<i} w_j  (= 1 - T_i, the share of the ray already absorbed)
// The occlusion o_i is held constant (stop-gradient): the prior only ever lowers density that is
// already hidden, it never pays the ray to become more transparent in front. alpha saturates, so
// a solid interior costs at most its sample count and is not hollowed out; thin haze behind the
// surface is what the gradient dL/dsigma_i = o_i dt_i exp(-sigma_i dt_i) removes.
// With per-sample factors m_i (e.g. the expression-region mask M at each sample) the prior acts
// where they are non-zero only: L = sum_i m_i o_i alpha_i.
#pragma once

#include <cmath>
#include <cstdint>

namespace icef {

// One ray: weights, sigma, dt [n], and the factors m [n] (null: 1 everywhere). Returns the loss;
// ADDS scale * dL/dsigma to d_sigma [n] when d_sigma is not null.
template <typename T>
T OcclusionLossRay(int n, const T* weights, const T* sigma, const T* dt, T scale, T* d_sigma,
                   const T* m = nullptr) {
  T absorbed = T(0), loss = T(0);
  for (int i = 0; i < n; ++i) {
    const T held = m ? absorbed * m[i] : absorbed;
    const T transmit = std::exp(-sigma[i] * dt[i]);
    loss += held * (T(1) - transmit);
    if (d_sigma) d_sigma[i] += scale * held * dt[i] * transmit;
    absorbed += weights[i];
  }
  return loss;
}

}  // namespace icef
