#include "icef/render/importance_sampler.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "icef/core/rng.h"
#include "icef/render/render_test_util.h"

namespace icef {
namespace {

using testing_render::RandomRays;

RaySamples Coarse(const std::vector<Ray>& rays, int per_ray, uint64_t seed) {
  RaySamplerOptions options;
  options.num_samples = per_ray;
  RaySamples s;
  SampleRays(rays, Aabb(), options, nullptr, seed, 0, Executor(2), &s);
  return s;
}

// A slab of density `density` where the ray's t lies within [center - half, center + half] of its
// aabb interval's middle; zero elsewhere.
std::vector<float> SlabDensity(const RaySamples& s, float density, float half) {
  std::vector<float> sigma(s.size(), 0.f);
  for (int64_t r = 0; r < s.num_rays(); ++r) {
    const int64_t o = s.ray_offset[r], m = s.ray_count[r];
    if (m == 0) continue;
    const float mid = 0.5f * (s.t[o] + s.t[o + m - 1]);
    for (int64_t i = o; i < o + m; ++i)
      if (std::abs(s.t[i] - mid) <= half) sigma[i] = density;
  }
  return sigma;
}

TEST(ImportanceSamplerTest, FineSamplesTileTheCoarseIntervalsInOrder) {
  const std::vector<Ray> rays = RandomRays(40, 1);
  const RaySamples coarse = Coarse(rays, 24, 5);
  const std::vector<float> sigma = SlabDensity(coarse, 30.f, 0.15f);
  ImportanceOptions options;
  options.num_samples = 32;
  RaySamples fine;
  ResampleRays(rays, coarse, sigma, options, 9, 4, Executor(2), &fine);
  ASSERT_EQ(fine.num_rays(), 40);
  for (int r = 0; r < 40; ++r) {
    ASSERT_EQ(fine.ray_count[r], 32);
    const int64_t o = fine.ray_offset[r], c0 = coarse.ray_offset[r], m = coarse.ray_count[r];
    double covered = 0;
    for (int64_t k = o; k < o + 32; ++k) {
      EXPECT_GT(fine.dt[k], 0.f);
      covered += fine.dt[k];
      const Vec3f p(fine.positions[3 * k], fine.positions[3 * k + 1], fine.positions[3 * k + 2]);
      EXPECT_LT((p - rays[r].At(fine.t[k])).norm(), 1e-5);
      // Inside exactly one coarse interval, which it subdivides.
      int inside = 0;
      for (int64_t i = c0; i < c0 + m; ++i) {
        const float lo = coarse.t[i] - 0.5f * coarse.dt[i], hi = coarse.t[i] + 0.5f * coarse.dt[i];
        if (fine.t[k] - 0.5f * fine.dt[k] >= lo - 1e-5f && fine.t[k] + 0.5f * fine.dt[k] <= hi + 1e-5f)
          ++inside;
      }
      EXPECT_EQ(inside, 1) << "ray " << r << " sample " << k - o;
      if (k > o)
        EXPECT_GE(fine.t[k] - 0.5f * fine.dt[k],
                  fine.t[k - 1] + 0.5f * fine.dt[k - 1] - 1e-5f);  // no overlap
    }
    double length = 0;
    for (int64_t i = c0; i < c0 + m; ++i) length += coarse.dt[i];
    EXPECT_LE(covered, length + 1e-4);
  }
}

TEST(ImportanceSamplerTest, SamplesGatherWhereTheWeightIs) {
  // An opaque slab: nearly all weight in the coarse interval(s) at its front face; with uniform = 0.1,
  // at least 90 % of the fine samples go there, and the strata there are that much finer.
  const std::vector<Ray> rays = RandomRays(30, 2);
  const RaySamples coarse = Coarse(rays, 32, 6);
  const std::vector<float> sigma = SlabDensity(coarse, 1e4f, 0.3f);
  ImportanceOptions options;
  options.num_samples = 40;
  options.uniform = 0.1f;
  RaySamples fine;
  ResampleRays(rays, coarse, sigma, options, 1, 0, Executor(1), &fine);
  for (int r = 0; r < 30; ++r) {
    const int64_t c0 = coarse.ray_offset[r], m = coarse.ray_count[r];
    int64_t front = -1;
    for (int64_t i = c0; i < c0 + m && front < 0; ++i)
      if (sigma[i] > 0) front = i;
    ASSERT_GE(front, 0);
    const float lo = coarse.t[front] - 0.5f * coarse.dt[front],
                hi = coarse.t[front] + 0.5f * coarse.dt[front];
    int there = 0;
    for (int64_t k = fine.ray_offset[r]; k < fine.ray_offset[r] + 40; ++k)
      if (fine.t[k] > lo && fine.t[k] < hi) ++there;
    EXPECT_GE(there, 36) << "ray " << r;  // 0.9 * 40 from the weight plus its share of the uniform part
    EXPECT_LE(there, 40);
  }
}

TEST(ImportanceSamplerTest, EmptyRaysSpreadByLengthAndMissesStayEmpty) {
  std::vector<Ray> rays = RandomRays(10, 3);
  rays.push_back(Ray{Vec3f(5, 5, 5), Vec3f(1, 0, 0)});  // misses the aabb: no coarse samples
  const RaySamples coarse = Coarse(rays, 16, 7);
  ASSERT_EQ(coarse.ray_count[10], 0);
  const std::vector<float> sigma(coarse.size(), 0.f);
  ImportanceOptions options;
  options.num_samples = 32;
  RaySamples fine;
  ResampleRays(rays, coarse, sigma, options, 2, 0, Executor(2), &fine);
  EXPECT_EQ(fine.ray_count[10], 0);
  for (int r = 0; r < 10; ++r) {
    ASSERT_EQ(fine.ray_count[r], 32);
    // Equal coarse strata and no weight: two fine samples per coarse interval, each half as deep.
    for (int64_t k = fine.ray_offset[r]; k < fine.ray_offset[r] + 32; ++k)
      EXPECT_NEAR(fine.dt[k], 0.5f * coarse.dt[coarse.ray_offset[r]], 1e-5f);
  }
}

TEST(ImportanceSamplerTest, DeterministicForAnyThreadCountAndJitteredBySeed) {
  const std::vector<Ray> rays = RandomRays(64, 4);
  const RaySamples coarse = Coarse(rays, 20, 8);
  const std::vector<float> sigma = SlabDensity(coarse, 5.f, 0.4f);
  ImportanceOptions options;
  options.num_samples = 24;
  RaySamples a, b, c;
  ResampleRays(rays, coarse, sigma, options, 11, 3, Executor(1), &a);
  ResampleRays(rays, coarse, sigma, options, 11, 3, Executor(4), &b);
  ResampleRays(rays, coarse, sigma, options, 11, 4, Executor(1), &c);
  EXPECT_EQ(a.t, b.t);
  EXPECT_EQ(a.dt, b.dt);
  EXPECT_NE(a.t, c.t);  // another step deals the counts with another jitter
}

TEST(ImportanceSamplerTest, OptionsValidate) {
  ImportanceOptions o;
  EXPECT_TRUE(o.Validate().ok());
  o.uniform = 1.5f;
  EXPECT_FALSE(o.Validate().ok());
  o.uniform = 0.1f;
  o.num_samples = -1;
  EXPECT_FALSE(o.Validate().ok());
}

}  // namespace
}  // namespace icef
