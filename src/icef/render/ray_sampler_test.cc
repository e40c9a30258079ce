#include "icef/render/ray_sampler.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "icef/core/rng.h"
#include "icef/render/render_test_util.h"

namespace icef {
namespace {

using testing_render::RandomRays;

TEST(RaySamplerTest, FixedCountStratifiedInsideAabbSortedAndContiguous) {
  const Aabb aabb;
  const std::vector<Ray> rays = RandomRays(50, 1);
  RaySamplerOptions options;
  options.num_samples = 16;
  RaySamples s;
  SampleRays(rays, aabb, options, nullptr, 7, 3, Executor(2), &s);
  ASSERT_EQ(s.num_rays(), 50);
  for (int r = 0; r < 50; ++r) {
    const Interval iv = *aabb.Intersect(rays[r]);
    ASSERT_EQ(s.ray_count[r], 16);
    const int o = s.ray_offset[r];
    for (int i = 0; i < 16; ++i) {
      const int k = o + i;
      EXPECT_NEAR(s.dt[k], (iv.t_far - iv.t_near) / 16, 1e-5);
      EXPECT_GE(s.t[k], iv.t_near + i * s.dt[k] - 1e-4);
      EXPECT_LE(s.t[k], iv.t_near + (i + 1) * s.dt[k] + 1e-4);
      const Vec3f p(s.positions[3 * k], s.positions[3 * k + 1], s.positions[3 * k + 2]);
      EXPECT_LT((p - rays[r].At(s.t[k])).norm(), 1e-5);
      EXPECT_TRUE((p.array() >= -1.0001f).all() && (p.array() <= 1.0001f).all());
      if (i > 0) {
        EXPECT_NEAR(s.t[k] - s.t[k - 1], 0.5f * (s.dt[k] + s.dt[k - 1]), 1e-4);
      }
    }
  }
}

TEST(RaySamplerTest, DeterministicAcrossThreadCountsAndVariesWithStep) {
  const std::vector<Ray> rays = RandomRays(100, 2);
  RaySamplerOptions options;
  RaySamples a, b, c;
  SampleRays(rays, Aabb(), options, nullptr, 7, 3, Executor(1), &a);
  SampleRays(rays, Aabb(), options, nullptr, 7, 3, Executor(2), &b);
  SampleRays(rays, Aabb(), options, nullptr, 7, 4, Executor(2), &c);
  EXPECT_EQ(a.t, b.t);
  EXPECT_EQ(a.positions, b.positions);
  EXPECT_NE(a.t, c.t);
}

TEST(RaySamplerTest, MidpointsWithoutStratification) {
  const std::vector<Ray> rays = {Ray{Vec3f(0, 0, 3), Vec3f(0, 0, -1)}};
  RaySamplerOptions options;
  options.num_samples = 4;
  options.stratified = false;
  RaySamples s;
  SampleRays(rays, Aabb(), options, nullptr, 0, 0, Executor(1), &s);
  ASSERT_EQ(s.size(), 4);
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(s.t[i], 2.f + 0.5f * (i + 0.5f), 1e-6);
}

TEST(RaySamplerTest, RaysMissingTheAabbGetNoSamples) {
  const std::vector<Ray> rays = {Ray{Vec3f(0, 0, 3), Vec3f(0, 1, 0)}, Ray{Vec3f(0, 0, 3), Vec3f(0, 0, -1)}};
  RaySamples s;
  SampleRays(rays, Aabb(), RaySamplerOptions(), nullptr, 0, 0, Executor(1), &s);
  EXPECT_EQ(s.ray_count[0], 0);
  EXPECT_EQ(s.ray_count[1], RaySamplerOptions{}.num_samples);
  EXPECT_EQ(s.ray_offset[1], 0);
}

TEST(RaySamplerTest, MarchingWithConeAngleGrowsTheStep) {
  const std::vector<Ray> rays = {Ray{Vec3f(0, 0, 3), Vec3f(0, 0, -1)}};
  RaySamplerOptions options;
  options.step_size = 0.01f;
  options.cone_angle = 0.005f;
  RaySamples s;
  SampleRays(rays, Aabb(), options, nullptr, 1, 1, Executor(1), &s);
  ASSERT_GT(s.size(), 50);
  for (int64_t k = 0; k < s.size(); ++k) {
    EXPECT_NEAR(s.dt[k], std::max(0.01f, 0.005f * s.t[k]), 1e-4);
    EXPECT_GE(s.t[k], 2.f);
    EXPECT_LT(s.t[k], 4.f);
    if (k > 0) {
      EXPECT_NEAR(s.t[k] - s.t[k - 1], 0.5f * (s.dt[k] + s.dt[k - 1]), 1e-4);
    }
  }
  // With step 0.01 and cone 0.005 * t (t in [2, 4]) the step is 0.01 .. 0.02: between 100 and 200 samples.
  EXPECT_GE(s.size(), 100);
  EXPECT_LE(s.size(), 201);
  options.max_samples = 10;
  SampleRays(rays, Aabb(), options, nullptr, 1, 1, Executor(1), &s);
  EXPECT_EQ(s.size(), 10);
}

TEST(RaySamplerTest, OccupancyGridSkipsEmptyCells) {
  OccupancyGridOptions grid_options;
  grid_options.resolution = 8;
  grid_options.dilation = 0;
  OccupancyGrid grid(Aabb(), grid_options);
  grid.Fill(false);  // forget the all-occupied start
  // Density only where z > 0.
  grid.Update(
      [](const float* p, int64_t n, float* sigma) {
        for (int64_t i = 0; i < n; ++i) sigma[i] = p[3 * i + 2] > 0.f ? 10.f : 0.f;
      },
      1, 0);
  const std::vector<Ray> rays = RandomRays(40, 3);
  RaySamples full, skipped;
  SampleRays(rays, Aabb(), RaySamplerOptions(), nullptr, 5, 0, Executor(2), &full);
  SampleRays(rays, Aabb(), RaySamplerOptions(), &grid, 5, 0, Executor(2), &skipped);
  EXPECT_LT(skipped.size(), full.size());
  EXPECT_GT(skipped.size(), 0);
  int64_t expected = 0;
  for (int64_t k = 0; k < full.size(); ++k) expected += full.positions[3 * k + 2] > 0.f ? 1 : 0;
  EXPECT_EQ(skipped.size(), expected);
  for (int64_t k = 0; k < skipped.size(); ++k) EXPECT_GT(skipped.positions[3 * k + 2], 0.f);
}

TEST(RaySamplerTest, ValidateRejectsBadOptions) {
  RaySamplerOptions o;
  EXPECT_TRUE(o.Validate().ok());
  o.num_samples = 0;
  EXPECT_FALSE(o.Validate().ok());
  o = RaySamplerOptions();
  o.cone_angle = -1;
  EXPECT_FALSE(o.Validate().ok());
}

}  // namespace
}  // namespace icef
