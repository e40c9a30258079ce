// Frequency (positional) encoding with coarse-to-fine annealing (Nerfies).
//
// Input x [n, d] (any frame; the deformation field feeds world/head-frame points, roughly
// [-1, 1]). Output [n, D], D = (include_input ? d : 0) + 2 * d * N:
//   [x_0 .. x_{d-1}],  then for k = 0 .. N-1:  w_k sin(2^k pi x_0 .. x_{d-1}), w_k cos(2^k pi x_...)
// with annealing weights w_k(alpha) = (1 - cos(pi * clamp(alpha - k, 0, 1))) / 2, alpha in [0, N]
// (alpha = N: every frequency fully on). Higher frequencies come from the double-angle recurrence
// (one sin/cos per input value). The encoding has no trainable parameters.
#pragma once

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "icef/core/parallel.h"
#include "icef/core/status.h"

namespace icef::nn {

struct FrequencyEncodingOptions {
  // Input dimensions d.
  int input_dims = 3;
  // Number of frequencies N (2^0 .. 2^(N-1), times pi).
  int num_frequencies = 6;
  // Whether x itself leads the output.
  bool include_input = true;

  Status Validate() const;
  std::string ToString() const;
  int output_dims() const { return (include_input ? input_dims : 0) + 2 * input_dims * num_frequencies; }
};

// Annealing weight of frequency k for the Nerfies schedule parameter alpha.
double AnnealingWeight(double alpha, int k);

// weights: [N] annealing weights. x [n, d] -> y [n, D].
template <typename T>
void FrequencyForward(const FrequencyEncodingOptions& o, const T* weights, int64_t n, const T* x, T* y) {
  const int d = o.input_dims, nf = o.num_frequencies, out = o.output_dims();
  const T pi = T(3.14159265358979323846);
  for (int64_t s = 0; s < n; ++s) {
    const T* xs = x + s * d;
    T* ys = y + s * out;
    int col = 0;
    if (o.include_input) {
      for (int i = 0; i < d; ++i) ys[col++] = xs[i];
    }
    for (int i = 0; i < d; ++i) {
      T sn = std::sin(pi * xs[i]), cs = std::cos(pi * xs[i]);
      for (int k = 0; k < nf; ++k) {
        ys[col + 2 * d * k + i] = weights[k] * sn;
        ys[col + 2 * d * k + d + i] = weights[k] * cs;
        const T s2 = T(2) * sn * cs, c2 = cs * cs - sn * sn;
        sn = s2;
        cs = c2;
      }
    }
  }
}

// dx [n, d] (overwritten) = J^T dy, dy [n, D].
template <typename T>
void FrequencyBackward(const FrequencyEncodingOptions& o, const T* weights, int64_t n, const T* x,
                       const T* dy, T* dx) {
  const int d = o.input_dims, nf = o.num_frequencies, out = o.output_dims();
  const T pi = T(3.14159265358979323846);
  for (int64_t s = 0; s < n; ++s) {
    const T* xs = x + s * d;
    const T* g = dy + s * out;
    const int col = o.include_input ? d : 0;
    for (int i = 0; i < d; ++i) {
      T acc = o.include_input ? g[i] : T(0);
      T sn = std::sin(pi * xs[i]), cs = std::cos(pi * xs[i]);
      T scale = pi;
      for (int k = 0; k < nf; ++k) {
        // d sin(a x)/dx = a cos, d cos(a x)/dx = -a sin, a = 2^k pi.
        acc += weights[k] * scale * (g[col + 2 * d * k + i] * cs - g[col + 2 * d * k + d + i] * sn);
        const T s2 = T(2) * sn * cs, c2 = cs * cs - sn * sn;
        sn = s2;
        cs = c2;
        scale *= T(2);
      }
      dx[s * d + i] = acc;
    }
  }
}

// y = enc(x) and jy = J_enc(x) · v, v [n, d] -> y, jy [n, D].
template <typename T>
void FrequencyJvp(const FrequencyEncodingOptions& o, const T* weights, int64_t n, const T* x, const T* v,
                  T* y, T* jy) {
  const int d = o.input_dims, nf = o.num_frequencies, out = o.output_dims();
  const T pi = T(3.14159265358979323846);
  for (int64_t s = 0; s < n; ++s) {
    const T* xs = x + s * d;
    const T* vs = v + s * d;
    T* ys = y + s * out;
    T* js = jy + s * out;
    int col = 0;
    if (o.include_input) {
      for (int i = 0; i < d; ++i) {
        ys[col] = xs[i];
        js[col++] = vs[i];
      }
    }
    for (int i = 0; i < d; ++i) {
      T sn = std::sin(pi * xs[i]), cs = std::cos(pi * xs[i]);
      T scale = pi;
      for (int k = 0; k < nf; ++k) {
        ys[col + 2 * d * k + i] = weights[k] * sn;
        ys[col + 2 * d * k + d + i] = weights[k] * cs;
        js[col + 2 * d * k + i] = weights[k] * scale * cs * vs[i];
        js[col + 2 * d * k + d + i] = -weights[k] * scale * sn * vs[i];
        const T s2 = T(2) * sn * cs, c2 = cs * cs - sn * sn;
        sn = s2;
        cs = c2;
        scale *= T(2);
      }
    }
  }
}

class FrequencyEncoding {
 public:
  explicit FrequencyEncoding(const FrequencyEncodingOptions& options);

  const FrequencyEncodingOptions& options() const { return options_; }
  int input_dims() const { return options_.input_dims; }
  int output_dims() const { return options_.output_dims(); }
  // Sets the annealing parameter alpha (clamped to [0, N]); initially N (no annealing).
  void SetAlpha(double alpha);
  double alpha() const { return alpha_; }
  // [N] current annealing weights (float and double copies).
  const std::vector<float>& weights() const { return weights_; }
  const std::vector<double>& weights_double() const { return weights_double_; }

  // x [n, d] -> y [n, D].
  void Forward(const Executor& executor, int64_t n, const float* x, float* y) const;
  // dx [n, d] (overwritten) from dy [n, D].
  void Backward(const Executor& executor, int64_t n, const float* x, const float* dy, float* dx) const;
  // y [n, D], jy [n, D] from x, v [n, d].
  void Jvp(const Executor& executor, int64_t n, const float* x, const float* v, float* y, float* jy) const;

  std::string ToString() const;

 private:
  FrequencyEncodingOptions options_;
  double alpha_ = 0.0;
  std::vector<float> weights_;
  std::vector<double> weights_double_;
};

}  // namespace icef::nn
