// Each layer against a naive double-precision reference on random small tensors.
#include "icef/infer/cnn_layers.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "icef/infer/cnn_test_util.h"

namespace icef::infer {
namespace {

using namespace ::icef::infer::testing;

struct ConvCase {
  int h, w, cin, cout, k, stride;
  Padding pad;
  bool bias;
};

TEST(CnnLayersTest, Conv2dMatchesNaiveReference) {
  const ConvCase cases[] = {
      {9, 7, 3, 5, 3, 1, Padding::Uniform(1), true},     // 3x3 'same'
      {11, 10, 4, 6, 3, 2, Padding::Valid(), true},      // 3x3 stride 2 valid (odd and even sizes)
      {15, 15, 3, 4, 7, 2, Padding::Valid(), true},      // 7x7 stride 2 valid (face-id stem)
      {19, 17, 3, 4, 11, 4, Padding::Uniform(2), true},  // 11x11 stride 4 pad 2 (AlexNet conv1)
      {6, 8, 5, 3, 5, 1, Padding{2, 1, 0, 2}, false},    // asymmetric padding, no bias
      {5, 5, 2, 2, 1, 1, Padding::Valid(), false},       // 1x1
  };
  uint64_t item = 0;
  for (const ConvCase& c : cases) {
    SCOPED_TRACE("case " + std::to_string(item));
    const Tensor3 in = RandomTensor(c.h, c.w, c.cin, item);
    const ConvWeights w = RandomConv(c.k, c.k, c.cin, c.cout, c.bias, item);
    ExpectNear(Conv2d(in, w, c.stride, c.pad), NaiveConv(in, w, c.stride, c.pad), 1e-4);
    ++item;
  }
}

TEST(CnnLayersTest, Conv2dOutputSizes) {
  // The face-identity stem: 150 -> 72 (7x7/2 valid); down convs 35 -> 17, 17 -> 8, 8 -> 3, 4 -> 1.
  const ConvWeights stem = RandomConv(7, 7, 1, 1, false, 1);
  EXPECT_EQ(Conv2d(Tensor3(150, 150, 1), stem, 2, Padding::Valid()).h, 72);
  const ConvWeights k3 = RandomConv(3, 3, 1, 1, false, 2);
  for (auto [in, out] : {std::pair{35, 17}, {17, 8}, {8, 3}, {4, 1}})
    EXPECT_EQ(Conv2d(Tensor3(in, in, 1), k3, 2, Padding::Valid()).w, out) << in;
  EXPECT_EQ(Conv2d(Tensor3(17, 17, 1), k3, 1, Padding::Uniform(1)).h, 17);
}

TEST(CnnLayersTest, AffineAndRelu) {
  Tensor3 x = RandomTensor(4, 3, 3, 10);
  const Tensor3 original = x;
  const std::vector<float> scale = {2.f, -0.5f, 1.5f}, shift = {0.1f, 0.f, -0.3f};
  ChannelAffine(x, scale, shift);
  for (int y = 0; y < 4; ++y)
    for (int i = 0; i < 3; ++i)
      for (int c = 0; c < 3; ++c) EXPECT_FLOAT_EQ(x.At(y, i, c), original.At(y, i, c) * scale[c] + shift[c]);
  Relu(x);
  int zeros = 0;
  for (size_t i = 0; i < x.data.size(); ++i) {
    EXPECT_GE(x.data[i], 0.f);
    zeros += x.data[i] == 0.f;
  }
  EXPECT_GT(zeros, 0);  // the random input has negative values after the affine
}

TEST(CnnLayersTest, PoolingMatchesNaiveReference) {
  const Tensor3 in = RandomTensor(9, 8, 3, 20);
  for (auto [window, stride] : {std::pair{3, 2}, {2, 2}, {3, 1}}) {
    const Tensor3 mx = MaxPool(in, window, stride), av = AvgPool(in, window, stride);
    ASSERT_EQ(mx.h, (9 - window) / stride + 1);
    ASSERT_EQ(mx.w, (8 - window) / stride + 1);
    for (int y = 0; y < mx.h; ++y)
      for (int x = 0; x < mx.w; ++x)
        for (int c = 0; c < 3; ++c) {
          double m = -1e30, s = 0.0;
          for (int i = 0; i < window; ++i)
            for (int j = 0; j < window; ++j) {
              m = std::max(m, double(in.At(y * stride + i, x * stride + j, c)));
              s += in.At(y * stride + i, x * stride + j, c);
            }
          EXPECT_FLOAT_EQ(mx.At(y, x, c), float(m));
          EXPECT_NEAR(av.At(y, x, c), s / (window * window), 1e-6);
        }
  }
}

TEST(CnnLayersTest, ZeroExtendedAddPadsBottomRightAndChannels) {
  const Tensor3 pooled = RandomTensor(4, 4, 2, 30);  // avg-pooled shortcut: larger, fewer channels
  const Tensor3 branch = RandomTensor(3, 3, 5, 31);  // conv branch: smaller, more channels
  const Tensor3 sum = AddZeroExtended(pooled, branch);
  ASSERT_EQ(sum.h, 4);
  ASSERT_EQ(sum.w, 4);
  ASSERT_EQ(sum.c, 5);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x)
      for (int c = 0; c < 5; ++c) {
        const double a = c < 2 ? pooled.At(y, x, c) : 0.0;
        const double b = (y < 3 && x < 3) ? branch.At(y, x, c) : 0.0;
        EXPECT_FLOAT_EQ(sum.At(y, x, c), float(a + b)) << y << "," << x << "," << c;
      }
  const Tensor3 padded = ZeroPadTo(branch, 4, 5, 6);
  EXPECT_EQ(padded.At(3, 4, 5), 0.f);
  EXPECT_EQ(padded.At(2, 2, 4), branch.At(2, 2, 4));
}

TEST(CnnLayersTest, ResizeBilinearFollowsTfCoordinateConventions) {
  // One row 0, 10, 20, 30 doubled to 8 columns.
  Tensor3 row(1, 4, 1);
  for (int x = 0; x < 4; ++x) row.At(0, x, 0) = 10.f * x;
  auto values = [](const Tensor3& t) {
    std::vector<float> v;
    for (int x = 0; x < t.w; ++x) v.push_back(t.At(0, x, 0));
    return v;
  };
  // half_pixel_centers: source (o + 0.5) / 2 - 0.5 = -0.25, 0.25, 0.75, ... clamped at the edges.
  EXPECT_EQ(values(ResizeBilinear(row, 1, 8, false, true)),
            (std::vector<float>{0.f, 2.5f, 7.5f, 12.5f, 17.5f, 22.5f, 27.5f, 30.f}));
  // legacy: source o / 2.
  EXPECT_EQ(values(ResizeBilinear(row, 1, 8, false, false)),
            (std::vector<float>{0.f, 5.f, 10.f, 15.f, 20.f, 25.f, 30.f, 30.f}));
  // align_corners: source o * 3 / 7, the corners land on the corners.
  const std::vector<float> aligned = values(ResizeBilinear(row, 1, 8, true, false));
  for (int o = 0; o < 8; ++o) EXPECT_NEAR(aligned[size_t(o)], 30.f * o / 7.f, 1e-5f) << o;
  // Separable: a product of a row and a column ramp stays one, channel by channel.
  Tensor3 grid(3, 2, 2);
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 2; ++x)
      for (int c = 0; c < 2; ++c) grid.At(y, x, c) = float((y + 1) * (x + 2) * (c + 1));
  const Tensor3 up = ResizeBilinear(grid, 5, 4, true, false);
  for (int y = 0; y < 5; ++y)
    for (int x = 0; x < 4; ++x)
      EXPECT_NEAR(up.At(y, x, 1), 2.f * (1 + y * 2.f / 4) * (2 + x / 3.f), 1e-5f) << y << "," << x;
}

