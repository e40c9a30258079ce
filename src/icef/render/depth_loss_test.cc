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
  EXPECT_NEAR(DepthMomentLossRay<double>(5, w.data(), t.data(), 1.2, DepthWindow<double>{}, 1.0, d.data()),
              0.0, 1e-30);
  for (double g : d) EXPECT_NEAR(g, 0.0, 1e-15);
  // The same weight in front of the target costs (0.1 * 1)^2.
  std::fill(d.begin(), d.end(), 0.0);
  EXPECT_NEAR(DepthMomentLossRay<double>(5, w.data(), t.data(), 1.3, DepthWindow<double>{}, 1.0, d.data()),
              0.01, 1e-14);
}

TEST(DepthLossTest, TheWindowBoundsThePullOfFarWeight) {
  // Weight centred on the target, plus a little where the ray leaves the head far behind it.
  const std::vector<double> w = {0.3, 0.4, 0.3, 0.0, 0.01}, t = {1.1, 1.2, 1.3, 1.5, 2.2};
  std::vector<double> open(5, 0.0), windowed(5, 0.0);
  const double l_open =
      DepthMomentLossRay<double>(5, w.data(), t.data(), 1.2, DepthWindow<double>{}, 1.0, open.data());
  const double l_windowed = DepthMomentLossRay<double>(5, w.data(), t.data(), 1.2,
                                                       DepthWindow<double>{0.15, 0.0}, 1.0, windowed.data());
  EXPECT_NEAR(l_open, 0.01 * 0.01, 1e-15);                    // (0.01 x 1.0)^2
  EXPECT_NEAR(l_windowed, 0.01 * 0.15 * 0.01 * 0.15, 1e-15);  // its offset clamped to the window
  // Inside the window the offsets are unchanged; beyond it, the far sample's lever is the window's.
  EXPECT_NEAR(windowed[0] / windowed[2], -1.0, 1e-12);
  EXPECT_NEAR(windowed[4] / windowed[3], 1.0, 1e-12);
  EXPECT_NEAR(open[4] / open[2], 1.0 / 0.1, 1e-9);
  EXPECT_NEAR(windowed[4] / windowed[2], 0.15 / 0.1, 1e-9);
}

TEST(DepthLossTest, BeyondTheReachCountsAsOneTerminationAtTheReach) {
  const DepthWindow<double> shape{0.15, 0.5};
  const std::vector<double> t = {1.1, 1.2, 1.3, 1.5, 2.2};
  // 0.99 of the weight centred on t*, 0.01 far behind it (beyond the reach): that 0.01 counts as if
  // at the reach, clamped to the window, and pulls on nothing itself.
  const std::vector<double> w = {0.3, 0.39, 0.3, 0.0, 0.01};
  std::vector<double> d(5, 0.0);
  EXPECT_NEAR(DepthMomentLossRay<double>(5, w.data(), t.data(), 1.2, shape, 1.0, d.data()),
              0.01 * 0.15 * 0.01 * 0.15, 1e-15);
  EXPECT_DOUBLE_EQ(d[4], 0.0);
  for (int i = 0; i < 3; ++i) EXPECT_LT(d[i], 0.0) << i;  // more weight within the window lowers the loss
  EXPECT_DOUBLE_EQ(d[3], 0.0);  // past the window's edge, a sample is as far as the reach
  // The same 0.01 passing through the ray (transmitted to the background) costs the same.
  const std::vector<double> through = {0.3, 0.39, 0.3, 0.0, 0.0};
  std::vector<double> d2(5, 0.0);
  EXPECT_NEAR(DepthMomentLossRay<double>(5, through.data(), t.data(), 1.2, shape, 1.0, d2.data()),
              0.01 * 0.15 * 0.01 * 0.15, 1e-15);
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(d2[i], d[i], 1e-15) << i;
  // A transparent ray cannot meet the prior: it costs the window squared.
  const std::vector<double> none(5, 0.0);
  std::vector<double> d3(5, 0.0);
  EXPECT_NEAR(DepthMomentLossRay<double>(5, none.data(), t.data(), 1.2, shape, 1.0, d3.data()), 0.15 * 0.15,
              1e-15);
  EXPECT_LT(d3[1], 0.0);
  // Fully opaque and centred: zero.
  const std::vector<double> opaque = {0.3, 0.4, 0.3, 0.0, 0.0};
  EXPECT_NEAR(DepthMomentLossRay<double>(5, opaque.data(), t.data(), 1.2, shape, 1.0, d3.data()), 0.0, 1e-30);
}

TEST(DepthLossTest, GradientMatchesCentralDifferences) {
  for (uint64_t seed = 0; seed < 8; ++seed) {
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
    // Half the seeds with a window, half with a reach (the offsets' kinks lie between samples, never
    // on one: the gradient is with respect to the weights).
    const DepthWindow<double> window{seed % 2 ? rng.Uniform(0.05, 0.3) : 0.0,
                                     seed % 4 >= 2 ? rng.Uniform(0.1, 0.5) : 0.0};
    // d starts non-zero: the gradient is added, not written.
    std::vector<double> base(n);
    for (int i = 0; i < n; ++i) d[i] = base[i] = rng.Uniform(-1.0, 1.0);
    DepthMomentLossRay<double>(n, w.data(), t.data(), target, window, scale, d.data());
    std::vector<double> scratch(n);
    for (int k = 0; k < n; ++k) {
      const double h = 1e-6;
      std::vector<double> wp = w, wm = w;
      wp[k] += h;
      wm[k] -= h;
      const double lp =
          DepthMomentLossRay<double>(n, wp.data(), t.data(), target, window, scale, scratch.data());
      const double lm =
          DepthMomentLossRay<double>(n, wm.data(), t.data(), target, window, scale, scratch.data());
      EXPECT_NEAR(d[k] - base[k], scale * (lp - lm) / (2 * h), 1e-8) << "seed " << seed << " k " << k;
    }
  }
}

}  // namespace
}  // namespace icef
