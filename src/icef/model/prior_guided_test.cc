// Prior-guided deformation (docs/design.md §2.1) with a hand-made prior: D = P + R_phi, L_id and
// L_smooth act on R_phi only, confidence blends R_phi only, the mouth cavity is dark and opaque,
// and the training gradient still matches finite differences with a prior under the residual.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "icef/core/rng.h"
#include "icef/face/expression.h"
#include "icef/face/face_model.h"
#include "icef/model/avatar_model.h"
#include "icef/model/face_prior.h"
#include "icef/model/model_test_util.h"
#include "icef/model/model_workspace.h"
#include "icef/testing/gradient_check.h"

namespace icef {
namespace {

using testing_model::TinyModelConfig;
using testing_model::TinySetup;

// P(x, beta) - x = beta_0 (0.1 sin(3 y), -0.2, 0.05 x) + beta_1 (0, 0.1 z, 0); the cavity is a ball of
// radius 0.1 beta_0 around (0, -0.2, 0.3); with teeth, a ball of the same radius around (0.3, -0.2, 0.3)
// is teeth; with air, the box |x + 0.3| < 0.1, |y + 0.2| < 0.1, z > 0.3 is air where beta_0 > 0.
class TestPrior final : public DeformationPrior {
 public:
  explicit TestPrior(int dims, bool teeth = false, bool air = false)
      : dims_(dims), teeth_(teeth), air_(air) {}
  void Offsets(const Executor&, int64_t n, const float* x, const float* betas,
               float* offsets) const override {
    for (int64_t i = 0; i < n; ++i) {
      const float* p = x + 3 * i;
      const float b0 = betas[i * dims_], b1 = dims_ > 1 ? betas[i * dims_ + 1] : 0.f;
      offsets[3 * i] = b0 * 0.1f * std::sin(3.f * p[1]);
      offsets[3 * i + 1] = -0.2f * b0 + 0.1f * b1 * p[2];
      offsets[3 * i + 2] = 0.05f * b0 * p[0];
    }
  }
  void Cavity(const Executor&, int64_t n, const float* x, const float* betas,
              uint8_t* inside) const override {
    for (int64_t i = 0; i < n; ++i) {
      const Vec3f d = Vec3f(x[3 * i], x[3 * i + 1], x[3 * i + 2]) - Vec3f(0.f, -0.2f, 0.3f);
      inside[i] = d.norm() < 0.1f * betas[i * dims_] ? kMouthCavity : kField;
      if (teeth_ && (d - Vec3f(0.3f, 0.f, 0.f)).norm() < 0.1f * betas[i * dims_]) inside[i] = kTeeth;
      if (air_ && betas[i * dims_] > 0.f && std::abs(x[3 * i] + 0.3f) < 0.1f &&
          std::abs(x[3 * i + 1] + 0.2f) < 0.1f && x[3 * i + 2] > 0.3f)
        inside[i] = kAir;
    }
  }
  bool has_teeth() const override { return teeth_; }
  // Normals: canonical (0.6, 0.8, 0) rotated about z by the sample's x, observed tilted further by
  // beta_0 (so beta = 0 leaves the shading as it is).
  bool Normals(const Executor&, int64_t n, const float* x, const float* betas, float* observed,
               float* canonical) const override {
    for (int64_t i = 0; i < n; ++i) {
      const float a = x[3 * i], b0 = betas[i * dims_];
      const Vec3f nc(0.6f * std::cos(a) - 0.8f * std::sin(a), 0.6f * std::sin(a) + 0.8f * std::cos(a), 0.f);
      const Vec3f no = Vec3f(nc.x(), nc.y(), 0.9f * b0).normalized();
      for (int k = 0; k < 3; ++k) observed[3 * i + k] = no[k], canonical[3 * i + k] = nc[k];
    }
    return true;
  }
  int expression_dims() const override { return dims_; }
  std::string ToString() const override { return "TestPrior"; }

