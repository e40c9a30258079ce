// Forward-only convolutional layers for the pretrained evaluation networks (the face-identity
// ResNet and LPIPS). Tensors are single images in HWC layout; filters are HWIO (TF.js / dlib
// order), so a convolution is one GEMM of the im2col matrix [out_h * out_w, kh * kw * cin] with
// the filter matrix [kh * kw * cin, cout], run on the calling thread (parallelise over images).
// No gradients: these networks are only evaluated.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace icef::infer {

// [h, w, c] row-major, channels fastest.
struct Tensor3 {
  int h = 0;
  int w = 0;
  int c = 0;
  std::vector<float> data;  // [h, w, c]

  Tensor3() = default;
  Tensor3(int h_, int w_, int c_, float fill = 0.f) : h(h_), w(w_), c(c_), data(size_t(h_) * w_ * c_, fill) {}
  float& At(int y, int x, int ch) { return data[(size_t(y) * w + x) * c + ch]; }
  float At(int y, int x, int ch) const { return data[(size_t(y) * w + x) * c + ch]; }
  std::string ToString() const;
};

// A 2-D convolution's parameters.
struct ConvWeights {
  int kh = 0;
  int kw = 0;
  int cin = 0;
  int cout = 0;
  std::vector<float> filters;  // [kh, kw, cin, cout] (HWIO)
  std::vector<float> bias;     // [cout], or empty for no bias
  std::string ToString() const;
};

// Zero padding on each side of the input, in pixels.
struct Padding {
  int top = 0;
  int left = 0;
  int bottom = 0;
  int right = 0;
  static Padding Valid() { return {}; }
  // Symmetric padding of p on every side (PyTorch `padding=p`; TF 'same' for odd kernels, stride 1).
  static Padding Uniform(int p) { return {p, p, p, p}; }
};

// out[y, x, o] = bias[o] + sum_{i, j, c} in[y * stride + i - pad.top, x * stride + j - pad.left, c]
//                                      * filters[i, j, c, o]   (zero outside the input).
// Output size: (h + top + bottom - kh) / stride + 1 (floor), likewise for width.
Tensor3 Conv2d(const Tensor3& input, const ConvWeights& weights, int stride, const Padding& pad);

// Depthwise convolution with one filter per channel (channel multiplier 1): filters [kh, kw, c]
// (TF's [kh, kw, c, 1]), out[y, x, c] = sum_{i, j} in[y * stride + i - pad.top, x * stride + j - pad.left, c]
// * filters[i, j, c] (zero outside the input); no bias.
Tensor3 DepthwiseConv2d(const Tensor3& input, const std::vector<float>& filters, int kh, int kw, int stride,
                        const Padding& pad);
// x = x > 0 ? x : alpha[c] * x (TF's Prelu, alpha per channel).
void Prelu(Tensor3& x, const std::vector<float>& alpha);
// x = 1 / (1 + exp(-x)).
void Sigmoid(Tensor3& x);
// Zero padding: `before` / `after` pixels or channels on each side, per dimension (h, w, c).
Tensor3 Pad(const Tensor3& input, const int before[3], const int after[3]);
// TF's 'SAME' padding of one dimension: output ceil(in / stride), the total padding split with the
// smaller half before. Returns {before, after}.
std::pair<int, int> SamePadding(int in, int kernel, int stride);

// x[..., c] = x[..., c] * scale[c] + shift[c] (dlib's affine layer / face-api's scale layer).
void ChannelAffine(Tensor3& x, const std::vector<float>& scale, const std::vector<float>& shift);
// x = max(x, 0).
void Relu(Tensor3& x);
// Max / average pooling over window x window with the given stride, no padding ('valid').
// Output size: (h - window) / stride + 1 (floor).
Tensor3 MaxPool(const Tensor3& input, int window, int stride);
Tensor3 AvgPool(const Tensor3& input, int window, int stride);
// Bilinear resampling to [out_h, out_w] as TF's ResizeBilinear: source coordinate
// (o + 0.5) * in / out - 0.5 with half_pixel_centers, o * (in - 1) / (out - 1) with align_corners,
// else o * in / out; the two neighbours clamped to the input, weighted by the fractional part.
Tensor3 ResizeBilinear(const Tensor3& input, int out_h, int out_w, bool align_corners,
                       bool half_pixel_centers);
// Transposed convolution (TF's Conv2DBackpropInput, the gradient of Conv2d with respect to its
// input): filters [kh, kw, cout, cin] (TF's order for this op), output [out_h, out_w, cout],
// out[y * stride + i - pad_top, x * stride + j - pad_left, o] += in[y, x, c] * filters[i, j, o, c].
Tensor3 TransposedConv2d(const Tensor3& input, const std::vector<float>& filters, int kh, int kw, int cout,
                         int stride, int out_h, int out_w, int pad_top, int pad_left);
// Copies `input` into an [h, w, c] tensor of zeros at the top-left corner (zero padding at the
// bottom, right and in the trailing channels). Requires h >= input.h, w >= input.w, c >= input.c.
Tensor3 ZeroPadTo(const Tensor3& input, int h, int w, int c);
// a += b (same shape).
void AddInPlace(Tensor3& a, const Tensor3& b);
// dlib's add_prev: the sum of two tensors of possibly different shapes, each zero-extended at
// the bottom / right / trailing channels to the larger of the two in every dimension.
Tensor3 AddZeroExtended(const Tensor3& a, const Tensor3& b);
// Mean over all pixels: [c].
std::vector<float> GlobalMean(const Tensor3& input);
// y[o] = sum_i x[i] * weights[i, o]; weights [in, out] row-major.
std::vector<float> FullyConnected(const std::vector<float>& x, const std::vector<float>& weights, int out);

}  // namespace icef::infer
