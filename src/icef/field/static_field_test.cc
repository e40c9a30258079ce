#include "icef/field/static_field.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <span>
#include <string>
#include <vector>

namespace icef {
namespace {

double MaxAbs(const std::vector<float>& v) {
  double m = 0;
  for (float x : v) m = std::max(m, std::abs(double(x)));
  return m;
}

double MaxAbsDiff(const std::vector<float>& a, const std::vector<float>& b) {
  double m = 0;
  for (size_t i = 0; i < a.size(); ++i) m = std::max(m, std::abs(double(a[i]) - double(b[i])));
  return m;
}

// ForwardDensity + ForwardColor(rows) give every sample its density and only the samples `rows` a
// colour (the rest rgb 0); Backward then reads no colour gradient elsewhere and gives the parameter
// and position gradients of a full Forward whose colour gradient is zero elsewhere (what training's
// samples past a ray's termination, and its unseen-view rays, get from the losses).
TEST(StaticFieldTest, ColouringSomeSamplesIsAFullPassWithoutTheOthersColour) {
  StaticFieldOptions options;
  options.grid.num_levels = 4;
  options.grid.log2_table_size = 10;
  options.grid.finest_resolution = 64.0;
  options.grid.init_scale = 0.5f;
  options.density_hidden = 32;
  options.color_hidden = {32};
  options.bf16_training = options.bf16_inference = false;
  nn::ParameterStore store;
  StaticField field(options, Aabb{}, &store, "static", 0, 1);
  field.Initialize(7);

  const int64_t n = 300;
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-0.9f, 0.9f);
  std::vector<float> positions(3 * n), directions(3 * n), d_sigma(n);
  for (int64_t i = 0; i < n; ++i) {
    const Vec3f d = Vec3f(u(rng), u(rng), u(rng)).normalized();
    for (int a = 0; a < 3; ++a) {
      positions[3 * i + a] = u(rng);
      directions[3 * i + a] = d[a];
    }
    d_sigma[i] = u(rng);
  }
  std::vector<int32_t> scattered;  // runs of samples, as rays composite them
  for (int32_t i = 0; i < n; ++i)
    if ((i / 7) % 3 != 1) scattered.push_back(i);
  std::vector<int32_t> all(n);
  for (int32_t i = 0; i < n; ++i) all[i] = i;
  const Executor ex(2);
  for (const std::vector<int32_t>& rows : {std::vector<int32_t>{}, std::vector<int32_t>{0}, scattered, all}) {
    SCOPED_TRACE("rows " + std::to_string(rows.size()));
    std::vector<uint8_t> coloured(n, 0);
    for (int32_t i : rows) coloured[i] = 1;
    // The colour gradient: random on the coloured rows; the partial pass gets garbage elsewhere.
    std::vector<float> d_rgb_full(3 * n), d_rgb_partial(3 * n, 1e3f);
    for (int64_t i = 0; i < 3 * n; ++i) {
      d_rgb_full[i] = coloured[i / 3] ? u(rng) : 0.f;
      if (coloured[i / 3]) d_rgb_partial[i] = d_rgb_full[i];
    }
    std::vector<float> sigma_a(n), rgb_a(3 * n), dpos_a(3 * n), sigma_b(n), rgb_b(3 * n, -1.f), dpos_b(3 * n);
    StaticFieldContext ctx_a, ctx_b;
    store.ZeroGrads();
    field.Forward(ex, n, positions.data(), directions.data(), nullptr, sigma_a.data(), rgb_a.data(), &ctx_a,
                  true, true);
    field.Backward(ex, n, sigma_a.data(), rgb_a.data(), d_sigma.data(), d_rgb_full.data(), &ctx_a,
                   dpos_a.data());
    const std::vector<float> grads_a(store.grads(), store.grads() + store.size());
    store.ZeroGrads();
    field.ForwardDensity(ex, n, positions.data(), nullptr, sigma_b.data(), &ctx_b, true, true);
    field.ForwardColor(ex, n, directions.data(), std::span<const int32_t>(rows), rgb_b.data(), &ctx_b, true);
    field.Backward(ex, n, sigma_b.data(), rgb_b.data(), d_sigma.data(), d_rgb_partial.data(), &ctx_b,
                   dpos_b.data());
    const std::vector<float> grads_b(store.grads(), store.grads() + store.size());

    EXPECT_EQ(sigma_a, sigma_b);
    for (int64_t i = 0; i < 3 * n; ++i) {
      if (coloured[i / 3])
        ASSERT_NEAR(rgb_b[i], rgb_a[i], 1e-6f) << i;
      else
        ASSERT_EQ(rgb_b[i], 0.f) << i;
    }
    ASSERT_GT(MaxAbs(grads_a), 0.0);
    EXPECT_LE(MaxAbsDiff(grads_a, grads_b), 1e-5 * MaxAbs(grads_a));
    ASSERT_GT(MaxAbs(dpos_a), 0.0);
    EXPECT_LE(MaxAbsDiff(dpos_a, dpos_b), 1e-5 * MaxAbs(dpos_a));
  }
}

}  // namespace
}  // namespace icef
