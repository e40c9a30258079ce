#include "icef/nn/hash_grid.h"

#include <gtest/gtest.h>

#include <cstring>

#include "icef/testing/gradient_check.h"

namespace icef::nn {
namespace {

using testing::Dot;
using testing::MaxRelativeError;
using testing::RandomVector;

TEST(HashGridLayoutTest, ReferenceConfigurationIsDenseAtLevelsZeroToFive) {
  const HashGridLayout g = MakeHashGridLayout(ReferenceHashGridOptions());
  ASSERT_EQ(g.num_levels, 16);
  EXPECT_EQ(g.levels[0].resolution, 16);
  EXPECT_EQ(g.levels[15].resolution, 1024);
  for (int l = 0; l < 16; ++l) EXPECT_EQ(g.levels[l].dense, l <= 5) << "level " << l;
  EXPECT_EQ(g.levels[5].entries, 65 * 65 * 65);
  EXPECT_EQ(g.levels[6].entries, 1 << 19);
  EXPECT_EQ(g.levels[6].offset, (g.levels[5].offset + g.levels[5].entries + 7) / 8 * 8);
  for (const HashGridLevel& lv : g.levels) EXPECT_EQ(lv.offset % 8, 0);
  // About 11.4 M parameters (docs/design.md §7).
  EXPECT_GT(g.num_params(), 11'300'000);
  EXPECT_LT(g.num_params(), 11'600'000);
}

TEST(HashGridLayoutTest, ValidateRejectsBadOptions) {
  HashGridOptions o;
  EXPECT_TRUE(o.Validate().ok());
  o.finest_resolution = 4;
  EXPECT_FALSE(o.Validate().ok());
  o = HashGridOptions{};
  o.log2_table_size = 40;
  EXPECT_FALSE(o.Validate().ok());
}

// A small grid with both dense and hashed levels (F = 3 to catch feature-index mistakes).
HashGridLayout SmallLayout() {
  HashGridOptions o;
  o.num_levels = 4;
  o.features_per_level = 3;
  o.log2_table_size = 8;
  o.base_resolution = 2;
  o.finest_resolution = 13;
  const HashGridLayout g = MakeHashGridLayout(o);
  EXPECT_TRUE(g.levels[0].dense);
  EXPECT_FALSE(g.levels[3].dense);
  return g;
}

TEST(HashGridGradientTest, ParamAndInputGradientsMatchFiniteDifferences) {
  const HashGridLayout g = SmallLayout();
  const int64_t n = 7;
  const int out = g.output_dims();
  std::vector<double> table = RandomVector(g.num_params(), 3, 1, -1, 1);
  std::vector<double> pos = RandomVector(n * 3, 3, 2, 0.02, 0.98);
  const std::vector<double> r = RandomVector(n * out, 3, 3, -1, 1);
  auto loss = [&] {
    std::vector<double> f(n * out);
    HashGridForward<double>(g, table.data(), n, pos.data(), f.data(), nullptr);
    return Dot(f, r);
  };
  std::vector<double> f(n * out), jac(n * out * 3), dtable(table.size(), 0.0), dpos(n * 3);
  HashGridForward<double>(g, table.data(), n, pos.data(), f.data(), jac.data());
  HashGridBackwardParams<double>(g, n, pos.data(), r.data(), dtable.data(), 0, g.num_levels);
  HashGridBackwardInput<double>(g, n, jac.data(), r.data(), dpos.data());
  EXPECT_LT(MaxRelativeError(&table, dtable, loss), 1e-6);
  EXPECT_LT(MaxRelativeError(&pos, dpos, loss), 1e-6);
  // Positions outside the cube are clamped: zero gradient on the clamped axis.
  std::vector<double> outside = {1.2, 0.5, -0.1};
  HashGridForward<double>(g, table.data(), 1, outside.data(), f.data(), jac.data());
  HashGridBackwardInput<double>(g, 1, jac.data(), r.data(), dpos.data());
  EXPECT_EQ(dpos[0], 0.0);
  EXPECT_EQ(dpos[2], 0.0);
  EXPECT_NE(dpos[1], 0.0);
}

TEST(HashGridTest, InterpolatesVertexValuesExactly) {
  // At a grid vertex the feature equals that vertex's table entry (dense level).
  const HashGridLayout g = SmallLayout();
  std::vector<double> table = RandomVector(g.num_params(), 4, 1, -1, 1);
  const int r = g.levels[0].resolution;
  const double p[3] = {1.0 / r, 0.0, 1.0};  // vertex (1, 0, r)
  std::vector<double> f(g.output_dims());
  HashGridForward<double>(g, table.data(), 1, p, f.data(), nullptr);
  const int64_t idx = 1 + 0 * (r + 1) + int64_t{r} * (r + 1) * (r + 1);
  for (int k = 0; k < g.features; ++k) EXPECT_NEAR(f[k], table[idx * g.features + k], 1e-12);
}

TEST(HashGridTest, ThreadedBackwardIsIdenticalForAnyThreadCount) {
  HashGridOptions o;
  o.num_levels = 8;
  o.log2_table_size = 12;
  o.finest_resolution = 256;
  const int64_t n = 5000;
  const std::vector<double> pd = RandomVector(n * 3, 9, 1, 0, 1), dd = RandomVector(n * 16, 9, 2, -1, 1);
  std::vector<float> pos(pd.begin(), pd.end()), dfeat(dd.begin(), dd.end());
  std::vector<std::vector<float>> grads;
  for (int threads : {1, 2, 3}) {
    ParameterStore store;
    HashGridEncoding enc(o, &store, "grid");
    enc.Initialize(1);
    std::vector<float> f(n * 16), jac(n * 48), dpos(n * 3);
    Executor ex(threads);
    enc.Forward(ex, n, pos.data(), f.data(), jac.data());
    enc.BackwardParams(ex, n, pos.data(), dfeat.data());
    enc.BackwardInput(ex, n, jac.data(), dfeat.data(), dpos.data());
    grads.emplace_back(store.grads(), store.grads() + store.size());
    // The float fast path agrees with the double kernels (features, Jacobian, table gradient).
    std::vector<double> table(enc.table(), enc.table() + enc.num_params()), fd(n * 16), jd(n * 48);
    std::vector<double> dd_table(table.size(), 0.0), dpd(n * 3);
    HashGridForward<double>(enc.layout(), table.data(), n, pd.data(), fd.data(), jd.data());
    HashGridBackwardParams<double>(enc.layout(), n, pd.data(), dd.data(), dd_table.data(), 0, 8);
    HashGridBackwardInput<double>(enc.layout(), n, jd.data(), dd.data(), dpd.data());
    for (int64_t i = 0; i < n * 16; ++i) ASSERT_NEAR(f[i], fd[i], 1e-7);
    for (int64_t i = 0; i < n * 48; ++i) ASSERT_NEAR(jac[i], jd[i], 1e-5 * (1 + std::abs(jd[i])));
    for (int64_t i = 0; i < n * 3; ++i) ASSERT_NEAR(dpos[i], dpd[i], 1e-4 * (1 + std::abs(dpd[i])));
    for (size_t i = 0; i < table.size(); ++i)
      ASSERT_NEAR(store.grads()[i], dd_table[i],
                  1e-4 * (1 + std::abs(dd_table[i])));  // float sums of ~1e3 terms
  }
  EXPECT_EQ(0, std::memcmp(grads[0].data(), grads[1].data(), grads[0].size() * sizeof(float)));
  EXPECT_EQ(0, std::memcmp(grads[0].data(), grads[2].data(), grads[0].size() * sizeof(float)));
}

}  // namespace
}  // namespace icef::nn
