// A depth prior on the compositing weights of one ray: the weighted depth's first moment about a
// target depth t*,
//   E = sum_i w_i (t_i - t*),   L = E^2,   dL/dw_k = 2 E (t_k - t*).
// L is zero when the ray's weight is centred on t* (whatever its opacity, which is left to the
// photometric and mask losses). Chain dL/dw to sigma through CompositeBackward's d_weights.
#pragma once

namespace icef {

// One ray: weights [n], t [n]. Returns L and adds scale * dL/dw to d_weights [n].
template <typename T>
T DepthMomentLossRay(int n, const T* weights, const T* t, T target, T scale, T* d_weights) {
  T e = T(0);
  for (int i = 0; i < n; ++i) e += weights[i] * (t[i] - target);
  for (int i = 0; i < n; ++i) d_weights[i] += scale * T(2) * e * (t[i] - target);
  return e * e;
}

}  // namespace icef
