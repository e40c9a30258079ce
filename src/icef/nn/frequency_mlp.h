// The deformation network's building block: y = Mlp([freq(x), c]), a frequency-encoded input x
// [n, d] concatenated with a conditioning vector c [n, dc] (the expression beta), then an Mlp
// whose input width is D + dc (D = encoding output). Forward, backward (parameter gradients and
// d/dx, d/dc) and the forward-mode JVP  jy = J_x y · vx + J_c y · vc  in one pass (docs/design.md §2:
// the linearised deformation uses vc = beta - beta_n, vx = 0; a smoothness loss may use vx).
// Residual outputs (D(x) = x + g) are the caller's business: it adds x (and vx) itself.
#pragma once

#include <algorithm>
#include <cstdint>
#include <string>

#include "icef/core/parallel.h"
#include "icef/nn/frequency_encoding.h"
#include "icef/nn/mlp.h"

namespace icef::nn {

// Scratch floats per tile of n samples for the kernels below.
inline int64_t FrequencyMlpScratch(const MlpShape& s, int64_t n) {
  return 2 * n * s.input_dims() + std::max(MlpBackwardScratch(s, n), MlpJvpScratch(s, n));
}

// Writes [freq(x), c] into in [n, D + dc].
template <typename T>
void FrequencyMlpInput(const FrequencyEncodingOptions& fo, const T* freq_weights, int dc, int64_t n,
                       const T* x, const T* c, T* in, T* enc_scratch) {
  const int D = fo.output_dims(), w0 = D + dc;
  FrequencyForward<T>(fo, freq_weights, n, x, enc_scratch);
  for (int64_t s = 0; s < n; ++s) {
    std::copy(enc_scratch + s * D, enc_scratch + (s + 1) * D, in + s * w0);
    std::copy(c + s * dc, c + (s + 1) * dc, in + s * w0 + D);
  }
}

// Tile forward: in [n, D + dc] receives the MLP input (keep it for the backward pass), hidden as
// in MlpForward, y [n, out].
template <typename T>
void FrequencyMlpForward(const FrequencyEncodingOptions& fo, const T* freq_weights, const MlpShape& s,
                         const T* w, int64_t n, const T* x, const T* c, T* in, T* hidden, T* y, T* scratch,
                         const MlpBf16Weights* bf = nullptr) {
  const int dc = s.input_dims() - fo.output_dims();
  FrequencyMlpInput(fo, freq_weights, dc, n, x, c, in, scratch);
  MlpForward<T>(s, w, n, in, hidden, y, bf);
}

// Tile backward: accumulates dw; writes dx [n, d] and dc_out [n, dc] unless null.
template <typename T>
void FrequencyMlpBackward(const FrequencyEncodingOptions& fo, const T* freq_weights, const MlpShape& s,
                          const T* w_transposed, int64_t n, const T* x, const T* in, const T* hidden,
                          const T* y, const T* dy, T* dw, T* dx, T* dc_out, T* scratch,
                          const MlpBf16Weights* bf_t = nullptr) {
  const int D = fo.output_dims(), w0 = s.input_dims(), dc = w0 - D;
  const bool need_input = dx != nullptr || dc_out != nullptr;
  T* d_in = scratch;            // [n, w0]
  T* d_enc = scratch + n * w0;  // [n, D]
  T* mlp_scratch = scratch + 2 * n * w0;
  MlpBackward<T>(s, w_transposed, n, in, hidden, y, dy, dw, need_input ? d_in : nullptr, mlp_scratch, bf_t);
  if (!need_input) return;
  for (int64_t r = 0; r < n; ++r) {
    std::copy(d_in + r * w0, d_in + r * w0 + D, d_enc + r * D);
    if (dc_out) std::copy(d_in + r * w0 + D, d_in + (r + 1) * w0, dc_out + r * dc);
  }
  if (dx) FrequencyBackward<T>(fo, freq_weights, n, x, d_enc, dx);
}

// Tile JVP: y = f(x, c), jy = J_x f vx + J_c f vc; vx [n, d] or vc [n, dc] may be null (zero).
template <typename T>
void FrequencyMlpJvp(const FrequencyEncodingOptions& fo, const T* freq_weights, const MlpShape& s, const T* w,
                     int64_t n, const T* x, const T* c, const T* vx, const T* vc, T* y, T* jy, T* scratch,
                     const MlpBf16Weights* bf = nullptr) {
  const int D = fo.output_dims(), w0 = s.input_dims(), dc = w0 - D;
  T* in = scratch;            // [n, w0]
  T* tin = scratch + n * w0;  // [n, w0]
  T* mlp_scratch = scratch + 2 * n * w0;
  // Encoding and its tangent go through mlp_scratch first (it is free until MlpJvp).
  T* enc = mlp_scratch;
  T* tenc = mlp_scratch + n * D;
  if (vx) {
    FrequencyJvp<T>(fo, freq_weights, n, x, vx, enc, tenc);
  } else {
    FrequencyForward<T>(fo, freq_weights, n, x, enc);
  }
  for (int64_t r = 0; r < n; ++r) {
    std::copy(enc + r * D, enc + (r + 1) * D, in + r * w0);
    std::copy(c + r * dc, c + (r + 1) * dc, in + r * w0 + D);
    if (vx) {
      std::copy(tenc + r * D, tenc + (r + 1) * D, tin + r * w0);
    } else {
      std::fill(tin + r * w0, tin + r * w0 + D, T(0));
    }
    if (vc) {
      std::copy(vc + r * dc, vc + (r + 1) * dc, tin + r * w0 + D);
    } else {
      std::fill(tin + r * w0 + D, tin + (r + 1) * w0, T(0));
    }
  }
  MlpJvp<T>(s, w, n, in, 0, w0, tin, y, jy, mlp_scratch, bf);
}

struct FrequencyMlpOptions {
  // Frequency encoding of x.
  FrequencyEncodingOptions encoding;
  // Conditioning dimensions dc (expression coefficients), appended after the encoding.
  int condition_dims = 16;
  // Hidden layer widths.
  std::vector<int> hidden = {64, 64, 64};
  // Output dimensions.
  int output_dims = 3;
  // Output activation.
  Activation output_activation = Activation::kNone;
  // Multiplies the initial output-layer weights (small: start near a zero residual).
  float output_init_scale = 1.0f;
  // Forward and JVP passes without a backward pass in BF16 (MlpOptions::bf16_inference).
  bool bf16_inference = false;
  // Training passes (forward and backward) in BF16 (MlpOptions::bf16_training).
  bool bf16_training = false;

