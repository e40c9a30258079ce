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
      {9, 7, 3, 5, 3, 1, Padding::Uniform(1), true},   // 3x3 'same'
      {11, 10, 4, 6, 3, 2, Padding::Valid(), true},    // 3x3 stride 2 valid (odd and even sizes)
      {15, 15, 3, 4, 7, 2, Padding::Valid(), true},    // 7x7 stride 2 valid (face-id stem)
      {19, 17, 3, 4, 11, 4, Padding::Uniform(2), true},  // 11x11 stride 4 pad 2 (AlexNet conv1)
      {6, 8, 5, 3, 5, 1, Padding{2, 1, 0, 2}, false},  // asymmetric padding, no bias
      {5, 5, 2, 2, 1, 1, Padding::Valid(), false},     // 1x1
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
