#include "icef/render/distortion_loss.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "icef/core/rng.h"

namespace icef {
namespace {

struct Ray1 {
  std::vector<double> w, t, dt;
};

Ray1 RandomRay(int n, uint64_t seed) {
  Rng rng(seed, StreamId("distortion_test"));
  Ray1 r;
  double t = 1.0;
  for (int i = 0; i < n; ++i) {
    const double dt = rng.Uniform(0.01, 0.2);
    r.dt.push_back(dt);
    r.t.push_back(t + 0.5 * dt);
    t += dt;
    r.w.push_back(rng.Uniform(0.0, 0.2));
  }
  return r;
}

double Naive(const Ray1& r) {
  double l = 0;
  for (size_t i = 0; i < r.w.size(); ++i) {
    for (size_t j = 0; j < r.w.size(); ++j) l += r.w[i] * r.w[j] * std::abs(r.t[i] - r.t[j]);
    l += r.w[i] * r.w[i] * r.dt[i] / 3;
  }
  return l;
}

TEST(DistortionLossTest, MatchesNaiveQuadraticSum) {
  for (uint64_t seed = 0; seed < 4; ++seed) {
    const Ray1 r = RandomRay(25, seed);
    EXPECT_NEAR(DistortionLossRay<double>(25, r.w.data(), r.t.data(), r.dt.data()), Naive(r), 1e-13);
  }
}

TEST(DistortionLossTest, ConcentratedWeightsCostLessThanSpreadOnes) {
  Ray1 r = RandomRay(10, 1);
  for (double& dt : r.dt) dt = 0.1;
  for (int i = 0; i < 10; ++i) r.t[i] = 1 + 0.1 * i;
  Ray1 spread = r, peak = r;
  for (int i = 0; i < 10; ++i) {
    spread.w[i] = 0.1;
    peak.w[i] = i == 4 ? 1.0 : 0.0;
  }
  EXPECT_LT(DistortionLossRay<double>(10, peak.w.data(), peak.t.data(), peak.dt.data()),
            DistortionLossRay<double>(10, spread.w.data(), spread.t.data(), spread.dt.data()));
}

TEST(DistortionLossTest, GradientMatchesCentralDifferences) {
  for (uint64_t seed = 0; seed < 4; ++seed) {
    const Ray1 r = RandomRay(15, 100 + seed);
    std::vector<double> g(15);
    DistortionLossRayBackward<double>(15, r.w.data(), r.t.data(), r.dt.data(), 1.0, g.data());
    for (int i = 0; i < 15; ++i) {
      Ray1 a = r, b = r;
      const double h = 1e-6;
      a.w[i] += h;
      b.w[i] -= h;
      const double fd = (Naive(a) - Naive(b)) / (2 * h);
      EXPECT_NEAR(g[i], fd, 1e-8 * (1 + std::abs(fd)));
    }
  }
}

TEST(DistortionLossTest, BatchedIsTheMeanOverRays) {
  const Ray1 a = RandomRay(5, 1), b = RandomRay(9, 2);
  std::vector<double> w = a.w, t = a.t, dt = a.dt;
  w.insert(w.end(), b.w.begin(), b.w.end());
  t.insert(t.end(), b.t.begin(), b.t.end());
  dt.insert(dt.end(), b.dt.begin(), b.dt.end());
  const std::vector<int32_t> offset = {0, 5, 14}, count = {5, 9, 0};
  std::vector<double> g;
  const double loss = DistortionLoss<double>(w, t, dt, offset, count, 2.0, Executor(2), &g);
  EXPECT_NEAR(loss, (Naive(a) + Naive(b)) / 3, 1e-13);
  std::vector<double> ga(5);
  DistortionLossRayBackward<double>(5, a.w.data(), a.t.data(), a.dt.data(), 2.0 / 3, ga.data());
  for (int i = 0; i < 5; ++i) EXPECT_DOUBLE_EQ(g[i], ga[i]);
}

}  // namespace
}  // namespace icef
