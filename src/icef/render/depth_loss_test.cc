#include "icef/render/depth_loss.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "icef/core/rng.h"

namespace icef {
namespace {

TEST(DepthLossTest, ZeroWhenTheWeightIsCentredOnTheTarget) {
  const std::vector<double> w = {0.0, 0.3, 0.4, 0.3, 0.0}, t = {1.0, 1.1, 1.2, 1.3, 1.4};
  std::vector<double> d(5, 0.0);
  EXPECT_NEAR(DepthMomentLossRay<double>(5, w.data(), t.data(), 1.2, 1.0, d.data()), 0.0, 1e-30);
  for (double g : d) EXPECT_NEAR(g, 0.0, 1e-15);
  // The same weight in front of the target costs (0.1 * 1)^2.
  std::fill(d.begin(), d.end(), 0.0);
  EXPECT_NEAR(DepthMomentLossRay<double>(5, w.data(), t.data(), 1.3, 1.0, d.data()), 0.01, 1e-14);
}

TEST(DepthLossTest, GradientMatchesCentralDifferences) {
  for (uint64_t seed = 0; seed < 4; ++seed) {
    Rng rng(seed, StreamId("depth_loss_test"));
    const int n = 20;
    std::vector<double> w(n), t(n), d(n, 0.0);
    double depth = 1.0;
    for (int i = 0; i < n; ++i) {
      depth += rng.Uniform(0.01, 0.1);
      t[i] = depth;
      w[i] = rng.Uniform(0.0, 0.1);
    }
    const double target = rng.Uniform(t[0], t[n - 1]), scale = rng.Uniform(0.5, 2.0);
    // d starts non-zero: the gradient is added, not written.
    std::vector<double> base(n);
    for (int i = 0; i < n; ++i) d[i] = base[i] = rng.Uniform(-1.0, 1.0);
    DepthMomentLossRay<double>(n, w.data(), t.data(), target, scale, d.data());
    std::vector<double> scratch(n);
    for (int k = 0; k < n; ++k) {
      const double h = 1e-6;
      std::vector<double> wp = w, wm = w;
      wp[k] += h;
      wm[k] -= h;
      const double lp = DepthMomentLossRay<double>(n, wp.data(), t.data(), target, scale, scratch.data());
      const double lm = DepthMomentLossRay<double>(n, wm.data(), t.data(), target, scale, scratch.data());
      EXPECT_NEAR(d[k] - base[k], scale * (lp - lm) / (2 * h), 1e-8) << "seed " << seed << " k " << k;
    }
  }
}

}  // namespace
}  // namespace icef
