#include "icef/model/avatar_model.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "icef/core/rng.h"
#include "icef/model/identity_losses.h"
#include "icef/model/model_test_util.h"
#include "icef/model/render_image.h"
#include "icef/nn/gemm_bf16.h"
#include "icef/testing/gradient_check.h"

namespace icef {
namespace {

using testing_model::TinyModelConfig;
using testing_model::TinySetup;

// bf16 = false: inference in FP32 (finite-difference checks need more than BF16's 8 bits).
std::unique_ptr<AvatarModel> MakeModel(const std::string& method, float deform_scale = 0.5f,
                                       bool bf16 = true) {
  ModelConfig config = TinyModelConfig(method);
  config.deformation.output_init_scale = deform_scale;  // a clearly non-zero warp from the start
  config.bf16_inference = bf16;
  auto model = AvatarModel::Create(config, TinySetup(), Executor(2));
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

TEST(MethodTest, ParseAndTraits) {
  for (Method m : AllMethods()) EXPECT_EQ(*ParseMethod(MethodName(m)), m);
  EXPECT_FALSE(ParseMethod("icef2").ok());
  EXPECT_NE(ParseMethod("x").status().message().find("icef-no-conf"), std::string::npos);
  EXPECT_TRUE(TraitsOf(Method::kIcef).confidence);
  EXPECT_FALSE(TraitsOf(Method::kIcefNoConf).confidence);
  EXPECT_FALSE(TraitsOf(Method::kIcefNoId).identity_losses);
  EXPECT_FALSE(TraitsOf(Method::kWarp).identity_losses);
  EXPECT_FALSE(TraitsOf(Method::kNerface).deformation);
  EXPECT_TRUE(TraitsOf(Method::kNerface).entangled_beta);
}

TEST(AvatarModelTest, StaticFieldNeverSeesBeta) {
  // ICEF: the canonical field has no expression input, so rendering two expressions that warp
  // every point to the same canonical point gives the same colour. We check it directly: the
  // static field at fixed canonical points is identical whatever expression the model was last
  // rendered at, while the entangled nerface baseline does change with beta.
  auto icef = MakeModel("icef");
  EXPECT_EQ(icef->config().StaticOptions(3).condition_dims, 0);
  const int n = 64;
  const std::vector<float> x = RandomPoints(n, 1);
  std::vector<float> dirs(3 * n, 0.f);
  for (int i = 0; i < n; ++i) dirs[3 * i + 2] = 1.f;
  std::vector<float> s0(n), c0(3 * n), s1(n), c1(3 * n);
  icef->QueryStatic(Executor(2), n, x.data(), dirs.data(), nullptr, s0.data(), c0.data());
  RenderOutput out;
  std::vector<Ray> rays = {Ray{Vec3f(0, 0, 2), Vec3f(0, 0, -1)}};
  icef->Render(rays, std::vector<float>{1.f, 1.f, 1.f}, Vec3f::Ones(), Executor(2), &out);
  icef->QueryStatic(Executor(2), n, x.data(), dirs.data(), nullptr, s1.data(), c1.data());
  EXPECT_EQ(s0, s1);
  EXPECT_EQ(c0, c1);

  auto nerface = MakeModel("nerface");
  EXPECT_EQ(nerface->config().StaticOptions(3).condition_dims, 3);
  std::vector<float> beta0(3 * n, 0.f), beta1(3 * n, 1.f);
  nerface->QueryStatic(Executor(2), n, x.data(), dirs.data(), beta0.data(), s0.data(), c0.data());
  nerface->QueryStatic(Executor(2), n, x.data(), dirs.data(), beta1.data(), s1.data(), c1.data());
  EXPECT_NE(s0, s1);
}

TEST(AvatarModelTest, ConfidenceBlendAtObservedAndFarExpressions) {
  auto model = MakeModel("icef");
  const int n = 32;
  const std::vector<float> x = RandomPoints(n, 2);
  const Executor ex(2);
  std::vector<float> phi(3 * n), lin(3 * n), fin(3 * n);
  // At a training expression delta = 0, kappa = 1: D_final == D_phi exactly.
  const std::vector<float>& observed = model->setup().training_expressions[1];
  EXPECT_EQ(model->Nearest(observed).delta, 0.0);
  EXPECT_EQ(model->Nearest(observed).kappa, 1.0);
  model->Offsets(ex, n, x.data(), observed, fin.data());
  model->OffsetsPhi(ex, n, x.data(), observed, phi.data());
  EXPECT_EQ(fin, phi);
  // As delta grows, D_final -> D_lin: the gap shrinks like kappa.
  double prev_gap = 1e30;
  for (float scale : {0.5f, 2.f, 8.f}) {
    std::vector<float> beta = {0.5f + scale, 0.2f * scale, -0.3f * scale};
    const NearestExpression near = model->Nearest(beta);
    model->Offsets(ex, n, x.data(), beta, fin.data());
    model->OffsetsPhi(ex, n, x.data(), beta, phi.data());
    model->OffsetsLinearized(ex, n, x.data(), beta, lin.data());
    double gap = 0, expected = 0;
    for (int i = 0; i < 3 * n; ++i) {
      gap = std::max(gap, double(std::abs(fin[i] - lin[i])));
      expected = std::max(expected, near.kappa * std::abs(phi[i] - lin[i]));
      ASSERT_NEAR(fin[i], near.kappa * phi[i] + (1 - near.kappa) * lin[i], 1e-5);
    }
    EXPECT_LE(gap, expected + 1e-6);
    EXPECT_LT(gap, prev_gap);
    prev_gap = gap;
  }
  EXPECT_LT(prev_gap, 1e-3);
  // icef-no-conf never blends.
  auto no_conf = MakeModel("icef-no-conf");
  std::vector<float> beta = {3.f, 1.f, 0.f};
  no_conf->Offsets(ex, n, x.data(), beta, fin.data());
  no_conf->OffsetsPhi(ex, n, x.data(), beta, phi.data());
  EXPECT_EQ(fin, phi);
}

TEST(AvatarModelTest, LinearizedWarpMatchesFiniteDifferences) {
  auto model = MakeModel("icef", 0.5f, /*bf16=*/false);
  const int n = 32;
  const std::vector<float> x = RandomPoints(n, 3);
  const Executor ex(1);
  const std::vector<float> beta = {0.9f, 0.4f, -0.2f};
  const int k = model->Nearest(beta).index;
  const std::vector<float>& anchor = model->setup().training_expressions[k];
  std::vector<float> lin(3 * n), base(3 * n), plus(3 * n), minus(3 * n);
  model->OffsetsLinearized(ex, n, x.data(), beta, lin.data());
  model->OffsetsPhi(ex, n, x.data(), anchor, base.data());
  // The warp is piecewise smooth (ReLU MLP): a small step keeps most points off the kinks.
  const float h = 1e-3f;
  std::vector<float> bp(3), bm(3);
  for (int i = 0; i < 3; ++i) {
    bp[i] = anchor[i] + h * (beta[i] - anchor[i]);
    bm[i] = anchor[i] - h * (beta[i] - anchor[i]);
  }
  model->OffsetsPhi(ex, n, x.data(), bp, plus.data());
  model->OffsetsPhi(ex, n, x.data(), bm, minus.data());
  double max_err = 0, max_tangent = 0;
  for (int i = 0; i < 3 * n; ++i) {
    const double fd = base[i] + (double(plus[i]) - minus[i]) / (2 * h);
    max_err = std::max(max_err, std::abs(fd - lin[i]));
    max_tangent = std::max(max_tangent, std::abs(double(lin[i]) - base[i]));
  }
  EXPECT_GT(max_tangent, 1e-3);  // the linear term is not trivially zero
  EXPECT_LT(max_err, 1e-2 * max_tangent + 1e-5);
}

TEST(IdentityLossTest, ZeroInsideRegionsPositiveOutside) {
  const double inv_half2[3] = {4, 4, 4};
  const double offsets[6] = {0.1, -0.2, 0.05, 0.3, 0.0, -0.1};
  const float inside[2] = {1.f, 1.f}, outside[2] = {0.f, 0.f};
  EXPECT_EQ(IdentityLoss<double>(2, offsets, inside, inv_half2, 1.0, nullptr), 0.0);
  EXPECT_GT(IdentityLoss<double>(2, offsets, outside, inv_half2, 1.0, nullptr), 0.0);
  const double zero[6] = {0, 0, 0, 0, 0, 0};
  EXPECT_EQ(IdentityLoss<double>(2, zero, outside, inv_half2, 1.0, nullptr), 0.0);
}

TEST(IdentityLossTest, GradientsMatchFiniteDifferences) {
  Rng rng(11, StreamId("id_grad"));
  const int n = 7;
  std::vector<double> off(6 * n);
  std::vector<float> mask(2 * n), weights(n);
  for (double& v : off) v = rng.Uniform(-0.3, 0.3);
  for (float& m : mask) m = static_cast<float>(rng.Uniform());
  for (float& w : weights) w = static_cast<float>(rng.Uniform());
  const double inv_half2[3] = {1.5, 2.0, 0.7}, half[3] = {0.8, 0.7, 1.2}, eps = 0.05;
  std::vector<double> g_id(6 * n, 0.0), g_sm(6 * n, 0.0);
  IdentityLoss<double>(2 * n, off.data(), mask.data(), inv_half2, 0.3, g_id.data());
  SmoothnessLoss<double>(n, off.data(), weights.data(), half, eps, 0.7, g_sm.data());
  const double h = 1e-6;
  for (int i = 0; i < 6 * n; ++i) {
    std::vector<double> p = off, m = off;
    p[i] += h;
    m[i] -= h;
    const double fd_id = 0.3 *
                         (IdentityLoss<double>(2 * n, p.data(), mask.data(), inv_half2, 1.0, nullptr) -
                          IdentityLoss<double>(2 * n, m.data(), mask.data(), inv_half2, 1.0, nullptr)) /
                         (2 * h);
    const double fd_sm = 0.7 *
                         (SmoothnessLoss<double>(n, p.data(), weights.data(), half, eps, 1.0, nullptr) -
                          SmoothnessLoss<double>(n, m.data(), weights.data(), half, eps, 1.0, nullptr)) /
                         (2 * h);
    EXPECT_NEAR(g_id[i], fd_id, 1e-7 * (1 + std::abs(fd_id))) << i;
    EXPECT_NEAR(g_sm[i], fd_sm, 1e-7 * (1 + std::abs(fd_sm))) << i;
  }
}

// End-to-end check of the hand-written chain (compositing, static field, warp, losses): the
// total training loss against central differences in a few parameters with large gradients.
// The engine is float32, so the tolerance is looser than the double-precision checks of each
// component (nn/, render/, identity_losses).
TEST(RenderImageTest, SupersamplingAveragesSubpixelRays) {
  ModelConfig config = TinyModelConfig("icef");
  config.render.supersample = 2;
  config.static_field.density_bias = 2.f;  // visible structure, so the sub-pixel rays differ
  auto created = AvatarModel::Create(config, TinySetup(), Executor(2));
  ASSERT_TRUE(created.ok()) << created.status().message();
  AvatarModel& model = **created;
  model.Initialize(3);
  Intrinsics in;
  in.width = 6, in.height = 5, in.fl_x = in.fl_y = 6, in.cx = 3, in.cy = 2.5;
  Mat4d pose = Mat4d::Identity();
  pose(2, 3) = 2.0;
  const Camera cam(in, pose);
  const std::vector<float> beta = {0.1f, 0.f, 0.2f};
  const RenderedImage img = RenderImage(model, cam, beta, Vec3f(1, 1, 1), Executor(2));
  ASSERT_EQ(img.color.width, 6);
  ASSERT_EQ(img.color.height, 5);
  double max_spread = 0;
  for (int j = 0; j < 5; ++j)
    for (int i = 0; i < 6; ++i) {
      std::vector<Ray> rays;
      for (double dv : {0.25, 0.75})
        for (double du : {0.25, 0.75}) rays.push_back(cam.RayThrough(i + du, j + dv));
      RenderOutput out;
      model.Render(rays, beta, Vec3f(1, 1, 1), Executor(1), &out);
      for (int c = 0; c < 3; ++c) {
        const float mean = 0.25f * (out.color[c] + out.color[3 + c] + out.color[6 + c] + out.color[9 + c]);
        EXPECT_NEAR(img.color.At(i, j, c), mean, 1e-5) << i << "," << j;
        max_spread = std::max<double>(max_spread, std::abs(out.color[c] - out.color[9 + c]));
      }
      EXPECT_NEAR(img.opacity.At(i, j, 0),
                  0.25f * (out.opacity[0] + out.opacity[1] + out.opacity[2] + out.opacity[3]), 1e-5);
    }
  EXPECT_GT(max_spread, 1e-3);  // the sub-pixel rays really saw different things
}

// Renders sample each ray render.sample_factor times as densely as training does.
TEST(RenderImageTest, RendersSampleTheFactorTimesTheTrainingCount) {
  ModelConfig config = TinyModelConfig("icef");
  config.static_field.density_bias = -8.f;  // nearly empty: no ray stops early, every sample is evaluated
  EXPECT_EQ(config.RenderSamplerOptions().num_samples, 2 * config.sampler.num_samples);  // the default
  EXPECT_FALSE(config.RenderSamplerOptions().stratified);
  const Intrinsics in{.width = 4, .height = 3, .fl_x = 4, .fl_y = 4, .cx = 2, .cy = 1.5};
  Mat4d pose = Mat4d::Identity();
  pose(2, 3) = 2.0;
  const Camera cam(in, pose);
  const std::vector<float> beta = {0.1f, 0.f, 0.2f};
  std::vector<Ray> rays;
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 4; ++i) rays.push_back(cam.RayThrough(i + 0.5, j + 0.5));
  int64_t evaluated[2] = {0, 0};
  for (int f : {1, 3}) {
    config.render.sample_factor = f;
    ASSERT_TRUE(config.Validate().ok());
    auto created = AvatarModel::Create(config, TinySetup(), Executor(1));
    ASSERT_TRUE(created.ok()) << created.status().message();
    (*created)->Initialize(5);
    RenderOutput out;
    (*created)->Render(rays, beta, Vec3f(1, 1, 1), Executor(1), &out);
    evaluated[f == 1 ? 0 : 1] = out.samples_evaluated;
  }
  EXPECT_GT(evaluated[0], 0);
  EXPECT_EQ(evaluated[1], 3 * evaluated[0]);
  // Marching mode: steps shrink by the factor.
  config.sampler.step_size = 0.03f;
  config.sampler.cone_angle = 0.004f;
  EXPECT_FLOAT_EQ(config.RenderSamplerOptions().step_size, 0.01f);
  EXPECT_FLOAT_EQ(config.RenderSamplerOptions().cone_angle, 0.004f / 3);
  EXPECT_EQ(config.RenderSamplerOptions().max_samples, 3 * config.sampler.max_samples);
  for (int bad : {0, 9}) {
    config.render.sample_factor = bad;
    const Status v = config.Validate();
    ASSERT_FALSE(v.ok()) << bad;
    EXPECT_NE(v.message().find("render.sample_factor"), std::string::npos) << v.message();
  }
}

// Large images render in bands of rows; every pixel must match a render of its own rays.
TEST(RenderImageTest, BandedRenderMatchesPerPixelRays) {
  ModelConfig config = TinyModelConfig("icef");
  config.render.supersample = 1;
  config.static_field.density_bias = 2.f;
  auto created = AvatarModel::Create(config, TinySetup(), Executor(2));
  ASSERT_TRUE(created.ok()) << created.status().message();
  AvatarModel& model = **created;
  model.Initialize(4);
  Intrinsics in;
  in.width = 300, in.height = 260, in.fl_x = in.fl_y = 300, in.cx = 150, in.cy = 130;  // 78 000 rays: 2 bands
  Mat4d pose = Mat4d::Identity();
  pose(2, 3) = 2.0;
  const Camera cam(in, pose);
  const std::vector<float> beta = {0.1f, 0.f, 0.2f};
  const RenderedImage img = RenderImage(model, cam, beta, Vec3f(1, 1, 1), Executor(2));
  ASSERT_EQ(img.color.width, 300);
  ASSERT_EQ(img.depth.height, 260);
  for (int j : {0, 100, 217, 218, 259})  // rows of both bands, either side of the band edge (218)
    for (int i : {0, 150, 299}) {
      const Ray ray = cam.RayThrough(i + 0.5, j + 0.5);
      RenderOutput out;
      model.Render(std::span<const Ray>(&ray, 1), beta, Vec3f(1, 1, 1), Executor(1), &out);
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(img.color.At(i, j, c), out.color[c], 1e-6) << i << "," << j;
      EXPECT_NEAR(img.depth.At(i, j, 0), out.depth[0], 1e-6) << i << "," << j;
      EXPECT_NEAR(img.mask.At(i, j, 0), out.mask[0], 1e-6) << i << "," << j;
    }
}

// Render marches rays in rounds and stops them once opaque; the result must be that of
// evaluating the fields at every sample and compositing them all (render/compositing.h).
TEST(AvatarModelTest, RenderEqualsCompositingEverySampleWhileSkippingOccludedOnes) {
  for (const char* method : {"icef", "nerface"}) {
    SCOPED_TRACE(method);
    ModelConfig config = TinyModelConfig(method);
    config.static_field.density_bias = 4.5f;  // opaque within a few samples along most rays
    config.deformation.output_init_scale = 0.5f;
    config.render.transmittance_eps = 3e-3;  // renders stop at their own threshold, not training's
    auto created = AvatarModel::Create(config, TinySetup(), Executor(2));
    ASSERT_TRUE(created.ok()) << created.status().message();
    AvatarModel& model = **created;
    model.Initialize(5);
    std::vector<Ray> rays;
    Rng rng(8, StreamId("rays"));
    for (int r = 0; r < 500; ++r) {
      const Vec3f o(float(rng.Uniform(-0.6, 0.6)), float(rng.Uniform(-0.6, 0.6)), 2.f);
      const Vec3f target(float(rng.Uniform(-0.3, 0.3)), float(rng.Uniform(-0.3, 0.3)), 0.f);
      rays.push_back(Ray{o, (target - o).normalized()});
    }
    const std::vector<float> beta = {0.9f, 0.1f, 0.7f};  // far from the training expressions: kappa < 1
    const Executor ex(2);
    RenderOutput out;
    model.Render(rays, beta, Vec3f(1, 1, 1), ex, &out);

    RaySamples samples;
    SampleRays(rays, model.setup().aabb, config.RenderSamplerOptions(), &model.occupancy(), 0, 0, ex,
               &samples);
    const int64_t n = samples.size();
    std::vector<float> dirs(3 * n), offsets(3 * n, 0.f), canonical(samples.positions), sigma(n), rgb(3 * n);
    for (int64_t r = 0; r < samples.num_rays(); ++r)
      for (int64_t i = samples.ray_offset[r]; i < samples.ray_offset[r] + samples.ray_count[r]; ++i)
        for (int a = 0; a < 3; ++a) dirs[3 * i + a] = rays[r].direction[a];
    std::vector<float> betas;
    for (int64_t i = 0; i < n; ++i) betas.insert(betas.end(), beta.begin(), beta.end());
    if (model.warp()) {
      model.Offsets(ex, n, samples.positions.data(), beta, offsets.data());
      for (int64_t i = 0; i < 3 * n; ++i) canonical[i] += offsets[i];
    }
    model.QueryStatic(ex, n, canonical.data(), dirs.data(), model.warp() ? nullptr : betas.data(),
                      sigma.data(), rgb.data());
    const float bg[3] = {1.f, 1.f, 1.f};
    CompositeInputs<float> in{sigma,
                              rgb,
                              samples.t,
                              samples.dt,
                              samples.ray_offset,
                              samples.ray_count,
                              std::span<const float>(bg, 3)};
    CompositeOutputs<float> ref;
    CompositeOptions render_eps;
    render_eps.transmittance_eps = config.render.transmittance_eps;
    CompositeForward(in, render_eps, ex, &ref);
    int64_t used = 0;
    for (int64_t r = 0; r < samples.num_rays(); ++r) {
      for (int a = 0; a < 3; ++a) ASSERT_NEAR(out.color[3 * r + a], ref.color[3 * r + a], 2e-6) << r;
      ASSERT_NEAR(out.opacity[r], ref.opacity[r], 2e-6) << r;
      ASSERT_NEAR(out.depth[r], ref.depth[r], 2e-5) << r;
      used += ref.num_used[r];
    }
    EXPECT_GE(out.samples_evaluated, used);
    EXPECT_LT(out.samples_evaluated, n * 3 / 4) << "used " << used << " of " << n;
  }
}

// bf16_inference changes renders by no more than BF16's precision allows, and only renders.
TEST(AvatarModelTest, Bf16InferenceRendersCloseToFp32) {
  std::vector<Ray> rays;
  Rng rng(9, StreamId("rays"));
  for (int r = 0; r < 400; ++r) {
    const Vec3f o(float(rng.Uniform(-0.3, 0.3)), float(rng.Uniform(-0.3, 0.3)), 2.f);
    rays.push_back(Ray{o, Vec3f(0, 0, -1)});
  }
  const std::vector<float> beta = {0.9f, 0.1f, 0.7f};  // kappa < 1: the JVP runs too
  RenderOutput out[2];
  for (int b = 0; b < 2; ++b) {
    ModelConfig config = TinyModelConfig("icef");
    config.static_field.density_bias = 2.f;
    config.deformation.output_init_scale = 0.5f;
    config.bf16_inference = b == 1;
    auto created = AvatarModel::Create(config, TinySetup(), Executor(2));
    ASSERT_TRUE(created.ok()) << created.status().message();
    (*created)->Initialize(5);
    (*created)->Render(rays, beta, Vec3f(1, 1, 1), Executor(2), &out[b]);
  }
  double mse = 0, max_diff = 0;
  for (size_t i = 0; i < out[0].color.size(); ++i) {
    const double d = out[1].color[i] - out[0].color[i];
    mse += d * d / out[0].color.size();
    max_diff = std::max(max_diff, std::abs(d));
  }
  EXPECT_LT(max_diff, 0.03);
  EXPECT_GT(-10 * std::log10(std::max(mse, 1e-20)), 40.0);
  if (nn::Bf16Supported()) {
    EXPECT_GT(max_diff, 0.0);
  }
}

TEST(AvatarModelTest, TrainLossGradientMatchesFiniteDifferences) {
  for (const char* method : {"icef", "nerface"}) {
    auto model = MakeModel(method, 0.05f);
    model->static_field().SetLevelWeights({1.f, 0.8f, 0.4f, 0.1f});  // coarse-to-fine scaling too
    TrainRays batch = testing_model::RandomBatch(24, 5);
    // L_depth on every other ray (NaN: no target), beside L_dist on the same sample weights; its
    // weight is large enough that a wrong sign of its gradient fails the check.
    Rng depth_rng(5, StreamId("depth_target"));
    for (int r = 0; r < 24; ++r)
      batch.depth_target.push_back(r % 2 ? std::numeric_limits<float>::quiet_NaN()
                                         : static_cast<float>(depth_rng.Uniform(1.5, 2.5)));
    LossWeights w;
    w.lambda_id = 0.5;
    w.lambda_mask = 0.2;
    w.lambda_distortion = 0.01 * std::sqrt(3.0);  // distances in aabb diagonals (sqrt 3 here)
    w.lambda_depth_prior = 300.0;
    w.depth_prior_window = 0.05;  // offsets clamped to +-0.05 diagonals, samples 0.25 behind left out:
    w.depth_prior_reach = 0.25;   // both fixed along each ray, so L_depth stays smooth in the parameters
    w.lambda_symmetry = 0.3;      // mirrored samples through the warp and both fields
    w.symmetry_colour = 0.0;  // its colour weight is a stop-gradient (symmetry_loss_test checks that part)
    w.symmetry_max_samples = 64;
    const Executor ex(1);
    // Raise densities so the compositing weights are non-trivial.
    nn::ParameterStore& store = model->store();
    store.ZeroGrads();
    model->TrainForwardBackward(batch, w, 3, 0, ex);
    const std::vector<double> grads(store.grads(), store.grads() + store.size());
    testing::ParameterGradientCheck check;
    check.rel_step = check.min_step = 3e-3f;
    check.skip_kinks = false;
    check.abs_tol_frac = 0;
    check.abs_tol = 1e-6;
    const auto report = check.Run(store.params(), grads,
                                  [&] { return model->TrainForwardBackward(batch, w, 3, 0, ex).total; });
    EXPECT_TRUE(report.ok()) << method << ":\n" << report.failures;
    EXPECT_GT(std::abs(*std::max_element(grads.begin(), grads.end(),
                                         [](double a, double b) { return std::abs(a) < std::abs(b); })),
              1e-6)
        << method;
    store.ZeroGrads();
  }
}

// Importance sampling (config importance): the training step evaluates exactly importance_samples
// per ray that crosses the grid, drawn from the coarse samples by the model's density, and the step
// is deterministic.
TEST(AvatarModelTest, ImportanceSamplingTrainsOnTheResampledSamples) {
  const TrainRays batch = testing_model::RandomBatch(24, 5);
  const LossWeights w;
  auto step = [&](int importance) {
    ModelConfig config = TinyModelConfig("icef");
    config.importance.num_samples = importance;
    auto model = AvatarModel::Create(config, TinySetup(), Executor(2));
    ICEF_CHECK(model.ok(), model.status().message());
    (*model)->Initialize(7);
    return (*model)->TrainForwardBackward(batch, w, 3, 0, Executor(2));
  };
  const LossTerms plain = step(0), fine = step(12), again = step(12);
  EXPECT_EQ(plain.samples, 24 * 16);  // sampler.num_samples of the tiny config, none skipped
  EXPECT_EQ(fine.samples, 24 * 12);
  EXPECT_EQ(fine.total, again.total);
  EXPECT_NE(fine.total, plain.total);
  EXPECT_TRUE(fine.AllFinite());
}

}  // namespace
}  // namespace icef

