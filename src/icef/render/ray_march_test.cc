#include "icef/render/ray_march.h"

#include <gtest/gtest.h>

#include <vector>

#include "icef/core/rng.h"
#include "icef/render/compositing.h"

namespace icef {
namespace {

// Rays with 0..max_count samples each, random densities (some rays opaque within a few samples,
// some never), colours and two extra channels.
struct Batch {
  RaySamples samples;
  std::vector<float> sigma, rgb, extras;
};

Batch RandomBatch(int rays, int max_count, uint64_t seed) {
  Rng rng(seed, StreamId("ray_march_test"));
  Batch b;
  for (int r = 0; r < rays; ++r) {
    const int count = static_cast<int>(rng.Uniform(0.0, max_count + 1.0));
    const double scale = r % 3 == 0 ? 0.5 : (r % 3 == 1 ? 20.0 : 200.0);
    b.samples.ray_offset.push_back(static_cast<int32_t>(b.samples.t.size()));
    b.samples.ray_count.push_back(count);
    double t = 0.3;
    for (int i = 0; i < count; ++i) {
      const double dt = rng.Uniform(0.01, 0.06);
      b.samples.t.push_back(float(t + 0.5 * dt));
      b.samples.dt.push_back(float(dt));
      t += dt;
      for (int a = 0; a < 3; ++a) b.samples.positions.push_back(0.f);
      b.sigma.push_back(float(scale * rng.Uniform(0.0, 1.0)));
      for (int a = 0; a < 3; ++a) b.rgb.push_back(float(rng.Uniform(0.0, 1.0)));
      for (int e = 0; e < 2; ++e) b.extras.push_back(float(rng.Uniform(-1.0, 1.0)));
    }
  }
  return b;
}

struct Marched {
  std::vector<float> color, opacity, depth, extras;
  int64_t evaluated = 0;
};

// Marches `b`, reading each round's rows from the full arrays through Sample(k, i).
Marched March(const Batch& b, float eps, int threads, int64_t target_rows, int min_per_ray = 4) {
  RayMarch march;
  march.Start(b.samples, 2);
  Marched m;
  std::vector<float> sigma, rgb, extras;
  while (march.NextRound(b.samples, target_rows, min_per_ray)) {
    const int64_t n = march.round_size();
    sigma.assign(n, 0.f), rgb.assign(3 * n, 0.f), extras.assign(2 * n, 0.f);
    for (int64_t k = 0; k < march.active(); ++k)
      for (int64_t i = march.round_begin(k); i < march.round_end(k); ++i) {
        const int64_t s = march.Sample(k, i);
        EXPECT_GE(s, b.samples.ray_offset[march.ray(k)]);
        EXPECT_LT(s, b.samples.ray_offset[march.ray(k)] + b.samples.ray_count[march.ray(k)]);
        sigma[i] = b.sigma[s];
        for (int a = 0; a < 3; ++a) rgb[3 * i + a] = b.rgb[3 * s + a];
        for (int e = 0; e < 2; ++e) extras[2 * i + e] = b.extras[2 * s + e];
      }
    march.Composite(b.samples, sigma.data(), rgb.data(), extras.data(), eps, Executor(threads));
    m.evaluated += n;
  }
  const float bg[3] = {0.2f, 0.5f, 0.9f};
  for (int64_t r = 0; r < b.samples.num_rays(); ++r) {
    float c[3];
    march.Color(r, bg, c);
    m.color.insert(m.color.end(), c, c + 3);
    m.opacity.push_back(march.opacity(r));
    m.depth.push_back(march.depth(r));
    for (int e = 0; e < 2; ++e) m.extras.push_back(march.extra(r, e));
  }
  return m;
}

TEST(RayMarchTest, MatchesCompositingEverySampleAndSkipsSamplesBehindOpaqueSurfaces) {
  const Batch b = RandomBatch(300, 40, 1);
  const float bg[3] = {0.2f, 0.5f, 0.9f};
  for (const float eps : {1e-4f, 1e-2f, 0.f}) {
    CompositeInputs<float> in{b.sigma,
                              b.rgb,
                              b.samples.t,
                              b.samples.dt,
                              b.samples.ray_offset,
                              b.samples.ray_count,
                              std::span<const float>(bg, 3)};
    CompositeOptions options;
    options.transmittance_eps = eps;
    CompositeOutputs<float> ref;
    CompositeForward(in, options, Executor(1), &ref);
    for (const int64_t target : {int64_t{1}, int64_t{64}, int64_t{1} << 16}) {
      SCOPED_TRACE(testing::Message() << "eps " << eps << " target " << target);
      const Marched m = March(b, eps, 2, target, target == 1 ? 1 : 4);
      int64_t used = 0;
      for (int64_t r = 0; r < b.samples.num_rays(); ++r) {
        // Same operations in the same order; only the compiler's fusing of multiply-adds (which
        // differs between optimisation levels) may move the last bit.
        for (int a = 0; a < 3; ++a)
          ASSERT_NEAR(m.color[3 * r + a], ref.color[3 * r + a], 1e-6) << "ray " << r;
        ASSERT_NEAR(m.opacity[r], ref.opacity[r], 1e-6) << "ray " << r;
        ASSERT_NEAR(m.depth[r], ref.depth[r], 1e-6) << "ray " << r;
        for (int e = 0; e < 2; ++e) {
          float expected = 0.f;
          for (int i = 0; i < b.samples.ray_count[r]; ++i) {
            const int64_t s = b.samples.ray_offset[r] + i;
            expected += ref.weights[s] * b.extras[2 * s + e];
          }
          ASSERT_NEAR(m.extras[2 * r + e], expected, 1e-6) << "ray " << r;
        }
        used += ref.num_used[r];
      }
      // Every used sample is evaluated, and nothing past a ray's last used sample beyond the
      // round it terminated in.
      EXPECT_GE(m.evaluated, used);
      if (eps > 0.f && target == 1) {
        EXPECT_EQ(m.evaluated, used);  // one sample per ray and round
      }
      if (eps > 0.f) {
        EXPECT_LT(m.evaluated, b.samples.size());
      } else {
        EXPECT_EQ(m.evaluated, b.samples.size());
      }
    }
  }
}

TEST(RayMarchTest, SameResultForAnyThreadCount) {
  const Batch b = RandomBatch(200, 30, 2);
  const Marched a = March(b, 1e-4f, 1, 256), c = March(b, 1e-4f, 2, 256);
  EXPECT_EQ(a.color, c.color);
  EXPECT_EQ(a.depth, c.depth);
  EXPECT_EQ(a.extras, c.extras);
  EXPECT_EQ(a.evaluated, c.evaluated);
}

TEST(RayMarchTest, RaysWithoutSamplesShowTheBackground) {
  RaySamples empty;
  empty.ray_offset = {0, 0};
  empty.ray_count = {0, 0};
  RayMarch march;
  march.Start(empty, 0);
  EXPECT_FALSE(march.NextRound(empty));
  const float bg[3] = {0.1f, 0.2f, 0.3f};
  float c[3];
  march.Color(1, bg, c);
  EXPECT_EQ(c[0], 0.1f);
  EXPECT_EQ(c[2], 0.3f);
  EXPECT_EQ(march.opacity(1), 0.f);
  EXPECT_EQ(march.depth(1), 0.f);
}

}  // namespace
}  // namespace icef
