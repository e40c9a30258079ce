// Single-threaded MLP kernels on one tile of n samples, templated on the scalar type (float for
// speed, double for gradient checks). All buffers are row-major and packed.
//
// Network: widths w_0 (input), w_1 ... w_{L-1} (hidden, ReLU), w_L (output, MlpShape activation);
// no bias terms (as tiny-cuda-nn). Layer l's weights are stored TRANSPOSED as Wt_l [w_l, w_{l+1}]
// (input-major), so a layer is y = x · Wt_l. Blocks follow each other without padding in a flat
// weight vector (offset WeightOffset(l)).
//
// hidden: the post-ReLU activations of the hidden layers of this tile, layer after layer, each
// block [n, w_l] (offset n * HiddenOffset(l)); kept from the forward pass for the backward pass.
#pragma once

#include <algorithm>
#include <cstdint>
#include <string>
#include <type_traits>
#include <vector>

#include "icef/core/status.h"
#include "icef/nn/activation.h"
#include "icef/nn/gemm.h"
#include "icef/nn/gemm_bf16.h"

namespace icef::nn {

class MlpShape {
 public:
  MlpShape() = default;
  MlpShape(std::vector<int> widths, Activation output_activation);

  const std::vector<int>& widths() const { return widths_; }
  int num_layers() const { return static_cast<int>(widths_.size()) - 1; }
  int input_dims() const { return widths_.front(); }
  int output_dims() const { return widths_.back(); }
  Activation output_activation() const { return output_activation_; }
  // First float of layer l's Wt block in the flat weight vector.
  int64_t WeightOffset(int l) const { return weight_offsets_[l]; }
  int64_t num_params() const { return weight_offsets_.back(); }
  // Sum of hidden widths before hidden layer l (l = 0 .. num_layers()-2): block l starts at
  // hidden + n * HiddenOffset(l).
  int HiddenOffset(int l) const { return hidden_offsets_[l]; }
  // Floats of hidden activations per sample (sum of hidden widths).
  int hidden_per_sample() const { return hidden_offsets_.back(); }
  int max_width() const { return max_width_; }
  // Multiply-adds per sample in the forward pass.
  int64_t ForwardMacs() const { return num_params(); }
  std::string ToString() const;

