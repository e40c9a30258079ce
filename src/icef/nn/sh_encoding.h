// Real spherical-harmonics encoding of unit directions (tiny-cuda-nn's basis and sign
// convention), `degree` bands -> degree^2 values (degree 4 -> 16). Directions [n, 3] in the world
// frame, assumed unit length (not renormalised); output [n, degree^2]. No parameters. The input
// gradient (rarely needed: view directions are data) is computed with dual numbers.
#pragma once

#include <cstdint>
#include <string>

#include "icef/core/parallel.h"
#include "icef/core/status.h"

namespace icef::nn {

// Evaluates the first degree^2 basis functions at (x, y, z) into out. T may be a dual number.
template <typename T>
void ShBasis(int degree, const T& x, const T& y, const T& z, T* out) {
  out[0] = T(0.28209479177387814);
  if (degree <= 1) return;
  out[1] = T(-0.48860251190291987) * y;
  out[2] = T(0.48860251190291987) * z;
  out[3] = T(-0.48860251190291987) * x;
  if (degree <= 2) return;
  const T xy = x * y, xz = x * z, yz = y * z, x2 = x * x, y2 = y * y, z2 = z * z;
  out[4] = T(1.0925484305920792) * xy;
  out[5] = T(-1.0925484305920792) * yz;
  out[6] = T(0.94617469575755997) * z2 - T(0.31539156525251999);
  out[7] = T(-1.0925484305920792) * xz;
  out[8] = T(0.54627421529603959) * x2 - T(0.54627421529603959) * y2;
  if (degree <= 3) return;
  out[9] = T(0.59004358992664352) * y * (T(-3.0) * x2 + y2);
  out[10] = T(2.8906114426405538) * xy * z;
  out[11] = T(0.45704579946446572) * y * (T(1.0) - T(5.0) * z2);
  out[12] = T(0.3731763325901154) * z * (T(5.0) * z2 - T(3.0));
  out[13] = T(0.45704579946446572) * x * (T(1.0) - T(5.0) * z2);
  out[14] = T(1.4453057213202769) * z * (x2 - y2);
  out[15] = T(0.59004358992664352) * x * (T(3.0) * y2 - x2);
}

// Forward-mode dual number a + b eps (used for the SH input gradient).
template <typename T>
struct Dual {
  T a = T(0), b = T(0);
  Dual() = default;
  explicit Dual(T v, T d = T(0)) : a(v), b(d) {}
  friend Dual operator+(const Dual& p, const Dual& q) { return Dual(p.a + q.a, p.b + q.b); }
  friend Dual operator-(const Dual& p, const Dual& q) { return Dual(p.a - q.a, p.b - q.b); }
  friend Dual operator*(const Dual& p, const Dual& q) { return Dual(p.a * q.a, p.a * q.b + p.b * q.a); }
};

// directions [n, 3] -> y [n, degree^2].
template <typename T>
void ShForward(int degree, int64_t n, const T* directions, T* y) {
  const int out = degree * degree;
  for (int64_t s = 0; s < n; ++s) {
    const T* d = directions + 3 * s;
    ShBasis<T>(degree, d[0], d[1], d[2], y + s * out);
  }
}

// d_directions [n, 3] (overwritten) = J^T dy.
template <typename T>
void ShBackward(int degree, int64_t n, const T* directions, const T* dy, T* d_directions) {
  const int out = degree * degree;
  Dual<T> vals[16];
  for (int64_t s = 0; s < n; ++s) {
    const T* d = directions + 3 * s;
    for (int a = 0; a < 3; ++a) {
      const Dual<T> x(d[0], a == 0 ? T(1) : T(0));
      const Dual<T> y(d[1], a == 1 ? T(1) : T(0));
      const Dual<T> z(d[2], a == 2 ? T(1) : T(0));
      ShBasis<Dual<T>>(degree, x, y, z, vals);
      T acc = T(0);
      for (int i = 0; i < out; ++i) acc += vals[i].b * dy[s * out + i];
      d_directions[3 * s + a] = acc;
    }
  }
}

struct ShEncodingOptions {
  // Number of SH bands (1..4); the output has degree^2 values.
  int degree = 4;

  Status Validate() const;
  std::string ToString() const { return "ShEncodingOptions(degree=" + std::to_string(degree) + ")"; }
};

class ShEncoding {
 public:
  explicit ShEncoding(const ShEncodingOptions& options);
  int input_dims() const { return 3; }
  int output_dims() const { return options_.degree * options_.degree; }
  // directions [n, 3] (unit, world frame) -> y [n, degree^2].
  void Forward(const Executor& executor, int64_t n, const float* directions, float* y) const;
  // d_directions [n, 3] (overwritten) from dy [n, degree^2].
  void Backward(const Executor& executor, int64_t n, const float* directions, const float* dy,
                float* d_directions) const;
  std::string ToString() const { return "ShEncoding(" + options_.ToString() + ")"; }

 private:
  ShEncodingOptions options_;
};

}  // namespace icef::nn
