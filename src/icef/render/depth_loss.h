// A depth prior on the compositing weights of one ray: the weighted depth's first moment about a
// target depth t*, with each sample's offset clamped to a window of half-width m,
//   c_i = clamp(t_i - t*, -m, m),   E = sum_i w_i c_i,   L = E^2,   dL/dw_k = 2 E c_k.
// L is zero when the ray's weight is centred on t*. Without the window, the little weight a ray
// keeps where it leaves the head (behind the face, a head's depth from t*) has the largest lever
// of all, and the prior erodes the far side of the head, which few other rays see.
//
// With a reach r, what lies beyond it (weight farther than r behind t*, and the light that passes
// through the whole ray, 1 - sum_i w_i) counts as one termination at the reach, offset q = c(r):
//   E = q (1 - sum_{in reach} w_i) + sum_{in reach} w_i c_i,   dL/dw_k = 2 E (c_k - q) in reach, 0 beyond.
// Weight beyond the reach then pulls on nothing, so the far side of the head is left alone, and a
// ray cannot meet the prior by turning transparent: a hole costs q^2. m <= 0: no window; r <= 0:
// no reach (the transmitted light then costs nothing, and opacity is left to the photometric and
// mask losses). Chain dL/dw to sigma through CompositeBackward's d_weights.
#pragma once

namespace icef {

// The shape of the prior along the ray: window half-width m and reach r (same units as t).
template <typename T>
struct DepthWindow {
  T window = T(0);
  T reach = T(0);

  T Clamp(T d) const {
    if (window <= T(0)) return d;
    return d > window ? window : (d < -window ? -window : d);
  }
  // The offset of everything beyond the reach (0 without one).
  T Beyond() const { return reach > T(0) ? Clamp(reach) : T(0); }
  // A sample's derivative dE/dw: its offset less the offset of what lies beyond the reach.
  T Lever(T t, T target) const {
    const T d = t - target;
    if (reach > T(0) && d > reach) return T(0);
    return Clamp(d) - Beyond();
  }
};

// One ray: weights [n], t [n]. Returns L and adds scale * dL/dw to d_weights [n].
template <typename T>
T DepthMomentLossRay(int n, const T* weights, const T* t, T target, const DepthWindow<T>& shape, T scale,
                     T* d_weights) {
  T e = shape.Beyond();
  for (int i = 0; i < n; ++i) e += weights[i] * shape.Lever(t[i], target);
  for (int i = 0; i < n; ++i) d_weights[i] += scale * T(2) * e * shape.Lever(t[i], target);
  return e * e;
}

}  // namespace icef
