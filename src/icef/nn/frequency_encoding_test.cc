#include "icef/nn/frequency_encoding.h"

#include <gtest/gtest.h>

#include "icef/testing/gradient_check.h"

namespace icef::nn {
namespace {

using testing::Dot;
using testing::MaxRelativeError;
using testing::RandomVector;

TEST(FrequencyEncodingTest, MatchesClosedFormAndLayout) {
  FrequencyEncodingOptions o;  // d = 3, N = 6, include input: 39 values
  ASSERT_EQ(o.output_dims(), 39);
  FrequencyEncoding enc(o);
  const double x[3] = {0.3, -0.7, 0.11};
  std::vector<double> y(39);
  FrequencyForward<double>(o, enc.weights_double().data(), 1, x, y.data());
  for (int i = 0; i < 3; ++i) EXPECT_EQ(y[i], x[i]);
  for (int k = 0; k < 6; ++k) {
    for (int i = 0; i < 3; ++i) {
      const double a = std::ldexp(M_PI, k) * x[i];
      EXPECT_NEAR(y[3 + 6 * k + i], std::sin(a), 1e-12);
      EXPECT_NEAR(y[3 + 6 * k + 3 + i], std::cos(a), 1e-12);
    }
  }
}

TEST(FrequencyEncodingTest, AnnealingWeights) {
  EXPECT_EQ(AnnealingWeight(0.0, 0), 0.0);
  EXPECT_NEAR(AnnealingWeight(0.5, 0), 0.5, 1e-12);
  EXPECT_EQ(AnnealingWeight(3.0, 2), 1.0);
  EXPECT_EQ(AnnealingWeight(3.0, 3), 0.0);
  FrequencyEncoding enc(FrequencyEncodingOptions{});
  EXPECT_EQ(enc.alpha(), 6.0);
  enc.SetAlpha(2.5);
  EXPECT_EQ(enc.weights()[1], 1.0f);
  EXPECT_NEAR(enc.weights()[2], 0.5f, 1e-6);
  EXPECT_EQ(enc.weights()[3], 0.0f);
  FrequencyEncodingOptions bad;
  bad.include_input = false;
  bad.num_frequencies = 0;
  EXPECT_FALSE(bad.Validate().ok());
}

TEST(FrequencyEncodingTest, BackwardAndJvpMatchFiniteDifferences) {
  FrequencyEncodingOptions o;
  o.input_dims = 4;
  o.num_frequencies = 5;
  FrequencyEncoding enc(o);
  enc.SetAlpha(3.4);  // partial annealing
  const int64_t n = 6;
  const int out = o.output_dims();
  const double* w = enc.weights_double().data();
  std::vector<double> x = RandomVector(n * 4, 2, 1, -1, 1);
  const std::vector<double> r = RandomVector(n * out, 2, 2, -1, 1);
  const std::vector<double> v = RandomVector(n * 4, 2, 3, -1, 1);
  auto forward = [&](const std::vector<double>& in) {
    std::vector<double> y(n * out);
    FrequencyForward<double>(o, w, n, in.data(), y.data());
    return y;
  };
  std::vector<double> dx(n * 4);
  FrequencyBackward<double>(o, w, n, x.data(), r.data(), dx.data());
  EXPECT_LT(MaxRelativeError(&x, dx, [&] { return Dot(forward(x), r); }), 1e-6);

  std::vector<double> y(n * out), jy(n * out);
  FrequencyJvp<double>(o, w, n, x.data(), v.data(), y.data(), jy.data());
  EXPECT_EQ(y, forward(x));
  const double h = 1e-6;
  std::vector<double> xp = x, xm = x;
  for (size_t i = 0; i < x.size(); ++i) {
    xp[i] += h * v[i];
    xm[i] -= h * v[i];
  }
  const std::vector<double> yp = forward(xp), ym = forward(xm);
  for (size_t i = 0; i < jy.size(); ++i) {
    const double fd = (yp[i] - ym[i]) / (2 * h);
    EXPECT_NEAR(jy[i], fd, 1e-6 * (std::abs(fd) + 1e-3));
  }
}

}  // namespace
}  // namespace icef::nn
