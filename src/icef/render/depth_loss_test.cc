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
  EXPECT_NEAR(DepthMomentLossRay<double>(5, w.data(), t.data(), 1.2, DepthWindow<double>{}, 1.0, d.data()), 0.0, 1e-30);
  for (double g : d) EXPECT_NEAR(g, 0.0, 1e-15);
  // The same weight in front of the target costs (0.1 * 1)^2.
  std::fill(d.begin(), d.end(), 0.0);
  EXPECT_NEAR(DepthMomentLossRay<double>(5, w.data(), t.data(), 1.3, DepthWindow<double>{}, 1.0, d.data()), 0.01, 1e-14);
}

TEST(DepthLossTest, TheWindowBoundsThePullOfFarWeight) {
  // Weight centred on the target, plus a little where the ray leaves the head far behind it.
  const std::vector<double> w = {0.3, 0.4, 0.3, 0.0, 0.01}, t = {1.1, 1.2, 1.3, 1.5, 2.2};
  std::vector<double> open(5, 0.0), windowed(5, 0.0);
  const double l_open = DepthMomentLossRay<double>(5, w.data(), t.data(), 1.2, DepthWindow<double>{}, 1.0, open.data());
  const double l_windowed = DepthMomentLossRay<double>(5, w.data(), t.data(), 1.2, DepthWindow<double>{0.15, 0.0}, 1.0, windowed.data());
  EXPECT_NEAR(l_open, 0.01 * 0.01, 1e-15);           // (0.01 x 1.0)^2
  EXPECT_NEAR(l_windowed, 0.01 * 0.15 * 0.01 * 0.15, 1e-15);  // its offset clamped to the window
  // Inside the window the offsets are unchanged; beyond it, the far sample's lever is the window's.
  EXPECT_NEAR(windowed[0] / windowed[2], -1.0, 1e-12);
  EXPECT_NEAR(windowed[4] / windowed[3], 1.0, 1e-12);
  EXPECT_NEAR(open[4] / open[2], 1.0 / 0.1, 1e-9);
  EXPECT_NEAR(windowed[4] / windowed[2], 0.15 / 0.1, 1e-9);
}

TEST(DepthLossTest, WeightBeyondTheReachIsLeftOut) {
  // The same ray: with a reach of 0.5 the far sample (1.0 behind t*) is left out, so the ray's
  // weight is centred and costs nothing, and the far sample gets no gradient.
  const std::vector<double> w = {0.3, 0.4, 0.3, 0.0, 0.01}, t = {1.1, 1.2, 1.3, 1.5, 2.2};
  std::vector<double> d(5, 0.0);
  EXPECT_NEAR(DepthMomentLossRay<double>(5, w.data(), t.data(), 1.2, DepthWindow<double>{0.15, 0.5}, 1.0, d.data()),
              0.0, 1e-30);
  for (double g : d) EXPECT_NEAR(g, 0.0, 1e-15);
  // Weight inside the reach still counts: 0.01 at 0.3 behind, clamped to the window.
  const std::vector<double> w2 = {0.3, 0.4, 0.3, 0.01, 0.01};
  EXPECT_NEAR(DepthMomentLossRay<double>(5, w2.data(), t.data(), 1.2, DepthWindow<double>{0.15, 0.5}, 1.0, d.data()),
              0.01 * 0.15 * 0.01 * 0.15, 1e-15);
  EXPECT_DOUBLE_EQ(d[4], 0.0);
  EXPECT_GT(d[3], 0.0);
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
    const DepthWindow<double> window{seed % 2 ? rng.Uniform(0.05, 0.3) : 0.0, seed % 4 >= 2 ? rng.Uniform(0.2, 1.0) : 0.0};
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
      const double lp = DepthMomentLossRay<double>(n, wp.data(), t.data(), target, window, scale, scratch.data());
      const double lm = DepthMomentLossRay<double>(n, wm.data(), t.data(), target, window, scale, scratch.data());
      EXPECT_NEAR(d[k] - base[k], scale * (lp - lm) / (2 * h), 1e-8) << "seed " << seed << " k " << k;
    }
  }
}

}  // namespace
}  // namespace icef
