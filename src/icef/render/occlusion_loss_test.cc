#include "icef/render/occlusion_loss.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "icef/core/rng.h"

namespace icef {
namespace {

struct Ray1 {
  std::vector<double> w, sigma, dt;
};

Ray1 RandomRay(int n, uint64_t seed) {
  Rng rng(seed, StreamId("occlusion_test"));
  Ray1 r;
  for (int i = 0; i < n; ++i) {
    r.dt.push_back(rng.Uniform(0.01, 0.2));
    r.sigma.push_back(rng.Uniform(0.0, 30.0));
    r.w.push_back(rng.Uniform(0.0, 0.2));
  }
  return r;
}

TEST(OcclusionLossTest, GradientMatchesFiniteDifferencesWithOcclusionHeld) {
  for (uint64_t seed = 1; seed <= 5; ++seed) {
    Ray1 r = RandomRay(24, seed);
    const int n = static_cast<int>(r.w.size());
    std::vector<double> grad(n, 0.0);
    OcclusionLossRay<double>(n, r.w.data(), r.sigma.data(), r.dt.data(), 1.7, grad.data());
    for (int k = 0; k < n; ++k) {
      const double h = 1e-6 * std::max(1.0, r.sigma[k]);
      Ray1 p = r, m = r;
      p.sigma[k] += h;
      m.sigma[k] -= h;
      const double fd = 1.7 *
                        (OcclusionLossRay<double>(n, p.w.data(), p.sigma.data(), p.dt.data(), 0.0, nullptr) -
                         OcclusionLossRay<double>(n, m.w.data(), m.sigma.data(), m.dt.data(), 0.0, nullptr)) /
                        (2 * h);
      EXPECT_NEAR(grad[k], fd, 1e-7 * std::max(1.0, std::abs(fd))) << "seed " << seed << " sample " << k;
    }
  }
}

// With per-sample factors m_i: the gradient of sum_i m_i o_i alpha_i, o_i held.
TEST(OcclusionLossTest, MaskedGradientMatchesFiniteDifferences) {
  for (uint64_t seed = 11; seed <= 15; ++seed) {
    Ray1 r = RandomRay(24, seed);
    const int n = static_cast<int>(r.w.size());
    Rng rng(seed, StreamId("occlusion_mask"));
    std::vector<double> m(n);
    for (double& v : m) v = rng.Uniform(0.0, 1.0);
    std::vector<double> grad(n, 0.0);
    OcclusionLossRay<double>(n, r.w.data(), r.sigma.data(), r.dt.data(), 0.6, grad.data(), m.data());
    for (int k = 0; k < n; ++k) {
      const double h = 1e-6 * std::max(1.0, r.sigma[k]);
      Ray1 p = r, q = r;
      p.sigma[k] += h;
      q.sigma[k] -= h;
      const double fd =
          0.6 *
          (OcclusionLossRay<double>(n, p.w.data(), p.sigma.data(), p.dt.data(), 0.0, nullptr, m.data()) -
           OcclusionLossRay<double>(n, q.w.data(), q.sigma.data(), q.dt.data(), 0.0, nullptr, m.data())) /
          (2 * h);
      EXPECT_NEAR(grad[k], fd, 1e-7 * std::max(1.0, std::abs(fd))) << "seed " << seed << " sample " << k;
    }
  }
}

// m = 0 leaves a sample alone (no cost, no gradient); m = 1 everywhere is the unmasked prior.
TEST(OcclusionLossTest, MaskSelectsTheSamplesItActsOn) {
  Ray1 r = RandomRay(16, 3);
  const int n = static_cast<int>(r.w.size());
  std::vector<double> ones(n, 1.0), half(n, 1.0);
  for (int i = n / 2; i < n; ++i) half[i] = 0.0;
  std::vector<double> g_plain(n, 0.0), g_ones(n, 0.0), g_half(n, 0.0);
  const double plain =
      OcclusionLossRay<double>(n, r.w.data(), r.sigma.data(), r.dt.data(), 1.0, g_plain.data());
  const double all =
      OcclusionLossRay<double>(n, r.w.data(), r.sigma.data(), r.dt.data(), 1.0, g_ones.data(), ones.data());
  const double front =
      OcclusionLossRay<double>(n, r.w.data(), r.sigma.data(), r.dt.data(), 1.0, g_half.data(), half.data());
  EXPECT_DOUBLE_EQ(all, plain);
  EXPECT_GT(front, 0.0);
  EXPECT_LT(front, plain);
  for (int i = 0; i < n; ++i) {
    EXPECT_DOUBLE_EQ(g_ones[i], g_plain[i]) << i;
    if (i < n / 2)
      EXPECT_DOUBLE_EQ(g_half[i], g_plain[i]) << i;
    else
      EXPECT_EQ(g_half[i], 0.0) << i;
  }
}

TEST(OcclusionLossTest, OnlyDensityBehindAbsorbedLightCosts) {
  // Haze in front of the surface and the surface itself are free; haze behind it is not.
  const std::vector<double> dt(4, 0.1);
  std::vector<double> sigma = {2.0, 2.0, 500.0, 2.0};
  // Weights of this ray as the compositor would give them.
  std::vector<double> w(4);
  double transmittance = 1;
  for (int i = 0; i < 4; ++i) {
    const double a = 1 - std::exp(-sigma[i] * dt[i]);
    w[i] = transmittance * a;
    transmittance *= 1 - a;
  }
  std::vector<double> grad(4, 0.0);
  const double loss = OcclusionLossRay<double>(4, w.data(), sigma.data(), dt.data(), 1.0, grad.data());
  EXPECT_EQ(grad[0], 0.0);            // nothing absorbed before the first sample
  EXPECT_LT(grad[1], 0.2 * grad[3]);  // in front of the surface: little absorbed yet
  EXPECT_GT(grad[3], 0.05);           // behind the surface: pushed down
  EXPECT_NEAR(grad[2], 0.0, 1e-12);   // the surface itself is saturated
  // Removing the haze behind the surface lowers the loss.
  sigma[3] = 0.0;
  EXPECT_LT(OcclusionLossRay<double>(4, w.data(), sigma.data(), dt.data(), 1.0, nullptr), loss);
}

}  // namespace
}  // namespace icef
