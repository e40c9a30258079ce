// Prior-guided deformation (DESIGN.md §2.1) with a hand-made prior: D = P + R_phi, L_id and
// L_smooth act on R_phi only, confidence blends R_phi only, the mouth cavity is dark and opaque,
// and the training gradient still matches finite differences with a prior under the residual.
#include <gtest/gtest.h>

#include <cmath>

#include "icef/core/rng.h"
#include "icef/model/avatar_model.h"
#include "icef/model/model_test_util.h"

namespace icef {
namespace {

using testing_model::TinyModelConfig;
using testing_model::TinySetup;

// P(x, beta) - x = beta_0 (0.1 sin(3 y), -0.2, 0.05 x) + beta_1 (0, 0.1 z, 0); the cavity is a ball of
// radius 0.1 beta_0 around (0, -0.2, 0.3).
class TestPrior final : public DeformationPrior {
 public:
  explicit TestPrior(int dims) : dims_(dims) {}
  void Offsets(const Executor&, int64_t n, const float* x, const float* betas, float* offsets) const override {
    for (int64_t i = 0; i < n; ++i) {
      const float* p = x + 3 * i;
      const float b0 = betas[i * dims_], b1 = dims_ > 1 ? betas[i * dims_ + 1] : 0.f;
      offsets[3 * i] = b0 * 0.1f * std::sin(3.f * p[1]);
      offsets[3 * i + 1] = -0.2f * b0 + 0.1f * b1 * p[2];
      offsets[3 * i + 2] = 0.05f * b0 * p[0];
    }
  }
  void Cavity(const Executor&, int64_t n, const float* x, const float* betas, uint8_t* inside) const override {
    for (int64_t i = 0; i < n; ++i) {
      const Vec3f d = Vec3f(x[3 * i], x[3 * i + 1], x[3 * i + 2]) - Vec3f(0.f, -0.2f, 0.3f);
      inside[i] = d.norm() < 0.1f * betas[i * dims_] ? 1 : 0;
    }
  }
  int expression_dims() const override { return dims_; }
  std::string ToString() const override { return "TestPrior"; }