  Status Validate() const;
  std::string ToString() const;
  MlpOptions ToMlpOptions() const;
};

// Batch state (the MLP input and hidden activations of the batch, per-thread scratch).
struct FrequencyMlpContext {
  int64_t n = 0;
  int num_threads = 0;
  AlignedVector<float> input;    // [n, D + dc]
  AlignedVector<float> scratch;  // per thread
  MlpContext mlp;                // hidden, per-thread gradients, transposed weights
};

class FrequencyMlp {
 public:
  FrequencyMlp(const FrequencyMlpOptions& options, ParameterStore* store, const std::string& name,
               int group = 0);
  void Initialize(uint64_t seed) { mlp_.Initialize(seed); }

  const FrequencyMlpOptions& options() const { return options_; }
  FrequencyEncoding& encoding() { return encoding_; }
  const FrequencyEncoding& encoding() const { return encoding_; }
  Mlp& mlp() { return mlp_; }
  const Mlp& mlp() const { return mlp_; }

  // x [n, d], c [n, dc] -> y [n, out]; keeps what Backward needs when keep_for_backward.
  void Forward(const Executor& executor, int64_t n, const float* x, const float* c, float* y,
               FrequencyMlpContext* ctx, bool keep_for_backward = true) const;
  // Accumulates parameter gradients; writes dx [n, d], dc [n, dc] unless null.
  void Backward(const Executor& executor, int64_t n, const float* x, const float* y, const float* dy,
                FrequencyMlpContext* ctx, float* dx, float* dc);
  // y [n, out], jy = J_x y vx + J_c y vc [n, out]; vx or vc may be null.
  void Jvp(const Executor& executor, int64_t n, const float* x, const float* c, const float* vx,
           const float* vc, float* y, float* jy, FrequencyMlpContext* ctx) const;

  std::string ToString() const;

 private:
  FrequencyMlpOptions options_;
  FrequencyEncoding encoding_;
  Mlp mlp_;
};

}  // namespace icef::nn
