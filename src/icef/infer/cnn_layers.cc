#include "icef/infer/cnn_layers.h"

// Eigen's AVX-512 GEMM packing trips a GCC 12 false positive (-Wmaybe-uninitialized inside
// avx512fintrin.h after inlining); the code is correct, so the warning is silenced for this file.
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"

#include <omp.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <sstream>

#include "icef/core/status.h"

namespace icef::infer {
namespace {

using RowMatrix = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

int PooledSize(int in, int window, int stride) { return in < window ? 0 : (in - window) / stride + 1; }

// Runs Eigen's GEMM on the calling thread only. Eigen would otherwise split each product over
// omp_get_max_threads() OpenMP threads, which on a shared, oversubscribed machine is ~100x slower
// (spinning barriers) for these small products; callers parallelise over images instead.
// omp_set_num_threads only changes the calling thread's setting, restored on exit.
class ScopedSingleThreadGemm {
 public:
  ScopedSingleThreadGemm() : saved_(omp_get_max_threads()) { omp_set_num_threads(1); }
  ~ScopedSingleThreadGemm() { omp_set_num_threads(saved_); }
  ScopedSingleThreadGemm(const ScopedSingleThreadGemm&) = delete;
  ScopedSingleThreadGemm& operator=(const ScopedSingleThreadGemm&) = delete;

