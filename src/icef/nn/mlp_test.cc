#include "icef/nn/mlp.h"

#include <gtest/gtest.h>

#include <cstring>

#include "icef/testing/gradient_check.h"

namespace icef::nn {
namespace {

using testing::Dot;
using testing::MaxRelativeError;
using testing::RandomVector;

constexpr double kTol = 1e-6;

struct DoubleMlp {
  MlpShape shape;
  std::vector<double> w;
  int64_t n;
  std::vector<double> x, r;  // input, loss weights

  DoubleMlp(std::vector<int> widths, Activation a, int64_t samples, uint64_t seed)
      : shape(std::move(widths), a), n(samples) {
    w = RandomVector(shape.num_params(), seed, 1, -0.6, 0.6);
    x = RandomVector(n * shape.input_dims(), seed, 2, -1.0, 1.0);
    r = RandomVector(n * shape.output_dims(), seed, 3, -1.0, 1.0);
  }
  std::vector<double> Forward(std::vector<double>* hidden = nullptr) const {
    std::vector<double> h(n * shape.hidden_per_sample() + 1), y(n * shape.output_dims());
    MlpForward<double>(shape, w.data(), n, x.data(), h.data(), y.data());
    if (hidden) *hidden = h;
    return y;
  }
  double Loss() const { return Dot(Forward(), r); }
};

class MlpGradientTest : public ::testing::TestWithParam<Activation> {};

TEST_P(MlpGradientTest, ParamAndInputGradientsMatchFiniteDifferences) {
  DoubleMlp m({7, 16, 32, 5}, GetParam(), 9, 11);
  if (GetParam() == Activation::kExp) {
    for (double& v : m.w) v *= 0.5;
  }
  std::vector<double> hidden;
  const std::vector<double> y = m.Forward(&hidden);
  std::vector<double> wt(m.w.size()), dw(m.w.size(), 0.0), dx(m.x.size());
  std::vector<double> scratch(MlpBackwardScratch(m.shape, m.n));
  MlpTransposeWeights<double>(m.shape, m.w.data(), wt.data());
  MlpBackward<double>(m.shape, wt.data(), m.n, m.x.data(), hidden.data(), y.data(), m.r.data(), dw.data(),
                      dx.data(), scratch.data());
  EXPECT_LT(MaxRelativeError(&m.w, dw, [&] { return m.Loss(); }), kTol);
  EXPECT_LT(MaxRelativeError(&m.x, dx, [&] { return m.Loss(); }), kTol);
  // Gradients accumulate: a second backward doubles dw.
  std::vector<double> dw2 = dw;
  MlpBackward<double>(m.shape, wt.data(), m.n, m.x.data(), hidden.data(), y.data(), m.r.data(), dw2.data(),
                      nullptr, scratch.data());
  for (size_t i = 0; i < dw.size(); ++i) EXPECT_NEAR(dw2[i], 2.0 * dw[i], 1e-12 * (1 + std::abs(dw[i])));
}

TEST_P(MlpGradientTest, JvpMatchesFiniteDifferencesOfForward) {
  DoubleMlp m({10, 32, 16, 3}, GetParam(), 6, 12);
  const int slice_begin = 4, slice_dims = 5;
  const std::vector<double> v = RandomVector(m.n * slice_dims, 12, 4, -1.0, 1.0);
  std::vector<double> y(m.n * 3), jy(m.n * 3), scratch(MlpJvpScratch(m.shape, m.n));
  MlpJvp<double>(m.shape, m.w.data(), m.n, m.x.data(), slice_begin, slice_dims, v.data(), y.data(), jy.data(),
                 scratch.data());
  EXPECT_EQ(y, m.Forward());
  const double h = 1e-6;
  DoubleMlp plus = m, minus = m;
  for (int64_t s = 0; s < m.n; ++s) {
    for (int i = 0; i < slice_dims; ++i) {
      plus.x[s * 10 + slice_begin + i] += h * v[s * slice_dims + i];
      minus.x[s * 10 + slice_begin + i] -= h * v[s * slice_dims + i];
    }
  }
  const std::vector<double> yp = plus.Forward(), ym = minus.Forward();
  for (size_t i = 0; i < jy.size(); ++i) {
    const double fd = (yp[i] - ym[i]) / (2 * h);
    EXPECT_NEAR(jy[i], fd, kTol * (std::abs(fd) + 1e-3)) << "output " << i;
  }
}

INSTANTIATE_TEST_SUITE_P(Activations, MlpGradientTest,
                         ::testing::Values(Activation::kNone, Activation::kRelu, Activation::kSigmoid,
                                           Activation::kExp),
                         [](const auto& info) { return ActivationName(info.param); });

TEST(GemmTest, FloatKernelsMatchGenericForReferenceShapes) {
  for (int m : {1, 3, 7, 8, 16, 19, 32, 40, 55, 64, 80}) {
    for (int k : {3, 16, 32, 55, 64}) {
      const int64_t n = 37;
      std::vector<double> ad = RandomVector(n * k, 1, m, -1, 1), bd = RandomVector(k * m, 2, m, -1, 1);
      std::vector<float> a(ad.begin(), ad.end()), b(bd.begin(), bd.end());
      std::vector<float> c(n * m), c_ref(n * m);
      GemmNN<float>(n, k, m, a.data(), b.data(), c.data());
      GemmNNGeneric<float>(n, k, m, a.data(), b.data(), c_ref.data());
      for (size_t i = 0; i < c.size(); ++i) ASSERT_NEAR(c[i], c_ref[i], 1e-4) << m << " " << k;
      // C[k, m] += A[n, k]^T B[n, m]
      std::vector<double> bd2 = RandomVector(n * m, 3, m, -1, 1);
      std::vector<float> b2(bd2.begin(), bd2.end());
      std::vector<float> acc(k * m, 0.5f), acc_ref(k * m, 0.5f);
      GemmTNAcc<float>(n, k, m, a.data(), b2.data(), acc.data());
      GemmTNAccGeneric<float>(n, k, m, a.data(), b2.data(), acc_ref.data());
      for (size_t i = 0; i < acc.size(); ++i) ASSERT_NEAR(acc[i], acc_ref[i], 1e-4) << m << " " << k;
    }
  }
}

// The threaded float Mlp agrees with the double kernels.
TEST(MlpTest, ThreadedFloatMatchesDoubleKernels) {
  ParameterStore store;
  MlpOptions o;
  o.widths = {32, 64, 64, 3};
  o.output_activation = Activation::kSigmoid;
  Mlp mlp(o, &store, "mlp");
  mlp.Initialize(5);
  const int64_t n = 300;  // several tiles, a partial tile per thread
  const std::vector<double> xd = RandomVector(n * 32, 5, 1, -1, 1), dyd = RandomVector(n * 3, 5, 2, -1, 1);
  std::vector<float> x(xd.begin(), xd.end()), dy(dyd.begin(), dyd.end()), y(n * 3), dx(n * 32);
  Executor ex(2);
  MlpContext ctx;
  mlp.Forward(ex, n, x.data(), y.data(), &ctx);
  mlp.Backward(ex, n, x.data(), y.data(), dy.data(), &ctx, dx.data());

  const MlpShape& s = mlp.shape();
  std::vector<double> w(mlp.weights(), mlp.weights() + s.num_params()), wt(w.size()), dw(w.size(), 0.0);
  std::vector<double> h(n * s.hidden_per_sample()), yd(n * 3), dxd(n * 32), scratch(MlpBackwardScratch(s, n));
  MlpForward<double>(s, w.data(), n, xd.data(), h.data(), yd.data());
  MlpTransposeWeights<double>(s, w.data(), wt.data());
  MlpBackward<double>(s, wt.data(), n, xd.data(), h.data(), yd.data(), dyd.data(), dw.data(), dxd.data(),
                      scratch.data());
  for (int64_t i = 0; i < n * 3; ++i) ASSERT_NEAR(y[i], yd[i], 1e-5);
  for (int64_t i = 0; i < n * 32; ++i) ASSERT_NEAR(dx[i], dxd[i], 1e-4 * (1 + std::abs(dxd[i])));
  const float* g = mlp.weight_grads();
  for (int64_t i = 0; i < s.num_params(); ++i) ASSERT_NEAR(g[i], dw[i], 1e-3 * (1 + std::abs(dw[i])));

  // Inference mode gives the same outputs; JVP output equals forward output.
  std::vector<float> y2(n * 3), jy(n * 3), v(n * 4, 0.25f);
  MlpContext ctx2;
  mlp.Forward(ex, n, x.data(), y2.data(), &ctx2, false);
  EXPECT_EQ(0, std::memcmp(y.data(), y2.data(), y.size() * sizeof(float)));
  mlp.Jvp(ex, n, x.data(), 8, 4, v.data(), y2.data(), jy.data(), &ctx2);
  for (int64_t i = 0; i < n * 3; ++i) ASSERT_NEAR(y[i], y2[i], 1e-6);
}

TEST(MlpTest, InitialisationBoundsAndValidation) {
  ParameterStore store;
  MlpOptions o;
  o.widths = {55, 64, 3};
  o.output_init_scale = 0.01f;
  Mlp mlp(o, &store, "deform");
  mlp.Initialize(1);
  const float* w = mlp.weights();
  const float b0 = std::sqrt(6.0f / 55), b1 = std::sqrt(6.0f / 67) * 0.01f;
  float max0 = 0, max1 = 0;
  for (int i = 0; i < 55 * 64; ++i) max0 = std::max(max0, std::abs(w[i]));
  for (int i = 55 * 64; i < 55 * 64 + 64 * 3; ++i) max1 = std::max(max1, std::abs(w[i]));
  EXPECT_LE(max0, b0);
  EXPECT_GT(max0, 0.9f * b0);
  EXPECT_LE(max1, b1);
  EXPECT_GT(max1, 0.8f * b1);
  MlpOptions bad;
  bad.widths = {3};
  EXPECT_FALSE(bad.Validate().ok());
  bad.widths = {3, 0, 2};
  EXPECT_FALSE(bad.Validate().ok());
  EXPECT_FALSE(ParseActivation("softplus").ok());
  EXPECT_EQ(*ParseActivation("exp"), Activation::kExp);
}

}  // namespace
}  // namespace icef::nn

