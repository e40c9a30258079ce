// Test-only helpers: random tensors / filters and naive double-precision reference layers.
#pragma once

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <string>

#include "icef/core/rng.h"
#include "icef/infer/cnn_layers.h"
#include "icef/io/atomic_file.h"

namespace icef::infer::testing {

inline Tensor3 RandomTensor(int h, int w, int c, uint64_t item) {
  Rng rng(7, StreamId("cnn_layers_test"), 0, item);
  Tensor3 t(h, w, c);
  for (float& v : t.data) v = float(rng.Uniform(-1.0, 1.0));
  return t;
}

inline ConvWeights RandomConv(int k_h, int k_w, int cin, int cout, bool bias, uint64_t item) {
  Rng rng(7, StreamId("cnn_layers_test_w"), 0, item);
  ConvWeights w;
  w.kh = k_h;
  w.kw = k_w;
  w.cin = cin;
  w.cout = cout;
  w.filters.resize(size_t(k_h) * k_w * cin * cout);
  for (float& v : w.filters) v = float(rng.Uniform(-0.5, 0.5));
  if (bias) {
    w.bias.resize(cout);
    for (float& v : w.bias) v = float(rng.Uniform(-0.5, 0.5));
  }
  return w;
}

// Direct definition of the convolution, in double.
inline Tensor3 NaiveConv(const Tensor3& in, const ConvWeights& w, int stride, const Padding& pad) {
  const int out_h = (in.h + pad.top + pad.bottom - w.kh) / stride + 1;
  const int out_w = (in.w + pad.left + pad.right - w.kw) / stride + 1;
  Tensor3 out(out_h, out_w, w.cout);
  for (int y = 0; y < out_h; ++y)
    for (int x = 0; x < out_w; ++x)
      for (int o = 0; o < w.cout; ++o) {
        double s = w.bias.empty() ? 0.0 : w.bias[o];
        for (int i = 0; i < w.kh; ++i)
          for (int j = 0; j < w.kw; ++j)
            for (int c = 0; c < w.cin; ++c) {
              const int sy = y * stride + i - pad.top, sx = x * stride + j - pad.left;
              if (sy < 0 || sx < 0 || sy >= in.h || sx >= in.w) continue;
              s += double(in.At(sy, sx, c)) * w.filters[((size_t(i) * w.kw + j) * w.cin + c) * w.cout + o];
            }
        out.At(y, x, o) = float(s);
      }
  return out;
}

inline void ExpectNear(const Tensor3& a, const Tensor3& b, double tol) {
  ASSERT_EQ(a.h, b.h);
  ASSERT_EQ(a.w, b.w);
  ASSERT_EQ(a.c, b.c);
  for (size_t i = 0; i < a.data.size(); ++i) ASSERT_NEAR(a.data[i], b.data[i], tol) << "index " << i;
}

// Writes a tiny TF.js manifest + shard: one float32 tensor and one uint8-quantised tensor.
inline std::filesystem::path WriteTinyTfjs(const std::filesystem::path& dir, size_t truncate_by = 0) {
  std::filesystem::create_directories(dir);
  const std::string manifest = R"([{"paths": ["w.bin"], "weights": [
    {"name": "a", "shape": [2, 2], "dtype": "float32"},
    {"name": "b", "shape": [3], "dtype": "float32",
     "quantization": {"dtype": "uint8", "scale": 0.5, "min": -1.0}}]}])";
  std::string bin(4 * 4 + 3, '\0');
  const float a[4] = {1.f, -2.f, 3.5f, 0.25f};
  std::memcpy(bin.data(), a, sizeof(a));
  bin[16] = char(0);
  bin[17] = char(4);
  bin[18] = char(255);
  bin.resize(bin.size() - truncate_by);
  EXPECT_TRUE(WriteFileAtomic(dir / "m.json", manifest).ok());
  EXPECT_TRUE(WriteFileAtomic(dir / "w.bin", bin).ok());
  return dir / "m.json";
}

}  // namespace icef::infer::testing