 private:
  std::vector<int> widths_;
  Activation output_activation_ = Activation::kNone;
  std::vector<int64_t> weight_offsets_;
  std::vector<int> hidden_offsets_;
  int max_width_ = 0;
};

// An MLP's weights packed for GemmNNBf16 (nn/gemm_bf16.h), layer by layer; layers whose output
// width is not a multiple of 16 (the small output layers) stay FP32.
struct MlpBf16Weights {
  std::vector<uint16_t> packed;
  std::vector<int64_t> offsets;  // [layers] first value of layer l in packed, -1: FP32
  void Pack(const MlpShape& s, const float* w) {
    offsets.assign(s.num_layers(), -1);
    int64_t size = 0;
    for (int l = 0; l < s.num_layers(); ++l)
      if (s.widths()[l + 1] % 16 == 0)
        offsets[l] = size, size += Bf16PackedSize(s.widths()[l], s.widths()[l + 1]);
    packed.resize(size);
    for (int l = 0; l < s.num_layers(); ++l)
      if (offsets[l] >= 0)
        PackBf16Pairs(s.widths()[l], s.widths()[l + 1], w + s.WeightOffset(l), packed.data() + offsets[l]);
  }
  // The untransposed layers W_l [w_{l+1}, w_l] (MlpTransposeWeights) for the backward pass's data
  // products; layers whose INPUT width is not a multiple of 16 stay FP32.
  void PackTransposed(const MlpShape& s, const float* w_transposed) {
    offsets.assign(s.num_layers(), -1);
    int64_t size = 0;
    for (int l = 0; l < s.num_layers(); ++l)
      if (s.widths()[l] % 16 == 0)
        offsets[l] = size, size += Bf16PackedSize(s.widths()[l + 1], s.widths()[l]);
    packed.resize(size);
    for (int l = 0; l < s.num_layers(); ++l)
      if (offsets[l] >= 0)
        PackBf16Pairs(s.widths()[l + 1], s.widths()[l], w_transposed + s.WeightOffset(l),
                      packed.data() + offsets[l]);
  }
  const uint16_t* layer(int l) const { return offsets[l] < 0 ? nullptr : packed.data() + offsets[l]; }
};

// Layer l's product: BF16 when bf packs the layer (float only), else GemmNN.
template <typename T>
inline void LayerProduct(const MlpShape& s, int l, const T* w, const MlpBf16Weights* bf, int64_t n,
                         const T* in, T* out) {
  const int in_w = s.widths()[l], out_w = s.widths()[l + 1];
  if constexpr (std::is_same_v<T, float>) {
    if (bf && bf->layer(l)) return GemmNNBf16(n, in_w, out_w, in, bf->layer(l), out);
  }
  GemmNN<T>(n, in_w, out_w, in, w + s.WeightOffset(l), out);
}

// Layer l's weight gradient, dW_l += in^T · d: BF16 when bf_t is given (float only) and the
// layer's output width is a multiple of 16, else GemmTNAcc.
template <typename T>
inline void LayerWeightGrad(const MlpShape& s, int l, const MlpBf16Weights* bf_t, int64_t n, const T* in,
                            const T* d, T* dw) {
  const int in_w = s.widths()[l], out_w = s.widths()[l + 1];
  if constexpr (std::is_same_v<T, float>) {
    if (bf_t && out_w % 16 == 0) return GemmTNAccBf16(n, in_w, out_w, in, d, dw + s.WeightOffset(l));
  }
  GemmTNAcc<T>(n, in_w, out_w, in, d, dw + s.WeightOffset(l));
}

// Layer l's data product of the backward pass, dest [n, w_l] = d [n, w_{l+1}] · W_l: BF16 when
// bf_t packs the layer (float only), else GemmNN on w_transposed.
template <typename T>
inline void LayerDataProduct(const MlpShape& s, int l, const T* w_transposed, const MlpBf16Weights* bf_t,
                             int64_t n, const T* d, T* dest) {
  const int in_w = s.widths()[l], out_w = s.widths()[l + 1];
  if constexpr (std::is_same_v<T, float>) {
    if (bf_t && bf_t->layer(l)) return GemmNNBf16(n, out_w, in_w, d, bf_t->layer(l), dest);
  }
  GemmNN<T>(n, out_w, in_w, d, w_transposed + s.WeightOffset(l), dest);
}

// Writes W_l [w_{l+1}, w_l] (the untransposed layer) for every layer into wt_out, same offsets.
// The backward pass multiplies by these. Call once per batch, not per tile.
template <typename T>
void MlpTransposeWeights(const MlpShape& s, const T* w, T* w_transposed) {
  for (int l = 0; l < s.num_layers(); ++l) {
    const int in = s.widths()[l], out = s.widths()[l + 1];
    const T* src = w + s.WeightOffset(l);
    T* dst = w_transposed + s.WeightOffset(l);
    for (int i = 0; i < in; ++i)
      for (int o = 0; o < out; ++o) dst[o * in + i] = src[i * out + o];
  }
}

// x [n, w_0] -> y [n, w_L]; hidden [n * hidden_per_sample] receives the hidden activations.
// bf (float only, may be null): the weights packed for BF16 products (inference).
template <typename T>
void MlpForward(const MlpShape& s, const T* w, int64_t n, const T* x, T* hidden, T* y,
                const MlpBf16Weights* bf = nullptr) {
  const T* in = x;
  const int layers = s.num_layers();
  for (int l = 0; l < layers; ++l) {
    const bool last = l == layers - 1;
    const int out_w = s.widths()[l + 1];
    T* out = last ? y : hidden + n * s.HiddenOffset(l);
    LayerProduct<T>(s, l, w, bf, n, in, out);
    const int64_t count = n * out_w;
    if (!last) {
      for (int64_t i = 0; i < count; ++i) out[i] = out[i] > T(0) ? out[i] : T(0);
    } else if (s.output_activation() != Activation::kNone) {
      const Activation a = s.output_activation();
      for (int64_t i = 0; i < count; ++i) out[i] = ApplyActivation(a, out[i]);
    }
    in = out;
  }
}

// Scratch floats MlpBackward needs for a tile of n samples.
inline int64_t MlpBackwardScratch(const MlpShape& s, int64_t n) { return 2 * n * s.max_width(); }

// Given dy = d loss / d y [n, w_L], ACCUMULATES d loss / d Wt into dw (flat, same layout as w) and,
// when dx is not null, WRITES d loss / d x [n, w_0]. w_transposed from MlpTransposeWeights.
// bf_t (float only, may be null): w_transposed packed by PackTransposed; then every product whose
// output width is a multiple of 16 runs in BF16 with FP32 sums, weight gradients included.
template <typename T>
void MlpBackward(const MlpShape& s, const T* w_transposed, int64_t n, const T* x, const T* hidden, const T* y,
                 const T* dy, T* dw, T* dx, T* scratch, const MlpBf16Weights* bf_t = nullptr) {
  const int layers = s.num_layers();
  T* bufs[2] = {scratch, scratch + n * s.max_width()};
  int cur = 0;
  T* d = bufs[cur];
  {
    const int64_t count = n * s.output_dims();
    const Activation a = s.output_activation();
    if (a == Activation::kNone) {
      std::copy(dy, dy + count, d);
    } else {
      for (int64_t i = 0; i < count; ++i) d[i] = dy[i] * ActivationDerivativeFromOutput(a, y[i]);
    }
  }
  for (int l = layers - 1; l >= 0; --l) {
    const int in_w = s.widths()[l];
    const T* in = l == 0 ? x : hidden + n * s.HiddenOffset(l - 1);
    LayerWeightGrad<T>(s, l, bf_t, n, in, d, dw);
    if (l == 0 && dx == nullptr) break;
    T* dest = l == 0 ? dx : bufs[1 - cur];
    LayerDataProduct<T>(s, l, w_transposed, bf_t, n, d, dest);
    if (l > 0) {
      const int64_t count = n * in_w;
      for (int64_t i = 0; i < count; ++i) dest[i] = in[i] > T(0) ? dest[i] : T(0);
      cur = 1 - cur;
      d = dest;
    }
  }
}

// Scratch floats MlpJvp needs for a tile of n samples.
inline int64_t MlpJvpScratch(const MlpShape& s, int64_t n) { return 4 * n * s.max_width(); }

// Forward-mode derivative: y = f(x) [n, w_L] and jy = J_f(x) · v [n, w_L], where the tangent v
// [n, slice_dims] is non-zero only on input columns [slice_begin, slice_begin + slice_dims).
template <typename T>
void MlpJvp(const MlpShape& s, const T* w, int64_t n, const T* x, int slice_begin, int slice_dims, const T* v,
            T* y, T* jy, T* scratch, const MlpBf16Weights* bf = nullptr) {
  const int layers = s.num_layers();
  const int64_t stride = n * s.max_width();
  T* h[2] = {scratch, scratch + stride};
  T* t[2] = {scratch + 2 * stride, scratch + 3 * stride};
  const T* in = x;
  const T* tin = v;
  int cur = 0;
  for (int l = 0; l < layers; ++l) {
    const bool last = l == layers - 1;
    const int out_w = s.widths()[l + 1];
    T* out = last ? y : h[cur];
    T* tout = last ? jy : t[cur];
    LayerProduct<T>(s, l, w, bf, n, in, out);
    if (l == 0 && !(slice_begin == 0 && slice_dims == s.widths()[0])) {
      // A tangent on part of the input: that slice of the first layer, in FP32 (its rows need not
      // pair up for BF16).
      GemmNN<T>(n, slice_dims, out_w, tin, w + s.WeightOffset(0) + int64_t{slice_begin} * out_w, tout);
    } else {
      LayerProduct<T>(s, l, w, bf, n, tin, tout);
    }
    const int64_t count = n * out_w;
    const Activation a = last ? s.output_activation() : Activation::kRelu;
    if (a == Activation::kRelu) {  // the hidden layers: a branch-free loop the compiler vectorises
      for (int64_t i = 0; i < count; ++i) {
        const bool on = out[i] > T(0);
        out[i] = on ? out[i] : T(0);
        tout[i] = on ? tout[i] : T(0);
      }
    } else if (a != Activation::kNone) {
      for (int64_t i = 0; i < count; ++i) {
        out[i] = ApplyActivation(a, out[i]);
        tout[i] *= ActivationDerivativeFromOutput(a, out[i]);
      }
    }
    in = out;
    tin = tout;
    cur = 1 - cur;
  }
}

}  // namespace icef::nn