namespace icef::nn {
namespace {

// Chunked scheduling with per-chunk accumulators: 1 and 3 threads give the same bits.
TEST(MlpTest, BackwardIsBitIdenticalForAnyThreadCount) {
  const int64_t n = 3 * kMlpChunk + 77;
  std::vector<std::vector<float>> results;
  for (int threads : {1, 3}) {
    ParameterStore store;
    MlpOptions o;
    o.widths = {32, 64, 64, 4};
    Mlp mlp(o, &store, "mlp");
    mlp.Initialize(9);
    std::vector<float> x(n * 32), y(n * 4), dy(n * 4), dx(n * 32);
    for (int64_t i = 0; i < n * 32; ++i) x[i] = float((i * 7919) % 201 - 100) / 100.0f;
    for (int64_t i = 0; i < n * 4; ++i) dy[i] = float((i * 104729) % 101 - 50) / 500.0f;
    MlpContext ctx;
    const Executor ex(threads);
    mlp.Forward(ex, n, x.data(), y.data(), &ctx);
    mlp.Backward(ex, n, x.data(), y.data(), dy.data(), &ctx, dx.data());
    std::vector<float> r(store.grads(), store.grads() + store.size());
    r.insert(r.end(), dx.begin(), dx.end());
    r.insert(r.end(), y.begin(), y.end());
    results.push_back(std::move(r));
  }
  ASSERT_EQ(results[0].size(), results[1].size());
  EXPECT_EQ(0, std::memcmp(results[0].data(), results[1].data(), results[0].size() * sizeof(float)));
}

}  // namespace
}  // namespace icef::nn