 private:
  int dims_;
};

std::unique_ptr<AvatarModel> MakePriorModel(const std::string& method, float deform_scale) {
  ModelConfig config = TinyModelConfig(method);
  config.deform_init_scale = deform_scale;
  const ModelSetup setup = TinySetup();
  auto model = AvatarModel::Create(config, setup, Executor(2), std::make_unique<TestPrior>(setup.expression_dim));
  ICEF_CHECK(model.ok(), model.status().message());
  (*model)->Initialize(7);
  return std::move(model).value();
}

std::vector<float> RandomPoints(int n, uint64_t seed) {
  Rng rng(seed, StreamId("points"));
  std::vector<float> p(3 * n);
  for (float& v : p) v = static_cast<float>(rng.Uniform(-0.4, 0.4));
  return p;
}

void ZeroResidual(AvatarModel& model) {
  nn::ParameterStore& store = model.store();
  for (int b = 0; b < store.num_blocks(); ++b)
    if (store.block(b).name.rfind("deformation", 0) == 0)
      for (float& v : store.params(b)) v = 0.f;
}

TrainRays Batch(int rays, uint64_t seed) {
  TrainRays batch;
  Rng rng(seed, StreamId("batch"));
  for (int r = 0; r < rays; ++r) {
    const Vec3f o(static_cast<float>(rng.Uniform(-0.2, 0.2)), static_cast<float>(rng.Uniform(-0.3, 0.2)), 2.f);
    batch.rays.push_back(Ray{o, Vec3f(0, 0, -1)});
    batch.frame.push_back(r % 3);
    for (int a = 0; a < 3; ++a) batch.target_rgb.push_back(static_cast<float>(rng.Uniform()));
    batch.target_alpha.push_back(static_cast<float>(rng.Uniform()));
  }
  return batch;
}

TEST(PriorGuidedTest, MethodsAndTraits) {
  EXPECT_TRUE(TraitsOf(Method::kIcefPrior).prior);
  EXPECT_TRUE(TraitsOf(Method::kIcefPrior).identity_losses);
  EXPECT_TRUE(TraitsOf(Method::kIcefPrior).confidence);
  EXPECT_TRUE(TraitsOf(Method::kWarpPrior).prior);
  EXPECT_FALSE(TraitsOf(Method::kWarpPrior).identity_losses);
  EXPECT_FALSE(TraitsOf(Method::kWarpPrior).confidence);
  EXPECT_FALSE(TraitsOf(Method::kIcef).prior);  // the paper's method stays prior-free
  EXPECT_EQ(*ParseMethod("icef-prior"), Method::kIcefPrior);
  EXPECT_EQ(*ParseMethod("warp-prior"), Method::kWarpPrior);
}

TEST(PriorGuidedTest, WithoutAFitThePriorMethodsAreRefused) {
  auto model = AvatarModel::Create(TinyModelConfig("icef-prior"), TinySetup(), Executor(1));
  ASSERT_FALSE(model.ok());
  EXPECT_NE(model.status().message().find("face"), std::string::npos) << model.status().message();
}

// With R_phi = 0 the warp is exactly P for every expression, and L_id is exactly zero, however far P
// moves the points: the identity regulariser constrains what is learned, not what the face model knows.
TEST(PriorGuidedTest, ZeroResidualIsThePriorAndCostsNoIdentityLoss) {
  auto model = MakePriorModel("icef-prior", 0.3f);
  ZeroResidual(*model);
  const int n = 64;
  const std::vector<float> x = RandomPoints(n, 3);
  const ModelSetup& setup = model->setup();
  TestPrior prior(setup.expression_dim);
  for (const std::vector<float>& beta : {std::vector<float>{0.5f, 0.f, 0.f}, std::vector<float>{2.f, 1.f, 0.5f}}) {
    std::vector<float> got(3 * n), want(3 * n), betas;
    model->Offsets(Executor(1), n, x.data(), beta, got.data());
    BroadcastExpression(beta, n, &betas);
    prior.Offsets(Executor(1), n, x.data(), betas.data(), want.data());
    for (int i = 0; i < 3 * n; ++i) ASSERT_NEAR(got[i], want[i], 1e-6f);
  }
  LossWeights w;
  w.lambda_id = 1.0;
  w.lambda_smooth = 1.0;
  const LossTerms terms = model->TrainForwardBackward(Batch(32, 1), w, 3, 0, Executor(1));
  EXPECT_GT(terms.samples, 0);
  EXPECT_EQ(terms.id, 0.0);
  EXPECT_EQ(terms.smooth, 0.0);
}

// D_final = P + kappa R_phi + (1 - kappa) R_lin: P enters with weight 1 at every kappa.
TEST(PriorGuidedTest, ConfidenceBlendsOnlyTheResidual) {
  auto with_prior = MakePriorModel("icef-prior", 0.3f);
  // The same residual without the prior: icef with the same seed and config.
  ModelConfig config = TinyModelConfig("icef");
  config.deform_init_scale = 0.3f;
  auto plain = std::move(AvatarModel::Create(config, TinySetup(), Executor(2))).value();
  plain->Initialize(7);
  const int n = 48;
  const std::vector<float> x = RandomPoints(n, 4);
  TestPrior prior(3);
  for (const std::vector<float>& beta :
       {std::vector<float>{0.5f, 0.f, 0.f}, std::vector<float>{0.7f, 0.1f, 0.f}, std::vector<float>{2.f, 1.5f, 1.f}}) {
    const double kappa = with_prior->Nearest(beta).kappa;
    std::vector<float> fin(3 * n), res(3 * n), p(3 * n), phi(3 * n), lin(3 * n), betas;
    with_prior->Offsets(Executor(1), n, x.data(), beta, fin.data());
    plain->Offsets(Executor(1), n, x.data(), beta, res.data());
    plain->OffsetsPhi(Executor(1), n, x.data(), beta, phi.data());
    plain->OffsetsLinearized(Executor(1), n, x.data(), beta, lin.data());
    BroadcastExpression(beta, n, &betas);
    prior.Offsets(Executor(1), n, x.data(), betas.data(), p.data());
    for (int i = 0; i < 3 * n; ++i) {
      ASSERT_NEAR(fin[i], p[i] + res[i], 1e-5f) << "kappa " << kappa;
      ASSERT_NEAR(res[i], kappa * phi[i] + (1 - kappa) * lin[i], 1e-5f);
    }
  }
}

// The open mouth renders as an opaque dark cavity where the prior says the mouth is open.
TEST(PriorGuidedTest, MouthCavityRendersDark) {
  auto model = MakePriorModel("icef-prior", 0.01f);
  const std::vector<Ray> rays = {Ray{Vec3f(0.f, -0.2f, 2.f), Vec3f(0, 0, -1)}};
  RenderOutput open, closed;
  model->Render(rays, std::vector<float>{1.5f, 0.f, 0.f}, Vec3f::Ones(), Executor(1), &open);
  model->Render(rays, std::vector<float>{0.f, 0.f, 0.f}, Vec3f::Ones(), Executor(1), &closed);
  EXPECT_GT(open.opacity[0], 0.99f);
  for (int a = 0; a < 3; ++a) EXPECT_LT(open.color[a], 0.2f);
  EXPECT_GT(closed.color[0], 0.2f);  // no cavity at neutral: whatever the static field holds
}

// The training loss's gradient with a prior under the residual (and a cavity on some rays).
TEST(PriorGuidedTest, TrainLossGradientMatchesFiniteDifferences) {
  auto model = MakePriorModel("icef-prior", 0.05f);
  const TrainRays batch = Batch(24, 5);
  LossWeights w;
  w.lambda_id = 0.5;
  w.lambda_smooth = 0.3;
  w.lambda_mask = 0.2;
  w.lambda_distortion = 0.01 * std::sqrt(3.0);
  const Executor ex(1);
  nn::ParameterStore& store = model->store();
  store.ZeroGrads();
  model->TrainForwardBackward(batch, w, 3, 0, ex);
  std::vector<float> grads(store.grads(), store.grads() + store.size());
  // The largest residual-field gradients and the largest gradients overall.
  std::vector<int64_t> order(grads.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = int64_t(i);
  std::partial_sort(order.begin(), order.begin() + 10, order.end(),
                    [&](int64_t a, int64_t b) { return std::abs(grads[a]) > std::abs(grads[b]); });
  std::vector<int64_t> check(order.begin(), order.begin() + 10);
  const int block = store.FindBlock("deformation");
  ASSERT_GE(block, 0);
  const int64_t d0 = store.block(block).offset, d1 = d0 + store.block(block).size;
  std::vector<int64_t> deform(order.begin(), order.end());
  std::erase_if(deform, [&](int64_t i) { return i < d0 || i >= d1; });
  std::partial_sort(deform.begin(), deform.begin() + 6, deform.end(),
                    [&](int64_t a, int64_t b) { return std::abs(grads[a]) > std::abs(grads[b]); });
  ASSERT_GT(std::abs(grads[deform[0]]), 1e-7);
  check.insert(check.end(), deform.begin(), deform.begin() + 6);
  for (int64_t i : check) {
    const float saved = store.params()[i];
    const float h = std::max(3e-3f, 3e-3f * std::abs(saved));
    store.params()[i] = saved + h;
    const double lp = model->TrainForwardBackward(batch, w, 3, 0, ex).total;
    store.params()[i] = saved - h;
    const double lm = model->TrainForwardBackward(batch, w, 3, 0, ex).total;
    store.params()[i] = saved;
    const double fd = (lp - lm) / (2.0 * (double(saved + h) - double(saved)));
    EXPECT_NEAR(grads[i], fd, 3e-2 * std::abs(fd) + 1e-6) << "parameter " << i;
  }
}

}  // namespace
}  // namespace icef