 private:
  int saved_;
};

}  // namespace

std::string Tensor3::ToString() const {
  std::ostringstream s;
  s << "Tensor3[" << h << " x " << w << " x " << c << "]";
  return s.str();
}

std::string ConvWeights::ToString() const {
  std::ostringstream s;
  s << "Conv " << kh << "x" << kw << " " << cin << "->" << cout << (bias.empty() ? " (no bias)" : "");
  return s.str();
}

Tensor3 Conv2d(const Tensor3& input, const ConvWeights& weights, int stride, const Padding& pad) {
  ICEF_CHECK(input.c == weights.cin, "Conv2d: input has " + std::to_string(input.c) +
                                         " channels, filters expect " + std::to_string(weights.cin));
  ICEF_CHECK(stride >= 1);
  ICEF_CHECK(weights.filters.size() == size_t(weights.kh) * weights.kw * weights.cin * weights.cout);
  ICEF_CHECK(weights.bias.empty() || weights.bias.size() == size_t(weights.cout));
  const int padded_h = input.h + pad.top + pad.bottom;
  const int padded_w = input.w + pad.left + pad.right;
  const int out_h = PooledSize(padded_h, weights.kh, stride);
  const int out_w = PooledSize(padded_w, weights.kw, stride);
  Tensor3 out(out_h, out_w, weights.cout);
  if (out_h == 0 || out_w == 0) return out;

  // im2col: one row per output pixel, columns in (i, j, c) order to match HWIO filters.
  const int patch = weights.kh * weights.kw * weights.cin;
  RowMatrix cols(int64_t(out_h) * out_w, patch);
  for (int y = 0; y < out_h; ++y) {
    for (int x = 0; x < out_w; ++x) {
      float* row = cols.data() + (int64_t(y) * out_w + x) * patch;
      for (int i = 0; i < weights.kh; ++i) {
        const int sy = y * stride + i - pad.top;
        for (int j = 0; j < weights.kw; ++j) {
          const int sx = x * stride + j - pad.left;
          float* dst = row + (i * weights.kw + j) * weights.cin;
          if (sy < 0 || sy >= input.h || sx < 0 || sx >= input.w) {
            std::fill(dst, dst + weights.cin, 0.f);
          } else {
            const float* src = &input.data[(size_t(sy) * input.w + sx) * input.c];
            std::copy(src, src + weights.cin, dst);
          }
        }
      }
    }
  }
  Eigen::Map<const RowMatrix> filters(weights.filters.data(), patch, weights.cout);
  Eigen::Map<RowMatrix> result(out.data.data(), int64_t(out_h) * out_w, weights.cout);
  {
    ScopedSingleThreadGemm single_thread;
    result.noalias() = cols * filters;
  }
  if (!weights.bias.empty()) {
    Eigen::Map<const Eigen::RowVectorXf> bias(weights.bias.data(), weights.cout);
    result.rowwise() += bias;
  }
  return out;
}

Tensor3 DepthwiseConv2d(const Tensor3& input, const std::vector<float>& filters, int kh, int kw, int stride,
                        const Padding& pad) {
  ICEF_CHECK(stride >= 1 && kh >= 1 && kw >= 1);
  ICEF_CHECK(filters.size() == size_t(kh) * kw * input.c,
             "DepthwiseConv2d: filters do not match the input's channels");
  const int out_h = PooledSize(input.h + pad.top + pad.bottom, kh, stride);
  const int out_w = PooledSize(input.w + pad.left + pad.right, kw, stride);
  Tensor3 out(out_h, out_w, input.c);
  const int c = input.c;
  for (int y = 0; y < out_h; ++y) {
    for (int x = 0; x < out_w; ++x) {
      float* dst = &out.data[(size_t(y) * out_w + x) * c];
      for (int i = 0; i < kh; ++i) {
        const int sy = y * stride + i - pad.top;
        if (sy < 0 || sy >= input.h) continue;
        for (int j = 0; j < kw; ++j) {
          const int sx = x * stride + j - pad.left;
          if (sx < 0 || sx >= input.w) continue;
          const float* src = &input.data[(size_t(sy) * input.w + sx) * c];
          const float* f = &filters[(size_t(i) * kw + j) * c];
          for (int ch = 0; ch < c; ++ch) dst[ch] += src[ch] * f[ch];
        }
      }
    }
  }
  return out;
}

void Prelu(Tensor3& x, const std::vector<float>& alpha) {
  ICEF_CHECK(alpha.size() == size_t(x.c),
             "Prelu: " + std::to_string(alpha.size()) + " slopes for " + x.ToString());
  const size_t pixels = size_t(x.h) * x.w;
  for (size_t p = 0; p < pixels; ++p) {
    float* v = &x.data[p * x.c];
    for (int c = 0; c < x.c; ++c) v[c] = v[c] > 0.f ? v[c] : alpha[c] * v[c];
  }
}

void Sigmoid(Tensor3& x) {
  for (float& v : x.data) v = 1.f / (1.f + std::exp(-v));
}

Tensor3 Pad(const Tensor3& input, const int before[3], const int after[3]) {
  for (int d = 0; d < 3; ++d) ICEF_CHECK(before[d] >= 0 && after[d] >= 0, "Pad: negative padding");
  Tensor3 out(input.h + before[0] + after[0], input.w + before[1] + after[1], input.c + before[2] + after[2]);
  for (int y = 0; y < input.h; ++y)
    for (int x = 0; x < input.w; ++x)
      std::copy_n(&input.data[(size_t(y) * input.w + x) * input.c], input.c,
                  &out.data[(size_t(y + before[0]) * out.w + x + before[1]) * out.c + before[2]]);
  return out;
}

std::pair<int, int> SamePadding(int in, int kernel, int stride) {
  const int out = (in + stride - 1) / stride;
  const int total = std::max((out - 1) * stride + kernel - in, 0);
  return {total / 2, total - total / 2};
}

void ChannelAffine(Tensor3& x, const std::vector<float>& scale, const std::vector<float>& shift) {
  ICEF_CHECK(scale.size() == size_t(x.c) && shift.size() == size_t(x.c));
  const size_t pixels = size_t(x.h) * x.w;
  for (size_t p = 0; p < pixels; ++p) {
    float* v = &x.data[p * x.c];
    for (int c = 0; c < x.c; ++c) v[c] = v[c] * scale[c] + shift[c];
  }
}

void Relu(Tensor3& x) {
  for (float& v : x.data) v = std::max(v, 0.f);
}

Tensor3 MaxPool(const Tensor3& input, int window, int stride) {
  Tensor3 out(PooledSize(input.h, window, stride), PooledSize(input.w, window, stride), input.c);
  for (int y = 0; y < out.h; ++y) {
    for (int x = 0; x < out.w; ++x) {
      for (int c = 0; c < input.c; ++c) {
        float m = input.At(y * stride, x * stride, c);
        for (int i = 0; i < window; ++i)
          for (int j = 0; j < window; ++j) m = std::max(m, input.At(y * stride + i, x * stride + j, c));
        out.At(y, x, c) = m;
      }
    }
  }
  return out;
}

Tensor3 AvgPool(const Tensor3& input, int window, int stride) {
  Tensor3 out(PooledSize(input.h, window, stride), PooledSize(input.w, window, stride), input.c);
  const float inv = 1.f / float(window * window);
  for (int y = 0; y < out.h; ++y) {
    for (int x = 0; x < out.w; ++x) {
      for (int c = 0; c < input.c; ++c) {
        float s = 0.f;
        for (int i = 0; i < window; ++i)
          for (int j = 0; j < window; ++j) s += input.At(y * stride + i, x * stride + j, c);
        out.At(y, x, c) = s * inv;
      }
    }
  }
  return out;
}

Tensor3 ResizeBilinear(const Tensor3& input, int out_h, int out_w, bool align_corners,
                       bool half_pixel_centers) {
  ICEF_CHECK(out_h > 0 && out_w > 0 && input.h > 0 && input.w > 0, "ResizeBilinear: empty size");
  // Per output row / column: the two source indices and the weight of the second.
  auto axis = [&](int in, int out) {
    std::vector<std::pair<int, int>> index(static_cast<size_t>(out));
    std::vector<float> frac(static_cast<size_t>(out));
    const double scale = align_corners && out > 1 ? double(in - 1) / (out - 1) : double(in) / out;
    for (int o = 0; o < out; ++o) {
      const double src = half_pixel_centers ? (o + 0.5) * scale - 0.5 : o * scale;
      const double lo = std::floor(src);
      index[size_t(o)] = {std::clamp(int(lo), 0, in - 1), std::clamp(int(std::ceil(src)), 0, in - 1)};
      frac[size_t(o)] = float(src - lo);
    }
    return std::pair{index, frac};
  };
  const auto [ys, fy] = axis(input.h, out_h);
  const auto [xs, fx] = axis(input.w, out_w);
  Tensor3 out(out_h, out_w, input.c);
  for (int y = 0; y < out_h; ++y)
    for (int x = 0; x < out_w; ++x)
      for (int c = 0; c < input.c; ++c) {
        const auto [y0, y1] = ys[size_t(y)];
        const auto [x0, x1] = xs[size_t(x)];
        const float top = input.At(y0, x0, c) + (input.At(y0, x1, c) - input.At(y0, x0, c)) * fx[size_t(x)];
        const float bottom =
            input.At(y1, x0, c) + (input.At(y1, x1, c) - input.At(y1, x0, c)) * fx[size_t(x)];
        out.At(y, x, c) = top + (bottom - top) * fy[size_t(y)];
      }
  return out;
}

Tensor3 TransposedConv2d(const Tensor3& input, const std::vector<float>& filters, int kh, int kw, int cout,
                         int stride, int out_h, int out_w, int pad_top, int pad_left) {
  ICEF_CHECK(filters.size() == size_t(kh) * kw * cout * input.c, "TransposedConv2d: filter size mismatch");
  Tensor3 out(out_h, out_w, cout);
  for (int y = 0; y < input.h; ++y)
    for (int x = 0; x < input.w; ++x)
      for (int i = 0; i < kh; ++i) {
        const int oy = y * stride + i - pad_top;
        if (oy < 0 || oy >= out_h) continue;
        for (int j = 0; j < kw; ++j) {
          const int ox = x * stride + j - pad_left;
          if (ox < 0 || ox >= out_w) continue;
          const float* f = &filters[(size_t(i) * kw + j) * cout * input.c];
          for (int o = 0; o < cout; ++o) {
            float s = 0.f;
            for (int c = 0; c < input.c; ++c) s += input.At(y, x, c) * f[size_t(o) * input.c + c];
            out.At(oy, ox, o) += s;
          }
        }
      }
  return out;
}

Tensor3 ZeroPadTo(const Tensor3& input, int h, int w, int c) {
  ICEF_CHECK(h >= input.h && w >= input.w && c >= input.c, "ZeroPadTo: target smaller than input");
  Tensor3 out(h, w, c);
  for (int y = 0; y < input.h; ++y)
    for (int x = 0; x < input.w; ++x)
      std::copy_n(&input.data[(size_t(y) * input.w + x) * input.c], input.c,
                  &out.data[(size_t(y) * w + x) * c]);
  return out;
}

void AddInPlace(Tensor3& a, const Tensor3& b) {
  ICEF_CHECK(a.h == b.h && a.w == b.w && a.c == b.c, "AddInPlace: " + a.ToString() + " vs " + b.ToString());
  for (size_t i = 0; i < a.data.size(); ++i) a.data[i] += b.data[i];
}

Tensor3 AddZeroExtended(const Tensor3& a, const Tensor3& b) {
  Tensor3 out = ZeroPadTo(a, std::max(a.h, b.h), std::max(a.w, b.w), std::max(a.c, b.c));
  for (int y = 0; y < b.h; ++y)
    for (int x = 0; x < b.w; ++x)
      for (int c = 0; c < b.c; ++c) out.At(y, x, c) += b.At(y, x, c);
  return out;
}

std::vector<float> GlobalMean(const Tensor3& input) {
  std::vector<double> sum(input.c, 0.0);
  const size_t pixels = size_t(input.h) * input.w;
  for (size_t p = 0; p < pixels; ++p)
    for (int c = 0; c < input.c; ++c) sum[c] += input.data[p * input.c + c];
  std::vector<float> mean(input.c);
  for (int c = 0; c < input.c; ++c) mean[c] = pixels ? float(sum[c] / double(pixels)) : 0.f;
  return mean;
}

std::vector<float> FullyConnected(const std::vector<float>& x, const std::vector<float>& weights, int out) {
  ICEF_CHECK(out > 0 && weights.size() == x.size() * size_t(out));
  std::vector<float> y(out, 0.f);
  for (size_t i = 0; i < x.size(); ++i)
    for (int o = 0; o < out; ++o) y[o] += x[i] * weights[i * out + o];
  return y;
}

}  // namespace icef::infer