 private:
  int dims_;
  bool teeth_, air_;
};

// A light along +z with strength 1.5: the prior shading scales the colour where beta_0 tilts the
// observed normal towards it. With shading = false (model.prior_shading off) nothing is shaded.
std::unique_ptr<AvatarModel> MakePriorModel(const std::string& method, float deform_scale,
                                            bool shading = true,
                                            float density_bias = StaticFieldOptions{}.density_bias,
                                            bool teeth = false, bool air = false) {
  ModelConfig config = TinyModelConfig(method);
  config.deformation.output_init_scale = deform_scale;
  config.prior_shading = shading;
  config.static_field.density_bias = density_bias;
  ModelSetup setup = TinySetup();
  setup.prior_light = Vec3f(0.f, 0.3f, 1.5f);
  auto model = AvatarModel::Create(config, setup, Executor(2),
                                   std::make_unique<TestPrior>(setup.expression_dim, teeth, air));
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

TrainRays Batch(int rays, uint64_t seed) { return testing_model::RandomBatch(rays, seed, true, -0.3); }

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
  for (const std::vector<float>& beta :
       {std::vector<float>{0.5f, 0.f, 0.f}, std::vector<float>{2.f, 1.f, 0.5f}}) {
    std::vector<float> got(3 * n), want(3 * n), betas;
    model->Offsets(Executor(1), n, x.data(), beta, got.data());
    BroadcastExpression(beta, n, &betas);
    prior.Offsets(Executor(1), n, x.data(), betas.data(), want.data());
    for (int i = 0; i < 3 * n; ++i) ASSERT_NEAR(got[i], want[i], 1e-6f);
  }
  LossWeights w;
  w.lambda_id_prior = 1.0;
  w.lambda_smooth = 1.0;
  const LossTerms terms = model->TrainForwardBackward(Batch(32, 1), w, 3, 0, Executor(1));
  EXPECT_GT(terms.samples, 0);
  EXPECT_EQ(terms.Get("id"), 0.0);
  EXPECT_EQ(terms.Get("smooth"), 0.0);
}

// On the prior, L_id (on R_phi) takes train.lambda_id_prior, not icef's lambda_id; warp-prior has none.
TEST(PriorGuidedTest, IdentityLossOnThePriorHasItsOwnWeight) {
  LossWeights w;
  w.lambda_id = 0.25;
  w.lambda_id_prior = 40.0;
  w.lambda_smooth = 0.5;
  for (const char* method : {"icef-prior", "warp-prior"}) {
    auto model = MakePriorModel(method, 0.3f);
    const LossTerms t = model->TrainForwardBackward(Batch(32, 2), w, 3, 0, Executor(1));
    double id_weight = -1, smooth_weight = -1;
    for (const LossValue& v : t.terms) {
      if (v.name == "id") id_weight = v.weight;
      if (v.name == "smooth") smooth_weight = v.weight;
    }
    const bool icef = std::string(method) == "icef-prior";
    EXPECT_EQ(id_weight, icef ? 40.0 : 0.0) << method;
    EXPECT_EQ(smooth_weight, icef ? 0.5 : 0.0) << method;
    if (icef) EXPECT_GT(t.Get("id"), 0.0);  // a non-zero residual outside the regions costs
  }
}

// On the prior, L_occ takes train.lambda_occlusion_prior; the methods without it lambda_occlusion.
TEST(PriorGuidedTest, OcclusionPriorOnThePriorHasItsOwnWeight) {
  LossWeights w;
  w.lambda_occlusion = 0.25;
  w.lambda_occlusion_prior = 3.0;
  auto weight_of = [](const LossTerms& t) {
    for (const LossValue& v : t.terms)
      if (v.name == "occlusion") return v.weight;
    return -1.0;
  };
  for (const char* method : {"icef-prior", "warp-prior"}) {
    auto model = MakePriorModel(method, 0.3f);
    EXPECT_EQ(weight_of(model->TrainForwardBackward(Batch(32, 2), w, 3, 0, Executor(1))), 3.0) << method;
  }
  auto plain = std::move(AvatarModel::Create(TinyModelConfig("icef"), TinySetup(), Executor(1))).value();
  plain->Initialize(7);
  EXPECT_EQ(weight_of(plain->TrainForwardBackward(Batch(32, 2), w, 3, 0, Executor(1))), 0.25);
}

// train.occlusion_prior_in_regions: on the prior, L_occ counts each sample times the region mask M
// (some of the batch lies outside the regions, so less than the whole prior, and more than none);
// the methods without the prior keep the whole prior.
TEST(PriorGuidedTest, OcclusionPriorInTheRegionsOnly) {
  auto occlusion = [](AvatarModel& model, bool in_regions) {
    LossWeights w;
    w.lambda_occlusion = w.lambda_occlusion_prior = 1.0;
    w.occlusion_prior_in_regions = in_regions;
    const LossTerms t = model.TrainForwardBackward(Batch(64, 5), w, 3, 0, Executor(1));
    return t.Get("occlusion");
  };
  auto model = MakePriorModel("icef-prior", 0.3f, true, 2.0f);  // dense: light is absorbed early
  const double whole = occlusion(*model, false), regions = occlusion(*model, true);
  EXPECT_GT(whole, 0.0);
  EXPECT_GT(regions, 0.0);
  EXPECT_LT(regions, 0.9 * whole);
  auto plain = std::move(AvatarModel::Create(TinyModelConfig("icef"), TinySetup(), Executor(1))).value();
  plain->Initialize(7);
  EXPECT_EQ(occlusion(*plain, true), occlusion(*plain, false));
}

// D_final = P + kappa R_phi + (1 - kappa) R_lin: P enters with weight 1 at every kappa.
TEST(PriorGuidedTest, ConfidenceBlendsOnlyTheResidual) {
  auto with_prior = MakePriorModel("icef-prior", 0.3f);
  // The same residual without the prior: icef with the same seed and config.
  ModelConfig config = TinyModelConfig("icef");
  config.deformation.output_init_scale = 0.3f;
  auto plain = std::move(AvatarModel::Create(config, TinySetup(), Executor(2))).value();
  plain->Initialize(7);
  const int n = 48;
  const std::vector<float> x = RandomPoints(n, 4);
  TestPrior prior(3);
  for (const std::vector<float>& beta :
       {std::vector<float>{0.5f, 0.f, 0.f}, std::vector<float>{0.7f, 0.1f, 0.f},
        std::vector<float>{2.f, 1.5f, 1.f}}) {
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

// The cavity's colour is learned: a render of the open mouth shows it, rays through the cavity pull
// it towards their targets (a darker target: positive gradients on all three logits, so a descent
// step darkens it), and rays that miss the cavity leave it alone (no gradient at all).
TEST(PriorGuidedTest, MouthCavityColourIsLearned) {
  auto model = MakePriorModel("icef-prior", 0.01f);
  nn::ParameterStore& store = model->store();
  const int block = store.FindBlock("cavity/colour");
  ASSERT_GE(block, 0);
  EXPECT_NEAR(model->CavityColour(0), 0.12f, 1e-6f);  // the start: dark red-brown
  const float want[3] = {0.5f, 0.2f, 0.1f};
  for (int a = 0; a < 3; ++a) store.params(block)[a] = std::log(want[a] / (1.f - want[a]));
  RenderOutput open;
  model->Render(std::vector<Ray>{Ray{Vec3f(0.f, -0.2f, 2.f), Vec3f(0, 0, -1)}},
                std::vector<float>{1.5f, 0.f, 0.f}, Vec3f::Ones(), Executor(1), &open);
  ASSERT_GT(open.opacity[0], 0.99f);
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(open.color[a], want[a], 0.03f) << a;

  TrainRays through, past;
  for (float dx : {-0.02f, 0.02f}) {
    through.rays.push_back(Ray{Vec3f(dx, -0.2f, 2.f), Vec3f(0, 0, -1)});
    past.rays.push_back(Ray{Vec3f(dx + 0.3f, 0.1f, 2.f), Vec3f(0, 0, -1)});
    for (TrainRays* b : {&through, &past}) {
      b->frame.push_back(0);  // beta_0 = 0.5: a cavity of radius 0.05
      for (int a = 0; a < 3; ++a) b->target_rgb.push_back(0.02f);
      b->target_alpha.push_back(1.f);
    }
  }
  const Executor ex(1);
  store.ZeroGrads();
  model->TrainForwardBackward(through, LossWeights{}, 3, 0, ex);
  for (int a = 0; a < 3; ++a) EXPECT_GT(store.grads(block)[a], 1e-4f) << a;
  store.ZeroGrads();
  model->TrainForwardBackward(past, LossWeights{}, 3, 0, ex);
  for (int a = 0; a < 3; ++a) EXPECT_EQ(store.grads(block)[a], 0.f) << a;
  // Without a prior there is no cavity and no block for it.
  ModelConfig plain = TinyModelConfig("icef");
  auto icef = AvatarModel::Create(plain, TinySetup(), Executor(1));
  ASSERT_TRUE(icef.ok());
  EXPECT_LT((*icef)->store().FindBlock("cavity/colour"), 0);
}

// A prior with teeth gives the model a teeth colour, learned as the cavity's is: a render through
// the teeth shows it (the start, off-white), its logits' gradient from rays through the teeth matches
// central differences of the loss, and rays that miss the teeth pass it none. The cavity's colour
// takes no gradient from the teeth.
TEST(PriorGuidedTest, TeethColourIsLearned) {
  auto model = MakePriorModel("icef-prior", 0.01f, true, StaticFieldOptions{}.density_bias, true);
  ASSERT_TRUE(model->has_teeth());
  nn::ParameterStore& store = model->store();
  const int block = store.FindBlock("teeth/colour"), cavity = store.FindBlock("cavity/colour");
  ASSERT_GE(block, 0);
  EXPECT_NEAR(model->TeethColour(0), 0.86f, 1e-6f);
  RenderOutput open;
  model->Render(std::vector<Ray>{Ray{Vec3f(0.3f, -0.2f, 2.f), Vec3f(0, 0, -1)}},
                std::vector<float>{1.5f, 0.f, 0.f}, Vec3f::Ones(), Executor(1), &open);
  ASSERT_GT(open.opacity[0], 0.99f);
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(open.color[a], model->TeethColour(a), 0.03f) << a;

  TrainRays through, past;
  for (float dx : {-0.02f, 0.02f}) {
    through.rays.push_back(Ray{Vec3f(0.3f + dx, -0.2f, 2.f), Vec3f(0, 0, -1)});
    past.rays.push_back(Ray{Vec3f(dx, -0.2f, 2.f), Vec3f(0, 0, -1)});  // through the cavity instead
    for (TrainRays* b : {&through, &past}) {
      b->frame.push_back(0);  // beta_0 = 0.5: balls of radius 0.05
      for (float target : {0.3f, 0.5f, 0.7f}) b->target_rgb.push_back(target);
      b->target_alpha.push_back(1.f);
    }
  }
  const Executor ex(1);
  store.ZeroGrads();
  model->TrainForwardBackward(through, LossWeights{}, 3, 0, ex);
  const std::vector<float> grad(store.grads(block).begin(), store.grads(block).end());
  for (int a = 0; a < 3; ++a) EXPECT_EQ(store.grads(cavity)[a], 0.f) << a;
  for (int a = 0; a < 3; ++a) {
    const float h = 1e-2f, start = store.params(block)[a];
    double loss[2];
    for (int s = 0; s < 2; ++s) {
      store.params(block)[a] = start + (s == 0 ? h : -h);
      store.ZeroGrads();
      loss[s] = model->TrainForwardBackward(through, LossWeights{}, 3, 0, ex).total;
    }
    store.params(block)[a] = start;
    const double numeric = (loss[0] - loss[1]) / (2.0 * h);
    EXPECT_GT(std::abs(numeric), 1e-4) << a;
    EXPECT_NEAR(grad[a], numeric, 0.03 * std::abs(numeric)) << a;
  }
  store.ZeroGrads();
  model->TrainForwardBackward(past, LossWeights{}, 3, 0, ex);
  for (int a = 0; a < 3; ++a) EXPECT_EQ(store.grads(block)[a], 0.f) << a;
  // A prior without teeth: no block for them.
  EXPECT_LT(MakePriorModel("icef-prior", 0.01f)->store().FindBlock("teeth/colour"), 0);
}

// Air (a prior's kAir: between parted lips) is empty whatever the static field holds there: a ray
// through 0.2 of air before a dense field ends about 0.2 farther than the same model's without air,
// at the expression that makes the air (beta_0 > 0) and not at rest; training rays through it pass
// no gradient to the cavity's colour.
TEST(PriorGuidedTest, AirIsEmpty) {
  auto with = MakePriorModel("icef-prior", 1e-6f, false, 4.f, false, true);
  auto without = MakePriorModel("icef-prior", 1e-6f, false, 4.f, false, false);
  const std::vector<Ray> ray = {Ray{Vec3f(-0.3f, -0.2f, 2.f), Vec3f(0, 0, -1)}};
  RenderOutput a, b, rest_a, rest_b;
  const std::vector<float> open = {0.5f, 0.f, 0.f}, rest = {0.f, 0.f, 0.f};
  with->Render(ray, open, Vec3f::Ones(), Executor(1), &a);
  without->Render(ray, open, Vec3f::Ones(), Executor(1), &b);
  with->Render(ray, rest, Vec3f::Ones(), Executor(1), &rest_a);
  without->Render(ray, rest, Vec3f::Ones(), Executor(1), &rest_b);
  ASSERT_GT(b.opacity[0], 0.99f);
  EXPECT_LT(b.depth[0], 1.6f);  // the dense field from the aabb's face at z = 0.5 on
  EXPECT_NEAR(a.depth[0] - b.depth[0], 0.2f, 0.05f);
  EXPECT_EQ(rest_a.depth[0], rest_b.depth[0]);
  TrainRays through;
  through.rays = ray;
  through.frame = {0};  // beta_0 = 0.5
  through.target_rgb = {0.1f, 0.2f, 0.3f};
  through.target_alpha = {1.f};
  nn::ParameterStore& store = with->store();
  store.ZeroGrads();
  with->TrainForwardBackward(through, LossWeights{}, 3, 0, Executor(1));
  for (float g : store.grads(store.FindBlock("cavity/colour"))) EXPECT_EQ(g, 0.f);
}

// The prior shading: colour times s = (1 + max(0, n_obs . v)) / (1 + max(0, n_can . v)) at every
// sample, from the prior's normals; at beta = 0 (equal normals) the render is the unshaded one, and
// model.prior_shading = false or a setup without a light turns it off.
TEST(PriorGuidedTest, PriorShadingScalesTheColourByTheLightOnTheTurnedSurface) {
  // Dense enough that every sample is shaded (sparser ones are left as they are: avatar_model.cc).
  auto shaded = MakePriorModel("icef-prior", 0.01f, true, -1.f);
  auto plain = MakePriorModel("icef-prior", 0.01f, false, -1.f);
  ASSERT_TRUE(shaded->prior_light().has_value());
  EXPECT_FALSE(plain->prior_light().has_value());
  const std::vector<Ray> rays = {Ray{Vec3f(0.1f, 0.05f, 2.f), Vec3f(0, 0, -1)},
                                 Ray{Vec3f(-0.2f, 0.1f, 2.f), Vec3f(0, 0, -1)}};
  for (float b0 : {0.f, 0.6f}) {
    const std::vector<float> beta = {b0, 0.f, 0.f};
    RenderOutput a, b;
    shaded->Render(rays, beta, Vec3f::Zero(), Executor(1), &a);
    plain->Render(rays, beta, Vec3f::Zero(), Executor(1), &b);
    for (size_t r = 0; r < rays.size(); ++r) {
      ASSERT_GT(b.opacity[r], 1e-3f);
      EXPECT_FLOAT_EQ(a.opacity[r], b.opacity[r]);  // the density is not shaded
      if (b0 == 0.f) {
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(a.color[3 * r + c], b.color[3 * r + c], 1e-6f);
      } else {  // the observed normal turns towards +z: brighter, by at most the largest ratio
        for (int c = 0; c < 3; ++c) {
          EXPECT_GT(a.color[3 * r + c], 1.05f * b.color[3 * r + c]);
          EXPECT_LT(a.color[3 * r + c], 2.5f * b.color[3 * r + c]);
        }
      }
    }
  }
  // The ratio itself, in double precision.
  const double up[3] = {0, 0, 1}, side[3] = {1, 0, 0}, none[3] = {0, 0, 0};
  EXPECT_DOUBLE_EQ(PriorShadeRatio(up, side, Vec3f(0, 0, 2)), 3.0);
  EXPECT_DOUBLE_EQ(PriorShadeRatio(side, up, Vec3f(0, 0, 2)), 1.0 / 3.0);
  EXPECT_DOUBLE_EQ(PriorShadeRatio(up, up, Vec3f(0.3f, -1, 2)), 1.0);
  EXPECT_DOUBLE_EQ(PriorShadeRatio(none, none, Vec3f(0, 0, 2)), 1.0);
}

// The training loss's gradient with a prior under the residual (and a cavity on some rays, and the
// prior shading on every sample).
TEST(PriorGuidedTest, TrainLossGradientMatchesFiniteDifferences) {
  auto model = MakePriorModel("icef-prior", 0.05f, true, -1.f);  // dense enough to be shaded
  TrainRays batch = Batch(24, 5);
  for (float dx : {-0.02f, 0.02f}) {  // through the cavity of frame 0 (beta_0 = 0.5: radius 0.05)
    for (float dy : {-0.02f, 0.02f}) {
      batch.rays.push_back(Ray{Vec3f(dx, -0.2f + dy, 2.f), Vec3f(0, 0, -1)});
      batch.frame.push_back(0);
      for (float v : {0.02f, 0.3f, 0.9f}) batch.target_rgb.push_back(v);
      batch.target_alpha.push_back(1.f);
    }
  }
  LossWeights w;
  w.lambda_id_prior = 0.5;
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
  // And the largest of the colour MLP's output layer (its last weights; no ReLU switches under a
  // step there): their gradient passes through the prior shading's ratio.
  const int color = store.FindBlock("static/color");
  ASSERT_GE(color, 0);
  const int64_t c1 = store.block(color).offset + store.block(color).size, c0 = c1 - 48;
  std::vector<int64_t> colour(order.begin(), order.end());
  std::erase_if(colour, [&](int64_t i) { return i < c0 || i >= c1; });
  std::partial_sort(colour.begin(), colour.begin() + 6, colour.end(),
                    [&](int64_t a, int64_t b) { return std::abs(grads[a]) > std::abs(grads[b]); });
  check.insert(check.end(), colour.begin(), colour.begin() + 6);
  // And the mouth cavity's learned colour (its three logits), which the cavity rays see.
  const int cavity = store.FindBlock("cavity/colour");
  ASSERT_GE(cavity, 0);
  ASSERT_EQ(store.block(cavity).size, 3);
  for (int64_t a = 0; a < 3; ++a) {
    const int64_t i = store.block(cavity).offset + a;
    EXPECT_GT(std::abs(grads[i]), 1e-6) << "cavity colour " << a;
    check.push_back(i);
  }
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

// L_depth on the face-model prior (the face model's depth on half the pixel rays and on unseen-view
// rays after TrainRays::photo_rays): the parameter gradients it adds are its weight times central
// differences of its value, over the largest gradients and over the residual R_phi's largest. On a
// coarse grid with random offsets on every parameter (structure for the differences to see), FP32
// products. Parameters whose stencil straddles a kink of the trilinear grid or a ReLU are skipped
// (testing/gradient_check.h).
TEST(PriorGuidedTest, DepthTermsGradientIsItsWeightTimesItsDerivative) {
  ModelConfig config = TinyModelConfig("icef-prior");
  config.deformation.output_init_scale = 0.05f;
  config.static_field.grid.num_levels = 2;
  config.static_field.grid.finest_resolution = 6;
  config.static_field.density_bias = -1.f;
  config.bf16_training = config.bf16_inference = false;
  ModelSetup setup = TinySetup();
  setup.prior_light = Vec3f(0.f, 0.3f, 1.5f);
  auto created =
      AvatarModel::Create(config, setup, Executor(1), std::make_unique<TestPrior>(setup.expression_dim));
  ASSERT_TRUE(created.ok()) << created.status().message();
  AvatarModel& model = **created;
  model.Initialize(7);
  nn::ParameterStore& store = model.store();
  Rng noise(12, StreamId("params"));
  for (int64_t i = 0; i < store.size(); ++i)
    store.params()[i] += static_cast<float>(noise.Uniform(-0.3, 0.3));

  TrainRays batch = Batch(24, 5);
  const TrainRays extra = Batch(8, 9);
  Rng rng(6, StreamId("view_depth"));
  for (int r = 0; r < 24; ++r)
    batch.depth_target.push_back(r % 2 ? NAN : static_cast<float>(rng.Uniform(1.6, 2.2)));
  batch.photo_rays = int64_t(batch.rays.size());
  for (int r = 0; r < 8; ++r) {
    batch.rays.push_back(extra.rays[r]);
    batch.frame.push_back(extra.frame[r]);
    for (int a = 0; a < 3; ++a) batch.target_rgb.push_back(0.5f);
    batch.target_alpha.push_back(1.f);
    batch.depth_target.push_back(static_cast<float>(rng.Uniform(1.6, 2.2)));
  }
  LossWeights off;  // the photo term alone
  LossWeights on = off;
  on.lambda_depth_prior = 30.0;
  const Executor ex(1);
  store.ZeroGrads();
  model.TrainForwardBackward(batch, off, 3, 0, ex);
  const std::vector<float> g_off(store.grads(), store.grads() + store.size());
  store.ZeroGrads();
  const double value = model.TrainForwardBackward(batch, on, 3, 0, ex).Get("depth");
  ASSERT_GT(value, 0.0);
  std::vector<double> added(store.size());
  for (size_t i = 0; i < added.size(); ++i) added[i] = double(store.grads()[i]) - double(g_off[i]);
  const auto depth = [&] {
    return on.lambda_depth_prior * model.TrainForwardBackward(batch, on, 3, 0, ex).Get("depth");
  };
  const testing::ParameterGradientCheck check;
  const auto all = check.Run(store.params(), added, depth);
  EXPECT_TRUE(all.ok()) << "largest gradients:\n" << all.failures;

  const int block = store.FindBlock("deformation");
  ASSERT_GE(block, 0);
  const int64_t d0 = store.block(block).offset, d1 = d0 + store.block(block).size;
  std::vector<double> residual(added.size(), 0.0);
  for (int64_t i = d0; i < d1; ++i) residual[i] = added[i];
  const auto largest = std::max_element(residual.begin(), residual.end(),
                                        [](double a, double b) { return std::abs(a) < std::abs(b); });
  ASSERT_GT(std::abs(*largest), 1e-7);  // L_depth reaches R_phi
  const auto r_phi = check.Run(store.params(), residual, depth);
  EXPECT_TRUE(r_phi.ok()) << "R_phi:\n" << r_phi.failures;
}

// Training colours only the samples its pixel rays composite: the samples past a ray's early
// termination and the unseen views' rays (after TrainRays::photo_rays, depth alone) skip the colour
// MLP and the prior shading's normals. Every term and gradient is the one of a step that colours
// every sample, to float rounding, on a sparse field and on one dense enough to stop rays early;
// and the pixel rays' colour terms are those of the pixel rays alone.
TEST(PriorGuidedTest, TrainingColoursOnlyWhatThePixelRaysComposite) {
  for (const float density_bias : {-1.f, 4.f}) {
    SCOPED_TRACE("density_bias " + std::to_string(density_bias));
    ModelConfig config = TinyModelConfig("icef-prior");
    config.deformation.output_init_scale = 0.05f;
    config.static_field.density_bias = density_bias;       // dense enough to be shaded
    config.bf16_training = config.bf16_inference = false;  // FP32 products: gradients compared below
    ModelSetup setup = TinySetup();
    setup.prior_light = Vec3f(0.f, 0.3f, 1.5f);
    auto created =
        AvatarModel::Create(config, setup, Executor(1), std::make_unique<TestPrior>(setup.expression_dim));
    ASSERT_TRUE(created.ok()) << created.status().message();
    AvatarModel& model = **created;
    model.Initialize(7);
    ASSERT_TRUE(model.prior_light().has_value());
    const TrainRays pixels = Batch(24, 5);
    TrainRays with_views = pixels;
    const TrainRays extra = Batch(8, 9);
    Rng rng(6, StreamId("view_depth"));
    with_views.depth_target.assign(pixels.rays.size(), NAN);
    for (int r = 0; r < 8; ++r) {
      with_views.rays.push_back(extra.rays[r]);
      with_views.frame.push_back(extra.frame[r]);
      for (int a = 0; a < 3; ++a) with_views.target_rgb.push_back(5.f);  // what no colour could match
      with_views.target_alpha.push_back(3.f);
      with_views.depth_target.push_back(static_cast<float>(rng.Uniform(1.6, 2.2)));
    }
    with_views.photo_rays = int64_t(pixels.rays.size());
    LossWeights w;
    w.lambda_mask = 0.2;
    w.lambda_depth_prior = 30.0;
    w.lambda_distortion = 0.01;
    w.lambda_symmetry = 0.1;  // its opacity part reads samples past termination too
    const Executor ex(1);
    nn::ParameterStore& store = model.store();
    const auto grads_of = [&](const TrainRays& batch, const LossWeights& weights, bool composited_only,
                              LossTerms* terms) {
      model.set_color_composited_only(composited_only);
      store.ZeroGrads();
      *terms = model.TrainForwardBackward(batch, weights, 3, 0, ex);
      return std::vector<double>(store.grads(), store.grads() + store.size());
    };
    // a and b agree to 1e-6 of the largest gradient (float sums in another order).
    const auto expect_close = [](const std::vector<double>& a, const std::vector<double>& b,
                                 const char* what) {
      double max_diff = 0, max_a = 0;
      for (size_t i = 0; i < a.size(); ++i) {
        max_diff = std::max(max_diff, std::abs(a[i] - b[i]));
        max_a = std::max(max_a, std::abs(a[i]));
      }
      EXPECT_GT(max_a, 0.0) << what;
      EXPECT_LE(max_diff, 1e-6 * max_a) << what;
    };

    LossTerms all, some;
    const std::vector<double> g_all = grads_of(with_views, w, false, &all);
    const int64_t every_sample = model.train_workspace().samples.size();
    const std::vector<double> g_some = grads_of(with_views, w, true, &some);
    const ModelWorkspace& ws = model.train_workspace();
    const int64_t pixel_samples = ws.samples.ray_offset[pixels.rays.size()];
    ASSERT_GT(every_sample, pixel_samples);  // the view rays have samples
    EXPECT_GT(ws.color_rows.size(), 0u);
    EXPECT_LE(int64_t(ws.color_rows.size()), pixel_samples);
    if (density_bias > 0) EXPECT_LT(int64_t(ws.color_rows.size()), pixel_samples / 2);  // rays end early
    ASSERT_EQ(all.terms.size(), some.terms.size());
    for (size_t k = 0; k < all.terms.size(); ++k)
      EXPECT_NEAR(all.terms[k].value, some.terms[k].value, 1e-6 * std::abs(all.terms[k].value))
          << all.terms[k].name;
    expect_close(g_all, g_some, "every term");

    LossWeights colour;
    colour.lambda_mask = 0.2;
    LossTerms a, b;
    const std::vector<double> g_a = grads_of(pixels, colour, true, &a),
                              g_b = grads_of(with_views, colour, true, &b);
    EXPECT_DOUBLE_EQ(a.Get("photo"), b.Get("photo"));
    EXPECT_DOUBLE_EQ(a.Get("mask"), b.Get("mask"));
    expect_close(g_a, g_b, "the pixel rays' colour terms");
  }
}

}  // namespace
}  // namespace icef

namespace icef {
namespace {

using testing_model::TinySetup;

// The fitted face model's prior warp reproduces the warp of the head the landmarks came from
// (style-free: the generic expression style), for training and far expressions, in world units;
// with the style fitted too (model.prior_style), which then stays the generic one.
class FittedPriorTest : public ::testing::TestWithParam<bool> {};

TEST_P(FittedPriorTest, MatchesTheGeneratingHeadsWarp) {
  face::ShapeParams shape;
  shape.jaw_width = 1.1f, shape.nose_length = 0.9f, shape.mouth_width = 1.1f, shape.brow_height = 0.85f;
  shape.eye_spacing = 1.05f, shape.chin_length = 1.15f;
  const face::FaceModel truth(shape);
  face::Similarity s;  // world -> head
  s.scale = 1.25;
  s.rotation = Eigen::AngleAxisd(-0.3, Vec3d(0.1, 1.0, 0.2).normalized()).toRotationMatrix();
  s.translation = Vec3d(-0.05, 0.1, 0.02);
  Rng rng(11, StreamId("prior_fit"));
  std::vector<face::FitFrame> frames;
  for (int k = 0; k < 5; ++k) {
    face::FitFrame f;
    f.expression.assign(face::kNumExpressions, 0.f);
    for (float& v : f.expression)
      v = rng.UniformDouble() < 0.4 ? static_cast<float>(rng.Uniform(0.0, 0.9)) : 0.f;
    std::vector<Vec3f> world;
    for (const Vec3f& p : truth.Landmarks(truth.Prepare(f.expression)))
      world.push_back(
          s.ApplyInverse(p.cast<double>() + 0.002 * Vec3d(rng.Normal(), rng.Normal(), rng.Normal()))
              .cast<float>());
    f.landmarks_3d = world;
    frames.push_back(std::move(f));
  }
  ModelSetup setup;
  setup.expression_dim = face::kNumExpressions;
  setup.expression_names = face::ExpressionNames();
  face::FaceFitOptions options;
  options.fit_style = GetParam();
  Result<face::FaceFit> fit = face::FitFaceModel(frames, options);
  ASSERT_TRUE(fit.ok()) << fit.status().message();
  // The landmarks' noise (0.002 head units, about the fit's assumed 0.02 IOD) moves the style's
  // fields off the generic ones where few landmarks see them: measured up to 0.15 on a gain
  // (smile_gain[0]), 0.011 head units on an offset.
  const auto fitted = fit->style.Fields(), generic = face::ExpressionStyle::Generic().Fields();
  for (int i = 0; i < face::ExpressionStyle::kNumFields; ++i)
    EXPECT_NEAR(fitted[i].second, generic[i].second, i < face::ExpressionStyle::kNumGains ? 0.25f : 0.02f)
        << fitted[i].first;
  setup.face_fit = *fit;
  Result<std::unique_ptr<DeformationPrior>> made = MakeFacePrior(setup);
  ASSERT_TRUE(made.ok()) << made.status().message();
  const std::unique_ptr<DeformationPrior> prior = std::move(made).value();

  // Points around the face surface: the neutral landmarks pushed in and out a little.
  std::vector<float> x;
  for (const Vec3f& p : truth.NeutralLandmarks())
    for (float dz : {-0.01f, 0.f, 0.01f}) {
      const Vec3d w = s.ApplyInverse((p + Vec3f(0.f, 0.f, dz)).cast<double>());
      for (int a = 0; a < 3; ++a) x.push_back(static_cast<float>(w[a]));
    }
  const int64_t n = static_cast<int64_t>(x.size() / 3);
  const double iod_world = face::InterOcularDistance(truth.NeutralLandmarks()) / s.scale;
  std::vector<std::vector<float>> betas = {frames[0].expression, frames[3].expression};
  std::vector<float> far(face::kNumExpressions, 0.f);
  far[face::kJawOpen] = 1.5f, far[face::kSmileRight] = 1.3f, far[face::kBrowRaiseLeft] = 1.6f,
  far[face::kEyeCloseLeft] = 1.f, far[face::kLipPucker] = 0.8f;
  betas.push_back(far);
  for (const std::vector<float>& beta : betas) {
    std::vector<float> rows, got(3 * n);
    BroadcastExpression(beta, n, &rows);
    prior->Offsets(Executor(1), n, x.data(), rows.data(), got.data());
    const face::ExpressionState state = truth.Prepare(beta);
    double worst = 0, motion = 0;
    for (int64_t i = 0; i < n; ++i) {
      const Vec3d xw(x[3 * i], x[3 * i + 1], x[3 * i + 2]);
      const Vec3d want =
          s.ApplyInverse(truth.PriorWarp(s.Apply(xw).cast<float>(), state).cast<double>()) - xw;
      const Vec3d have(got[3 * i], got[3 * i + 1], got[3 * i + 2]);
      worst = std::max(worst, (have - want).norm() / iod_world);
      motion = std::max(motion, want.norm() / iod_world);
    }
    // Measured 0.0013, 0.0016, 0.0096 IOD (generic style), 0.0070, 0.0030, 0.022 (style fitted: its
    // gain errors, up to 0.15, grow with the far expression's weights).
    EXPECT_LT(worst, GetParam() ? 0.03 : 0.02) << "largest warp " << motion << " IOD";
    EXPECT_GT(motion, 0.05);  // the expressions do move the face
  }
}

INSTANTIATE_TEST_SUITE_P(FacePriorTest, FittedPriorTest, ::testing::Values(false, true),
                         [](const auto& info) { return info.param ? "StyleFitted" : "GenericStyle"; });

// The shading normals (FacePrior::Normals): the neutral normal at P(x), and that normal carried
// back through the warp. On the expressed surface away from the lids (which the prior slides rather
// than warps) and the mouth's cavity, the carried normal is the expressed face model's own normal;
// where an expression leaves the surface alone, and at neutral, the two normals agree.
TEST(FacePriorTest, ShadingNormalsAreTheNeutralNormalCarriedThroughTheWarp) {
  face::ShapeParams shape;
  shape.jaw_width = 1.1f, shape.cheek_fullness = 1.1f;
  const face::FaceModel truth(shape);
  ModelSetup setup;
  setup.expression_dim = face::kNumExpressions;
  setup.expression_names = face::ExpressionNames();
  face::FaceFit fit;
  fit.shape = shape;
  fit.head_from_world.scale = 1.3;
  fit.head_from_world.rotation =
      Eigen::AngleAxisd(0.5, Vec3d(0.2, 1.0, -0.3).normalized()).toRotationMatrix();
  fit.head_from_world.translation = Vec3d(0.05, -0.1, 0.2);
  setup.face_fit = fit;
  Result<std::unique_ptr<DeformationPrior>> made = MakeFacePrior(setup);
  ASSERT_TRUE(made.ok()) << made.status().message();
  const std::unique_ptr<DeformationPrior> prior = std::move(made).value();
  const Mat3f to_world = fit.head_from_world.rotation.transpose().cast<float>();
  auto normals = [&](const std::vector<Vec3f>& head_points, const std::vector<float>& beta,
                     std::vector<Vec3f>* observed, std::vector<Vec3f>* canonical) {
    std::vector<float> x, rows, obs(3 * head_points.size()), can(3 * head_points.size());
    for (const Vec3f& p : head_points) {
      const Vec3d w = fit.head_from_world.ApplyInverse(p.cast<double>());
      for (int a = 0; a < 3; ++a) x.push_back(static_cast<float>(w[a]));
    }
    const int64_t n = static_cast<int64_t>(head_points.size());
    BroadcastExpression(beta, n, &rows);
    ASSERT_TRUE(prior->Normals(Executor(2), n, x.data(), rows.data(), obs.data(), can.data()));
    observed->clear(), canonical->clear();
    for (int64_t i = 0; i < n; ++i) {
      observed->emplace_back(obs[3 * i], obs[3 * i + 1], obs[3 * i + 2]);
      canonical->emplace_back(can[3 * i], can[3 * i + 1], can[3 * i + 2]);
    }
  };
  auto angle_deg = [](const Vec3f& a, const Vec3f& b) {
    return std::acos(std::clamp(a.normalized().dot(b.normalized()), -1.f, 1.f)) * 57.29578f;
  };

  // On the expressed surface: the landmarks of the jaw line, nose and brows.
  std::vector<float> beta(face::kNumExpressions, 0.f);
  beta[face::kJawOpen] = 0.9f, beta[face::kSmileLeft] = 0.8f, beta[face::kCheekPuff] = 0.9f;
  beta[face::kBrowRaiseRight] = 1.2f;
  const face::ExpressionState state = truth.Prepare(beta);
  const auto landmarks = truth.Landmarks(state);
  std::vector<Vec3f> points;
  for (int i = 0; i < 36; ++i) points.push_back(landmarks[i]);
  std::vector<Vec3f> observed, canonical;
  normals(points, beta, &observed, &canonical);
  double worst = 0, turned = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    EXPECT_NEAR(observed[i].norm(), 1.f, 1e-5f);
    worst = std::max<double>(worst, angle_deg(observed[i], to_world * truth.Normal(points[i], state)));
    turned = std::max<double>(turned, angle_deg(observed[i], canonical[i]));
  }
  EXPECT_LT(worst, 2.0);   // the expressed model's own normal (measured 0.6 degrees; 21 with J for J^T)
  EXPECT_GT(turned, 5.0);  // and the expression does turn the surface (10 degrees)

  // Where the expression moves nothing (the crown, the back of the head: jaw and mouth only), and at
  // neutral everywhere, the two normals agree.
  std::vector<float> mouth_only(face::kNumExpressions, 0.f);
  mouth_only[face::kJawOpen] = 1.f, mouth_only[face::kLipPucker] = 0.8f;
  const std::vector<Vec3f> far_away = {Vec3f(0.f, 0.388f, 0.f), Vec3f(0.1f, 0.3f, -0.2f),
                                       Vec3f(-0.2f, 0.2f, -0.25f)};
  normals(far_away, mouth_only, &observed, &canonical);
  for (size_t i = 0; i < far_away.size(); ++i) EXPECT_LT(angle_deg(observed[i], canonical[i]), 0.05) << i;
  normals(points, std::vector<float>(face::kNumExpressions, 0.f), &observed, &canonical);
  for (size_t i = 0; i < points.size(); ++i) EXPECT_EQ(observed[i], canonical[i]) << i;
}

// Another expression space (NerFace's 76-D vectors, say): one line that names the dataset and the
// names it has, and points to the tracker that re-expresses it.
TEST(FacePriorTest, AnotherExpressionSpacePointsToTheTracker) {
  EXPECT_TRUE(CheckFaceModelExpressions(face::ExpressionNames(), "d").ok());
  const Status s = CheckFaceModelExpressions({"e0", "e1"}, "data/nerface");
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.message().find('\n'), std::string::npos);
  for (const char* want :
       {"data/nerface", "[e0, e1]", "icef track DATASET --keep-cameras --out NEW", "icef, warp"})
    EXPECT_NE(s.message().find(want), std::string::npos) << want << " in " << s.message();
}

TEST(FacePriorTest, SetupJsonKeepsTheFit) {
  ModelSetup setup = TinySetup();
  face::FaceFit fit;
  fit.shape.jaw_width = 1.2f;
  fit.head_from_world.scale = 1.5;
  fit.head_from_world.rotation = Eigen::AngleAxisd(0.4, Vec3d::UnitY()).toRotationMatrix();
  fit.head_from_world.translation = Vec3d(0.1, 0.2, 0.3);
  fit.rms_iod = 0.01, fit.max_iod = 0.03, fit.landmarks_used = 300, fit.landmarks_total = 340,
  fit.iterations = 7;
  fit.style.jaw_gain = 0.75f, fit.style.smile_gain[1] = 1.2f, fit.style.jaw_hinge_dz = -0.02f;
  setup.face_fit = fit;
  setup.prior_light = Vec3f(-0.5f, 0.75f, 1.25f);
  const Result<ModelSetup> parsed = ModelSetup::FromJson(setup.ToJson(), "test");
  ASSERT_TRUE(parsed.ok()) << parsed.status().message();
  const ModelSetup& back = *parsed;
  ASSERT_TRUE(back.face_fit.has_value());
  EXPECT_FLOAT_EQ(back.face_fit->shape.jaw_width, 1.2f);
  EXPECT_NEAR(back.face_fit->head_from_world.scale, 1.5, 1e-12);
  EXPECT_NEAR((back.face_fit->head_from_world.rotation - fit.head_from_world.rotation).norm(), 0.0, 1e-12);
  EXPECT_EQ(back.face_fit->landmarks_used, 300);
  EXPECT_EQ(back.face_fit->style, fit.style);
  ASSERT_TRUE(back.prior_light.has_value());
  EXPECT_EQ(*back.prior_light, Vec3f(-0.5f, 0.75f, 1.25f));
  Json no_light = setup.ToJson();
  no_light.erase("prior_light");  // a model saved before the prior shading: no light, no shading
  EXPECT_FALSE(ModelSetup::FromJson(no_light, "ckpt")->prior_light.has_value());
  no_light["prior_light"] = {1.0, 2.0};
  EXPECT_NE(ModelSetup::FromJson(no_light, "ckpt").status().message().find("prior_light"), std::string::npos);
  Json bad = setup.ToJson();
  bad["face_fit"]["head_from_world"]["rotation"][0][0] = 3.0;
  const auto err = ModelSetup::FromJson(bad, "ckpt");
  ASSERT_FALSE(err.ok());
  EXPECT_NE(err.status().message().find("rotation"), std::string::npos) << err.status().message();
  bad = setup.ToJson();
  bad["face_fit"]["shape"].erase("mouth_width");
  EXPECT_NE(ModelSetup::FromJson(bad, "ckpt").status().message().find("mouth_width"), std::string::npos);
  // The expression style: a setup saved before styles were fitted has none (the generic style); a
  // gain out of range or a missing field names itself.
  Json old = setup.ToJson();
  old["face_fit"].erase("style");
  ASSERT_TRUE(ModelSetup::FromJson(old, "ckpt").ok());
  EXPECT_TRUE(ModelSetup::FromJson(old, "ckpt")->face_fit->style.IsGeneric());
  bad = setup.ToJson();
  bad["face_fit"]["style"]["jaw_gain"] = 9.0;
  EXPECT_NE(ModelSetup::FromJson(bad, "ckpt").status().message().find("jaw_gain"), std::string::npos);
  bad = setup.ToJson();
  bad["face_fit"]["style"].erase("smile_gain[1]");
  EXPECT_NE(ModelSetup::FromJson(bad, "ckpt").status().message().find("smile_gain[1]"), std::string::npos);
}

// A fit with an expression style: the prior warps as the face model in that style does, not as the
// generic one.
TEST(FacePriorTest, ThePriorWarpsInTheFittedStyle) {
  face::FaceFit fit;
  fit.shape.jaw_width = 1.1f;
  fit.style.jaw_gain = 0.7f, fit.style.smile_gain[1] = 1.25f, fit.style.jaw_hinge_dz = 0.03f;
  fit.head_from_world.scale = 1.2;
  fit.head_from_world.rotation = Eigen::AngleAxisd(0.3, Vec3d(0.3, 1.0, 0.1).normalized()).toRotationMatrix();
  fit.head_from_world.translation = Vec3d(0.02, -0.05, 0.1);
  ModelSetup setup;
  setup.expression_dim = face::kNumExpressions;
  setup.expression_names = face::ExpressionNames();
  setup.face_fit = fit;
  Result<std::unique_ptr<DeformationPrior>> made = MakeFacePrior(setup);
  ASSERT_TRUE(made.ok()) << made.status().message();
  const face::FaceModel styled(fit.shape, fit.style), generic(fit.shape);
  std::vector<float> beta(face::kNumExpressions, 0.f);
  beta[face::kJawOpen] = 1.2f, beta[face::kSmileLeft] = 0.9f;
  const face::ExpressionState s_state = styled.Prepare(beta), g_state = generic.Prepare(beta);
  std::vector<float> x;
  std::vector<Vec3d> world;
  for (const Vec3f& p : styled.Landmarks(s_state)) {
    world.push_back(fit.head_from_world.ApplyInverse(p.cast<double>()));
    for (int a = 0; a < 3; ++a) x.push_back(static_cast<float>(world.back()[a]));
  }
  const int64_t n = static_cast<int64_t>(world.size());
  std::vector<float> rows, got(3 * n);
  BroadcastExpression(beta, n, &rows);
  (*made)->Offsets(Executor(1), n, x.data(), rows.data(), got.data());
  double worst_styled = 0, largest_generic = 0;
  for (int64_t i = 0; i < n; ++i) {
    const Vec3f h = fit.head_from_world.Apply(world[i]).cast<float>();
    const Vec3d have = world[i] + Vec3d(got[3 * i], got[3 * i + 1], got[3 * i + 2]);
    auto canonical = [&](const face::FaceModel& m, const face::ExpressionState& st) {
      return fit.head_from_world.ApplyInverse(m.PriorWarp(h, st).cast<double>());
    };
    worst_styled = std::max(worst_styled, (have - canonical(styled, s_state)).norm());
    largest_generic = std::max(largest_generic, (have - canonical(generic, g_state)).norm());
  }
  EXPECT_LT(worst_styled, 1e-5);
  EXPECT_GT(largest_generic, 0.01);  // the style moves the mouth's landmarks by head units' hundredths
}

}  // namespace
}  // namespace icef
