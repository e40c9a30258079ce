// Signed-distance primitives and smooth blending operators for the face model (all in head
// units, float). The ellipsoid distance is iq's first-order bound, not exact; callers sphere-trace
// with a step factor < 1.
#pragma once

#include <algorithm>
#include <cmath>

#include "icef/math/types.h"

namespace icef::face {

// The Euclidean length as std::sqrt of the squared norm: the same value as Eigen's norm(), which
// takes the square root through an SSE intrinsic that a loop over points cannot vectorise.
inline float Length(const Vec3f& p) { return std::sqrt(p.squaredNorm()); }

inline float SdSphere(const Vec3f& p, float r) { return Length(p) - r; }

// p relative to the centre; r: semi-axes.
inline float SdEllipsoid(const Vec3f& p, const Vec3f& r) {
  const float k0 = Length(p.cwiseQuotient(r));
  const float k1 = Length(p.cwiseQuotient(r.cwiseProduct(r)));
  return k1 > 1e-12f ? k0 * (k0 - 1.f) / k1 : -r.minCoeff();
}

// A capsule from a (radius ra) to b (radius rb), radius interpolated along the axis.
inline float SdCone(const Vec3f& p, const Vec3f& a, const Vec3f& b, float ra, float rb) {
  const Vec3f ab = b - a;
  const float h = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.f, 1.f);
  return Length(p - a - h * ab) - (ra + (rb - ra) * h);
}

// Polynomial smooth minimum with blend width k (k > 0).
inline float SmoothMin(float a, float b, float k) {
  const float h = std::max(k - std::abs(a - b), 0.f) / k;
  return std::min(a, b) - h * h * k * 0.25f;
}
inline float SmoothMax(float a, float b, float k) { return -SmoothMin(-a, -b, k); }

inline float SmoothStep(float e0, float e1, float x) {
  const float t = std::clamp((x - e0) / (e1 - e0), 0.f, 1.f);
  return t * t * (3.f - 2.f * t);
}

// Compactly supported smooth bump of the squared normalised radius: (1 - r2)^3 for r2 < 1, else 0
// (C2 at the boundary, so warps built from it are smooth and exactly zero outside).
inline float Bump(float r2) {
  if (r2 >= 1.f) return 0.f;
  const float u = 1.f - r2;
  return u * u * u;
}

// Bump of an ellipsoidal window: centre c, inverse semi-axes inv_r.
inline float EllipsoidBump(const Vec3f& p, const Vec3f& c, const Vec3f& inv_r) {
  return Bump((p - c).cwiseProduct(inv_r).squaredNorm());
}

}  // namespace icef::face
