// The loss terms as a list (model/losses.h): what the training step reports, and that each term's
// gradient reaches the parameters with its weight.
#include "icef/model/losses.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "icef/core/rng.h"
#include "icef/model/avatar_model.h"
#include "icef/model/model_test_util.h"
#include "icef/testing/gradient_check.h"

namespace icef {
namespace {

using testing_model::TinyModelConfig;
using testing_model::TinySetup;

const std::vector<std::string> kTerms = {"photo",     "mask",     "distortion", "depth",
                                         "occlusion", "symmetry", "id",         "smooth"};

// coarse: a coarse grid, visible opacities and a field with structure (random offsets on every
// parameter), as the finite-difference checks need (see symmetry_loss_test.cc).
std::unique_ptr<AvatarModel> MakeModel(const std::string& method, bool coarse = false) {
  ModelConfig config = TinyModelConfig(method);
  config.deformation.output_init_scale = 0.05f;
  config.bf16_inference = false;
  config.bf16_training = false;  // finite differences need more than BF16's 8 bits
  if (coarse) {
    config.static_field.grid.num_levels = 2;
    config.static_field.grid.finest_resolution = 6;
    config.static_field.density_bias = 1.f;
  }
  auto model = AvatarModel::Create(config, TinySetup(), Executor(1));
  ICEF_CHECK(model.ok(), model.status().message());
  (*model)->Initialize(7);
  if (coarse) {
    Rng noise(12, StreamId("params"));
    for (int64_t i = 0; i < (*model)->store().size(); ++i)
      (*model)->store().params()[i] += static_cast<float>(noise.Uniform(-0.3, 0.3));
  }
  return std::move(model).value();
}

// depth: a face-model depth on every other ray (L_depth), NaN on the rest.
TrainRays Batch(bool alpha, bool depth = true) {
  TrainRays batch = testing_model::RandomBatch(24, 5, alpha);
  if (depth) {
    Rng rng(5, StreamId("depth_target"));
    for (int r = 0; r < 24; ++r)
      batch.depth_target.push_back(r % 2 ? NAN : static_cast<float>(rng.Uniform(1.5, 2.5)));
  }
  return batch;
}

LossWeights AllOn() {
  LossWeights w;
  w.lambda_id = 0.5;
  w.lambda_smooth = 0.01;
  w.lambda_mask = 0.2;
  w.lambda_distortion = 0.02;
  w.lambda_depth_prior = 30.0;
  w.lambda_occlusion = 0.1;
  w.lambda_symmetry = 0.3;
  w.symmetry_max_samples = 64;
  w.smooth_max_samples = 64;
  w.smooth_epsilon = 0.05;
  return w;
}

TEST(LossesTest, EveryTermListedOnceAndTheTotalIsTheirWeightedSum) {
  for (const std::string method : {"icef", "icef-no-id", "nerface"}) {
    auto model = MakeModel(method);
    model->store().ZeroGrads();
    const LossWeights w = AllOn();
    const LossTerms t = model->TrainForwardBackward(Batch(true), w, 3, 0, Executor(1));
    ASSERT_EQ(t.terms.size(), kTerms.size()) << method;
    double total = 0;
    for (size_t i = 0; i < kTerms.size(); ++i) {
      EXPECT_EQ(t.terms[i].name, kTerms[i]) << method;
      EXPECT_TRUE(std::isfinite(t.terms[i].value)) << method << " " << kTerms[i];
      total += t.terms[i].weight * t.terms[i].value;
    }
    EXPECT_NEAR(t.total, total, 1e-12 * std::max(1.0, std::abs(total))) << method;
    EXPECT_EQ(t.terms[0].weight, 1.0);
    EXPECT_EQ(t.terms[1].weight, w.lambda_mask);
    EXPECT_GT(t.Get("photo"), 0.0);
    EXPECT_GT(t.Get("mask"), 0.0);
    EXPECT_GT(t.samples, 0);
    EXPECT_TRUE(t.AllFinite());
    const bool identity = method == "icef";
    EXPECT_EQ(t.terms[3].weight, w.lambda_depth_prior) << method;
    EXPECT_GT(t.Get("depth"), 0.0) << method;
    EXPECT_EQ(t.terms[6].weight, identity ? w.lambda_id : 0.0) << method;
    EXPECT_EQ(t.terms[7].weight, identity ? w.lambda_smooth : 0.0) << method;
    if (identity) {
      EXPECT_GT(t.Get("id"), 0.0);
    } else {
      EXPECT_EQ(t.Get("id"), 0.0) << method;
    }
    // nerface has no canonical space: no symmetry prior.
    EXPECT_EQ(t.terms[5].weight, method == "nerface" ? 0.0 : w.lambda_symmetry) << method;
  }
  // Without alpha the mask term has nothing to act on, without depth targets the depth term.
  auto model = MakeModel("icef");
  const LossTerms t = model->TrainForwardBackward(Batch(false, false), AllOn(), 3, 0, Executor(1));
  EXPECT_EQ(t.terms[1].weight, 0.0);
  EXPECT_EQ(t.Get("mask"), 0.0);
  EXPECT_EQ(t.terms[3].weight, 0.0);
  EXPECT_EQ(t.Get("depth"), 0.0);
}

TEST(LossesTest, FirstNonFiniteNamesTheTerm) {
  LossTerms t;
  t.terms = {{"photo", 1, 0.5}, {"id", 1, 0.1}};
  t.total = 0.6;
  EXPECT_EQ(t.FirstNonFinite(), "");
  t.terms[1].value = std::nan("");
  EXPECT_EQ(t.FirstNonFinite(), "id");
  t.terms[1].value = 0.1;
  t.total = INFINITY;
  EXPECT_EQ(t.FirstNonFinite(), "total");
  EXPECT_NE(t.ToString().find("photo 0.5"), std::string::npos) << t.ToString();
}

// Each term alone (on top of the photo term, which is always on): the parameter gradients it adds
// equal its weight times central differences of its own value (skipping parameters whose stencil
// straddles a kink of the trilinear grid, testing/gradient_check.h). Not L_occ: it holds the
// occlusion in front of a sample constant by design (render/occlusion_loss.h, tested there), so its
// gradient is no derivative of its value; the list test above checks that it is evaluated.
TEST(LossesTest, EachTermsGradientIsItsWeightTimesItsDerivative) {
  const TrainRays batch = Batch(true);
  const Executor ex(1);
  const LossWeights all = AllOn();
  struct Case {
    std::string term;
    double LossWeights::*lambda;
  };
  const std::vector<Case> cases = {{"mask", &LossWeights::lambda_mask},
                                   {"distortion", &LossWeights::lambda_distortion},
                                   {"depth", &LossWeights::lambda_depth_prior},
                                   {"symmetry", &LossWeights::lambda_symmetry},
                                   {"id", &LossWeights::lambda_id},
                                   {"smooth", &LossWeights::lambda_smooth}};
  for (const Case& c : cases) {
    auto model = MakeModel("icef", true);
    nn::ParameterStore& store = model->store();
    LossWeights off;  // only the photo term
    off.symmetry_max_samples = all.symmetry_max_samples;
    off.smooth_max_samples = all.smooth_max_samples;
    off.smooth_epsilon = all.smooth_epsilon;
    LossWeights on = off;
    on.*c.lambda = all.*c.lambda;
    store.ZeroGrads();
    model->TrainForwardBackward(batch, off, 3, 0, ex);
    const std::vector<float> g_off(store.grads(), store.grads() + store.size());
    store.ZeroGrads();
    const double value = model->TrainForwardBackward(batch, on, 3, 0, ex).Get(c.term);
    const std::vector<float> g_on(store.grads(), store.grads() + store.size());
    EXPECT_GT(std::abs(value), 0.0) << c.term;
    std::vector<double> added(g_on.size());
    for (size_t i = 0; i < added.size(); ++i) added[i] = double(g_on[i]) - double(g_off[i]);
    // The distortion term has kinks near many parameters, how many depends on the float sums'
    // order (the host's GEMM kernel): 24 candidates leave at least min_checked smooth ones.
    testing::ParameterGradientCheck check;
    check.top_k = 24;
    const auto report = check.Run(store.params(), added, [&] {
      return on.*c.lambda * model->TrainForwardBackward(batch, on, 3, 0, ex).Get(c.term);
    });
    EXPECT_TRUE(report.ok()) << c.term << ":\n" << report.failures;
    store.ZeroGrads();
  }
}

// Rays after TrainRays::photo_rays (unseen views, train.depth_prior_views) carry a depth target
// alone: L_photo and L_mask are those of the pixel rays (their garbage colour and alpha targets
// count nothing), the depth term reaches them, and its gradient on them is its derivative.
TEST(LossesTest, RaysAfterThePhotoRaysCountOnlyInTheDepthTerm) {
  const TrainRays pixels = Batch(true);
  TrainRays with_views = pixels;
  const TrainRays extra = testing_model::RandomBatch(8, 11, true);
  Rng rng(6, StreamId("view_depth"));
  for (int r = 0; r < 8; ++r) {
    with_views.rays.push_back(extra.rays[r]);
    with_views.frame.push_back(extra.frame[r]);
    for (int a = 0; a < 3; ++a) with_views.target_rgb.push_back(5.f);  // what no colour could match
    with_views.target_alpha.push_back(3.f);
    with_views.depth_target.push_back(static_cast<float>(rng.Uniform(1.5, 2.5)));
  }
  with_views.photo_rays = int64_t(pixels.rays.size());
  ASSERT_EQ(with_views.NumPhotoRays(), 24);
  ASSERT_EQ(pixels.NumPhotoRays(), 24);
  const Executor ex(1);

  // Photo and mask alone: the same values and parameter gradients as without the view rays.
  LossWeights photo_mask;
  photo_mask.lambda_mask = 0.2;
  auto model = MakeModel("icef", true);
  nn::ParameterStore& store = model->store();
  store.ZeroGrads();
  const LossTerms a = model->TrainForwardBackward(pixels, photo_mask, 3, 0, ex);
  const std::vector<float> g_a(store.grads(), store.grads() + store.size());
  store.ZeroGrads();
  const LossTerms b = model->TrainForwardBackward(with_views, photo_mask, 3, 0, ex);
  const std::vector<float> g_b(store.grads(), store.grads() + store.size());
  EXPECT_DOUBLE_EQ(a.Get("photo"), b.Get("photo"));
  EXPECT_DOUBLE_EQ(a.Get("mask"), b.Get("mask"));
  EXPECT_NEAR(a.psnr(), b.psnr(), 1e-12);
  double max_diff = 0, max_g = 0;
  for (size_t i = 0; i < g_a.size(); ++i) {
    max_diff = std::max(max_diff, std::abs(double(g_a[i]) - double(g_b[i])));
    max_g = std::max(max_g, std::abs(double(g_a[i])));
  }
  EXPECT_GT(max_g, 0.0);
  EXPECT_LE(max_diff, 1e-6 * max_g);

  // The depth term sees the view rays: only they carry a target here.
  LossWeights depth = photo_mask;
  depth.lambda_depth_prior = 30.0;
  TrainRays views_only = with_views;
  std::fill(views_only.depth_target.begin(), views_only.depth_target.begin() + 24, NAN);
  store.ZeroGrads();
  const double value = model->TrainForwardBackward(views_only, depth, 3, 0, ex).Get("depth");
  EXPECT_GT(value, 0.0);
  store.ZeroGrads();
  model->TrainForwardBackward(views_only, photo_mask, 3, 0, ex);
  const std::vector<float> g_off(store.grads(), store.grads() + store.size());
  store.ZeroGrads();
  model->TrainForwardBackward(views_only, depth, 3, 0, ex);
  std::vector<double> added(store.size());
  for (size_t i = 0; i < added.size(); ++i) added[i] = double(store.grads()[i]) - double(g_off[i]);
  const testing::ParameterGradientCheck check;
  const auto report = check.Run(store.params(), added, [&] {
    return depth.lambda_depth_prior * model->TrainForwardBackward(views_only, depth, 3, 0, ex).Get("depth");
  });
  EXPECT_TRUE(report.ok()) << report.failures;
}

}  // namespace
}  // namespace icef
