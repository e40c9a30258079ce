#include "icef/nn/sh_encoding.h"

#include <gtest/gtest.h>

#include "icef/testing/gradient_check.h"

namespace icef::nn {
namespace {

using testing::Dot;
using testing::MaxRelativeError;
using testing::RandomVector;

TEST(ShEncodingTest, BasisIsOrthonormalOnTheSphere) {
  // Monte-Carlo-free check: quadrature over a fine (theta, phi) grid.
  const int nt = 200, np = 400;
  double gram[16][16] = {};
  for (int i = 0; i < nt; ++i) {
    const double theta = (i + 0.5) * M_PI / nt;
    for (int j = 0; j < np; ++j) {
      const double phi = (j + 0.5) * 2 * M_PI / np;
      const double x = std::sin(theta) * std::cos(phi), y = std::sin(theta) * std::sin(phi),
                   z = std::cos(theta);
      double b[16];
      ShBasis<double>(4, x, y, z, b);
      const double dA = std::sin(theta) * (M_PI / nt) * (2 * M_PI / np);
      for (int a = 0; a < 16; ++a)
        for (int c = 0; c < 16; ++c) gram[a][c] += b[a] * b[c] * dA;
    }
  }
  for (int a = 0; a < 16; ++a)
    for (int c = 0; c < 16; ++c) EXPECT_NEAR(gram[a][c], a == c ? 1.0 : 0.0, 2e-3) << a << "," << c;
}

TEST(ShEncodingTest, InputGradientMatchesFiniteDifferences) {
  for (int degree = 1; degree <= 4; ++degree) {
    const int64_t n = 5;
    const int out = degree * degree;
    std::vector<double> d = RandomVector(n * 3, 7, degree, -1, 1);
    const std::vector<double> r = RandomVector(n * out, 7, 10 + degree, -1, 1);
    auto loss = [&] {
      std::vector<double> y(n * out);
      ShForward<double>(degree, n, d.data(), y.data());
      return Dot(y, r);
    };
    std::vector<double> dd(n * 3);
    ShBackward<double>(degree, n, d.data(), r.data(), dd.data());
    if (degree == 1) {
      for (double g : dd) EXPECT_EQ(g, 0.0);
    } else {
      EXPECT_LT(MaxRelativeError(&d, dd, loss), 1e-6) << "degree " << degree;
    }
  }
  EXPECT_FALSE(ShEncodingOptions{5}.Validate().ok());
}

}  // namespace
}  // namespace icef::nn