// The transposed convolution is the adjoint of the convolution: <conv(x), y> = <x, conv^T(y)>
// for every x and y, strides and paddings included.
TEST(CnnLayersTest, TransposedConvIsTheAdjointOfConv) {
  struct Case {
    int h, w, k, stride, pad, cin, cout;
  };
  for (const Case& c : {Case{8, 8, 2, 2, 0, 3, 2}, Case{7, 9, 3, 2, 1, 2, 4}, Case{6, 5, 3, 1, 1, 4, 3}}) {
    const Tensor3 x = RandomTensor(c.h, c.w, c.cin, 50 + c.k);
    const ConvWeights w = RandomConv(c.k, c.k, c.cin, c.cout, false, 60 + c.k);
    const Padding pad = Padding::Uniform(c.pad);
    const Tensor3 y = Conv2d(x, w, c.stride, pad);
    const Tensor3 r = RandomTensor(y.h, y.w, y.c, 70 + c.k);
    // Conv2d's filter is [kh, kw, cin, cout]; the transposed op reads [kh, kw, cout', cin'] with
    // cout' = cin (its output) and cin' = cout (its input): the same array.
    const Tensor3 back = TransposedConv2d(r, w.filters, c.k, c.k, c.cin, c.stride, c.h, c.w, c.pad, c.pad);
    double lhs = 0, rhs = 0;
    for (size_t i = 0; i < y.data.size(); ++i) lhs += double(y.data[i]) * r.data[i];
    for (size_t i = 0; i < x.data.size(); ++i) rhs += double(x.data[i]) * back.data[i];
    EXPECT_NEAR(lhs, rhs, 1e-4 * (1 + std::abs(lhs))) << c.h << "x" << c.w << " k" << c.k << " s" << c.stride;
  }
}

TEST(CnnLayersTest, GlobalMeanAndFullyConnected) {
  const Tensor3 in = RandomTensor(3, 5, 4, 40);
  const std::vector<float> mean = GlobalMean(in);
  ASSERT_EQ(mean.size(), 4u);
  for (int c = 0; c < 4; ++c) {
    double s = 0.0;
    for (int y = 0; y < 3; ++y)
      for (int x = 0; x < 5; ++x) s += in.At(y, x, c);
    EXPECT_NEAR(mean[c], s / 15.0, 1e-6);
  }
  const ConvWeights fc = RandomConv(1, 1, 4, 3, false, 41);  // [4, 3] matrix
  const std::vector<float> y = FullyConnected(mean, fc.filters, 3);
  for (int o = 0; o < 3; ++o) {
    double s = 0.0;
    for (int i = 0; i < 4; ++i) s += double(mean[i]) * fc.filters[i * 3 + o];
    EXPECT_NEAR(y[o], s, 1e-6);
  }
}

}  // namespace
}  // namespace icef::infer
