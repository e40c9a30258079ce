// A depth prior on the compositing weights of one ray: the weighted depth's first moment about a
// target depth t*, each sample's offset clamped to a window of half-width m and samples farther
// than a reach r behind t* left out,
//   d_i = clamp(t_i - t*, -m, m) for t_i - t* <= r, else 0;   E = sum_i w_i d_i;
//   L = E^2,   dL/dw_k = 2 E d_k.
// L is zero when the ray's weight is centred on t* (whatever its opacity, which is left to the
// photometric and mask losses). Without the window and the reach, the little weight a ray keeps
// where it leaves the head (behind the face, a head's depth from t*) has the largest lever of all,
// and the prior erodes the far side of the head, which few other rays see. m <= 0: no window;
// r <= 0: no reach. Chain dL/dw to sigma through CompositeBackward's d_weights.
#pragma once

namespace icef {

// The shape of the prior along the ray: window half-width m and reach r (same units as t).
template <typename T>
struct DepthWindow {
  T window = T(0);
  T reach = T(0);
  // One sample's offset from the target.
  T Offset(T t, T target) const {
    const T d = t - target;
    if (reach > T(0) && d > reach) return T(0);
    if (window <= T(0)) return d;
    return d > window ? window : (d < -window ? -window : d);
  }
};

// One ray: weights [n], t [n]. Returns L and adds scale * dL/dw to d_weights [n].
template <typename T>
T DepthMomentLossRay(int n, const T* weights, const T* t, T target, const DepthWindow<T>& shape, T scale,
                     T* d_weights) {
  T e = T(0);
  for (int i = 0; i < n; ++i) e += weights[i] * shape.Offset(t[i], target);
  for (int i = 0; i < n; ++i) d_weights[i] += scale * T(2) * e * shape.Offset(t[i], target);
  return e * e;
}

}  // namespace icef
