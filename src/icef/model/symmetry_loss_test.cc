#include "icef/model/symmetry_loss.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "icef/core/rng.h"
#include "icef/model/avatar_model.h"
#include "icef/model/model_test_util.h"
#include "icef/testing/gradient_check.h"

namespace icef {
namespace {

struct Inputs {
  std::vector<double> sigma_a, rgb_a, sigma_b, rgb_b, dt;
};

Inputs RandomInputs(int m, uint64_t seed) {
  Rng rng(seed, StreamId("symmetry_inputs"));
  Inputs in;
  for (int j = 0; j < m; ++j) {
    in.sigma_a.push_back(rng.Uniform(0.0, 30.0));
    in.sigma_b.push_back(rng.Uniform(0.0, 30.0));
    in.dt.push_back(rng.Uniform(0.005, 0.05));
    for (int c = 0; c < 3; ++c) {
      in.rgb_a.push_back(rng.Uniform());
      in.rgb_b.push_back(rng.Uniform());
    }
  }
  return in;
}

double Loss(const Inputs& in, double colour) {
  return SymmetryLoss<double>(int64_t(in.dt.size()), in.sigma_a.data(), in.rgb_a.data(), in.sigma_b.data(),
                              in.rgb_b.data(), in.dt.data(), colour, 1.0, nullptr, nullptr, nullptr, nullptr);
}

TEST(SymmetryLossTest, ZeroForMirrorImagesPositiveOtherwise) {
  Inputs in = RandomInputs(6, 1);
  in.sigma_b = in.sigma_a;
  in.rgb_b = in.rgb_a;
  EXPECT_EQ(Loss(in, 1.0), 0.0);
  in.sigma_b[2] += 5.0;
  EXPECT_GT(Loss(in, 0.0), 0.0);
  in.sigma_b = in.sigma_a;
  in.rgb_b[4] += 0.2;
  EXPECT_EQ(Loss(in, 0.0), 0.0);  // colour part off
  EXPECT_GT(Loss(in, 1.0), 0.0);
}

TEST(SymmetryLossTest, GradientsMatchFiniteDifferences) {
  const int m = 7;
  const double colour = 0.6, scale = 1.3, h = 1e-6;
  for (uint64_t seed = 2; seed < 5; ++seed) {
    const Inputs in = RandomInputs(m, seed);
    std::vector<double> ds_a(m), dc_a(3 * m), ds_b(m), dc_b(3 * m);
    SymmetryLoss<double>(m, in.sigma_a.data(), in.rgb_a.data(), in.sigma_b.data(), in.rgb_b.data(),
                         in.dt.data(), colour, scale, ds_a.data(), dc_a.data(), ds_b.data(), dc_b.data());
    // The colour weight alpha_a alpha_b is held constant: differentiate the colour part with it frozen
    // by perturbing rgb only, and the opacity part with colour = 0 for the densities.
    auto check = [&](std::vector<double> Inputs::*field, const std::vector<double>& grad, double c,
                     const char* name) {
      for (size_t i = 0; i < grad.size(); ++i) {
        Inputs p = in, q = in;
        (p.*field)[i] += h;
        (q.*field)[i] -= h;
        const double fd = scale * (Loss(p, c) - Loss(q, c)) / (2 * h);
        EXPECT_NEAR(grad[i], fd, 1e-7 * std::max(1.0, std::abs(fd))) << name << " " << i << " seed " << seed;
      }
    };
    check(&Inputs::rgb_a, dc_a, colour, "rgb_a");
    check(&Inputs::rgb_b, dc_b, colour, "rgb_b");
    // Densities: the opacity part only (the colour part's weight is a stop-gradient).
    std::vector<double> ds_a0(m), dc0(3 * m), ds_b0(m);
    SymmetryLoss<double>(m, in.sigma_a.data(), in.rgb_a.data(), in.sigma_b.data(), in.rgb_b.data(),
                         in.dt.data(), colour, scale, ds_a0.data(), dc0.data(), ds_b0.data(), dc0.data());
    check(&Inputs::sigma_a, ds_a0, 0.0, "sigma_a");
    check(&Inputs::sigma_b, ds_b0, 0.0, "sigma_b");
  }
}

TEST(SymmetryLossTest, ModelFindsThePlaneOfAFrontalFace) {
  auto model =
      AvatarModel::Create(testing_model::TinyModelConfig("icef"), testing_model::TinySetup(), Executor(1));
  ASSERT_TRUE(model.ok());
  ASSERT_TRUE((*model)->symmetry_plane().has_value());
  const SymmetryPlane& plane = *(*model)->symmetry_plane();
  EXPECT_GT(std::abs(plane.normal().x()), 0.99f);  // the test face is mirror-symmetric in x
  EXPECT_NEAR(plane.offset(), 0.f, 0.01f);
}

// The model's L_sym path end to end: gathering, mirroring, the second static-field pass, the
// scatter into the main backward and the warp's share. Its gradient alone is the difference of two
// backward passes (lambda_symmetry on and off), checked against finite differences of terms.symmetry.
TEST(SymmetryLossTest, ModelGradientMatchesFiniteDifferences) {
  for (const char* method : {"icef", "nerface"}) {
    ModelConfig config = testing_model::TinyModelConfig(method);
    const bool applies = std::string(method) != "nerface";  // no canonical space: the prior is off
    config.deformation.output_init_scale = 0.05f;
    config.bf16_training = false;  // finite differences need more than BF16's 8 bits
    config.static_field.grid.num_levels =
        2;  // coarse cells: few samples cross a cell face under a parameter step
    config.static_field.grid.finest_resolution = 6;
    config.static_field.density_bias = 1.f;  // visible opacities in the tiny box
    auto created = AvatarModel::Create(config, testing_model::TinySetup(), Executor(1));
    ASSERT_TRUE(created.ok()) << created.status().message();
    AvatarModel& model = **created;
    model.Initialize(11);
    // A field with structure (the initial one is nearly uniform): random offsets on every parameter.
    Rng noise(12, StreamId("params"));
    for (int64_t i = 0; i < model.store().size(); ++i)
      model.store().params()[i] += static_cast<float>(noise.Uniform(-0.3, 0.3));
    TrainRays batch;
    Rng rng(6, StreamId("batch"));
    for (int r = 0; r < 16; ++r) {
      const Vec3f o(static_cast<float>(rng.Uniform(-0.3, 0.3)), static_cast<float>(rng.Uniform(-0.3, 0.3)),
                    2.f);
      batch.rays.push_back(Ray{o, Vec3f(0.1f, 0.f, -1.f).normalized()});
      batch.frame.push_back(r % 3);
      for (int a = 0; a < 3; ++a) batch.target_rgb.push_back(rng.Uniform());
    }
    const Executor ex(1);
    LossWeights off, on;
    on.lambda_symmetry = 1.0;
    on.symmetry_max_samples = 48;
    nn::ParameterStore& store = model.store();
    auto grads_with = [&](const LossWeights& w) {
      store.ZeroGrads();
      const LossTerms t = model.TrainForwardBackward(batch, w, 3, 0, ex);
      std::vector<double> g(store.grads(), store.grads() + store.size());
      return std::pair{t, g};
    };
    const auto [t_on, g_on] = grads_with(on);
    const auto [t_off, g_off] = grads_with(off);
    if (!applies) {
      EXPECT_EQ(t_on.Get("symmetry"), 0.0);
      EXPECT_EQ(g_on, g_off) << "nerface: lambda_symmetry must not change its gradients";
      continue;
    }
    ASSERT_GT(t_on.Get("symmetry"), 1e-4) << method;  // differences at h and h/2: testing/gradient_check.h
    std::vector<double> g(g_on.size());
    for (size_t i = 0; i < g.size(); ++i) g[i] = g_on[i] - g_off[i];
    testing::ParameterGradientCheck check;
    check.top_k = 16;
    check.rel_tol = 2e-2;
    check.abs_tol_frac = 0;
    check.abs_tol = 1e-6;
    check.min_checked = 10;
    const auto report = check.Run(
        store.params(), g, [&] { return model.TrainForwardBackward(batch, on, 3, 0, ex).Get("symmetry"); });
    EXPECT_TRUE(report.ok()) << method << ":\n" << report.failures;
    store.ZeroGrads();
  }
}

}  // namespace
}  // namespace icef