namespace icef {
namespace {

// No clipping of new expressions (docs/design.md §3): geometry that an expression's warp moves out of
// the training grid (and out of the visual hull carved in training) is rendered, because the
// render-time grid is built for the rendered expression and the hull is looked up at canonical
// points. The setup is a hand-made warp that shifts everything down by 0.2 * beta_0 (an "opening
// jaw"), a canonical field dense everywhere, and a hull that allows only y >= 0 (the "training
// silhouette" above the chin line y = 0).
TEST(AvatarModelTest, RenderOccupancyFollowsTheWarpBeyondTheTrainingHull) {
  ModelConfig config = TinyModelConfig("warp");
  config.static_field.density_bias = 3.f;  // dense everywhere: opacity ~1 over any 0.25 of path
  ModelSetup setup = TinySetup();
  for (auto& e : setup.training_expressions) std::fill(e.begin(), e.end(), 0.f);
  auto created = AvatarModel::Create(config, setup, Executor(2));
  ASSERT_TRUE(created.ok()) << created.status().message();
  AvatarModel& model = **created;
  model.Initialize(3);
  // g(x, beta) = (0, 0.4 beta_0, 0) half-extents for beta_0 >= 0: D(x) = x + (0, 0.2 beta_0, 0), so
  // what sits at canonical y appears 0.2 beta_0 lower.
  nn::ParameterStore& store = model.store();
  const int block = store.FindBlock("deformation");
  ASSERT_GE(block, 0);
  float* w = store.params() + store.block(block).offset;
  std::fill(w, w + store.block(block).size, 0.f);
  const int input =
      3 * (1 + 2 * config.deformation.num_frequencies) + setup.expression_dim;  // [freq(x), beta]
  const int h0 = config.deformation.hidden[0], h1 = config.deformation.hidden[1];
  w[(input - setup.expression_dim) * h0 + 0] = 1.f;  // beta_0 -> hidden unit 0
  w[input * h0 + 0 * h1 + 0] = 1.f;                  // unit 0 -> unit 0
  w[input * h0 + h0 * h1 + 0 * 3 + 1] = 0.4f;        // unit 0 -> y offset
  const std::vector<float> open = {1.f, 0.f, 0.f}, neutral = {0.f, 0.f, 0.f};
  std::vector<float> probe = {0.f, -0.1f, 0.f}, offset(3);
  model.OffsetsPhi(Executor(1), 1, probe.data(), open, offset.data());
  ASSERT_NEAR(offset[1], 0.2f, 1e-5f);  // the hand-made warp is what the comment says

  const int r = model.occupancy().resolution();
  std::vector<uint8_t> hull(model.occupancy().num_cells(), 0);
  for (int z = 0; z < r; ++z)
    for (int y = r / 2; y < r; ++y)
      for (int x = 0; x < r; ++x) hull[model.occupancy().CellIndex(x, y, z)] = 1;
  ASSERT_TRUE(model.occupancy().SetAllowed(hull).ok());

  // Horizontal rays at heights y through the middle of the box.
  auto opacity = [&](float y, std::span<const float> beta, const OccupancyGrid* grid) {
    RenderOutput out;
    const std::vector<Ray> rays = {Ray{Vec3f(0.f, y, 2.f), Vec3f(0.f, 0.f, -1.f)}};
    model.Render(rays, beta, Vec3f::Ones(), Executor(1), &out, grid);
    return out.opacity[0];
  };
  const OccupancyGrid open_grid = model.RenderOccupancy(open, Executor(2));
  const OccupancyGrid neutral_grid = model.RenderOccupancy(neutral, Executor(2));
  // Above the chin line: rendered either way.
  EXPECT_GT(opacity(0.2f, open, nullptr), 0.9f);
  EXPECT_GT(opacity(0.2f, open, &open_grid), 0.9f);
  // Below it, where the opened "jaw" now is: the training grid clips it, the expression's grid does not.
  EXPECT_LT(opacity(-0.1f, open, nullptr), 1e-6f);
  EXPECT_GT(opacity(-0.1f, open, &open_grid), 0.9f);
  // At neutral nothing moved, and nothing is added below the hull.
  EXPECT_LT(opacity(-0.1f, neutral, &neutral_grid), 1e-6f);
  // Far below, where the warp brings no canonical geometry from inside the hull: still empty.
  EXPECT_LT(opacity(-0.4f, open, &open_grid), 1e-6f);
  // RenderImage builds the expression's grid by default; the training grid on request.
  Intrinsics in;
  in.width = in.height = 16;
  in.fl_x = in.fl_y = 16;
  in.cx = in.cy = 8;
  const Camera camera = Camera::LookAt(in, Vec3d(0, 0, 2), Vec3d::Zero());
  const RenderedImage with = RenderImage(model, camera, open, Vec3f::Ones(), Executor(2));
  const RenderedImage without =
      RenderImage(model, camera, open, Vec3f::Ones(), Executor(2), RenderOccupancyMode::kTraining);
  auto covered_rows = [](const Image& alpha) {
    int rows = 0;
    for (int y = 0; y < alpha.height; ++y) rows += alpha.At(alpha.width / 2, y, 0) > 0.5f;
    return rows;
  };
  EXPECT_GT(covered_rows(with.opacity), covered_rows(without.opacity) + 1);
}

}  // namespace
}  // namespace icef
