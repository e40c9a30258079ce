#include "icef/train/density_start.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "icef/core/rng.h"
#include "icef/face/face_model.h"
#include "icef/model/model_test_util.h"

namespace icef {
namespace {

// The face model's average head, world = (head - translation) / 2.
face::FaceFit ScaledFit() {
  face::FaceFit fit;
  fit.head_from_world.scale = 2.0;
  fit.head_from_world.translation = Vec3d(0.1, 0.0, 0.0);
  return fit;
}

float Target(const face::FaceFit& fit, const DensityStartOptions& o, const Vec3f& head_point) {
  const Vec3f world = fit.head_from_world.ApplyInverse(head_point.cast<double>()).cast<float>();
  float t = 0;
  DensityStartTargets(fit, -4.f, o, 1, world.data(), &t, Executor(1));
  return t;
}

TEST(DensityStartTest, TargetIsHighInsideTheErodedHeadAndLowOutsideIt) {
  const face::FaceFit fit = ScaledFit();
  DensityStartOptions o;  // inside 3, width 0.01, erosion 0.04 head units
  const face::FaceModel head(fit.shape);
  const face::ExpressionState neutral = head.Prepare(std::vector<float>(face::kNumExpressions, 0.f));
  EXPECT_NEAR(Target(fit, o, Vec3f(0.f, 0.1f, 0.f)), 3.f, 1e-3f);  // the middle of the skull
  EXPECT_NEAR(Target(fit, o, Vec3f(0.f, 0.f, 3.f)), -4.f, 1e-3f);  // far in front of the face
  const Vec3f surface = head.ProjectNeutral(Vec3f(0.05f, -0.1f, 0.6f), Vec3f(0.f, 0.f, -1.f));
  const Vec3f normal = head.Normal(surface, neutral);
  // On the fitted surface and outside it the target is (nearly) the empty field's: the seeded head
  // lies 0.04 head units inside it, 4 widths.
  EXPECT_LT(Target(fit, o, surface), -4.f + 0.2f);
  EXPECT_LT(Target(fit, o, surface + 0.01f * normal), Target(fit, o, surface));
  // Inward it rises to the inside value.
  EXPECT_GT(Target(fit, o, surface - 0.03f * normal), Target(fit, o, surface) + 0.5f);
  EXPECT_GT(Target(fit, o, surface - 0.1f * normal), Target(fit, o, surface - 0.03f * normal) + 0.5f);
  // Without erosion the surface is halfway.
  o.erosion = 0.f;
  EXPECT_NEAR(Target(fit, o, surface), -0.5f, 0.05f);
  // Distances are the head's: the scale of head_from_world does not change the target of a head point.
  face::FaceFit unscaled = fit;
  unscaled.head_from_world.scale = 1.0;
  EXPECT_NEAR(Target(unscaled, o, surface + 0.005f * normal), Target(fit, o, surface + 0.005f * normal),
              1e-4f);
}

TEST(DensityStartTest, LossGradientMatchesFiniteDifferences) {
  Rng rng(7, StreamId("density_start_test"));
  const int n = 9;
  std::vector<double> sigma(n), targets(n), grad(n), unused(n);
  for (int i = 0; i < n; ++i) {
    sigma[i] = std::exp(rng.Uniform(-5.0, 4.0));
    targets[i] = rng.Uniform(-4.0, 3.0);
  }
  LogDensityLoss<double>(n, sigma.data(), targets.data(), grad.data());
  for (int i = 0; i < n; ++i) {
    const double h = 1e-6 * sigma[i];
    std::vector<double> plus = sigma, minus = sigma;
    plus[i] += h;
    minus[i] -= h;
    const double numeric = (LogDensityLoss<double>(n, plus.data(), targets.data(), unused.data()) -
                            LogDensityLoss<double>(n, minus.data(), targets.data(), unused.data())) /
                           (2 * h);
    EXPECT_NEAR(grad[i], numeric, 1e-7 * std::max(1.0, std::abs(numeric))) << i;
  }
}

// Over a 16^3 lattice of the front of the head (world): the mean log-density where the target is the
// inside value and where it is the empty field's, and the mean squared error to the targets.
struct FieldStats {
  double inside = 0, outside = 0, mse = 0;
};
FieldStats MeasureField(AvatarModel& model, const face::FaceFit& fit) {
  const int r = 16, n = r * r * r;
  const Vec3f lo(-0.5f, -0.8f, 0.2f), hi(0.5f, 0.4f, 0.8f);  // the face at scale 0.5
  std::vector<float> positions, targets(n), sigma(n);
  for (int z = 0; z < r; ++z)
    for (int y = 0; y < r; ++y)
      for (int x = 0; x < r; ++x) {
        const Vec3f u((x + 0.5f) / r, (y + 0.5f) / r, (z + 0.5f) / r);
        const Vec3f p = lo + u.cwiseProduct(hi - lo);
        positions.insert(positions.end(), {p.x(), p.y(), p.z()});
      }
  const Executor executor(1);
  DensityStartTargets(fit, -4.f, DensityStartOptions{}, n, positions.data(), targets.data(), executor);
  StaticFieldContext ctx;
  model.static_field().Density(executor, n, positions.data(), nullptr, sigma.data(), &ctx);
  FieldStats m;
  int n_in = 0, n_out = 0;
  for (int i = 0; i < n; ++i) {
    const double log_sigma = std::log(sigma[i]);
    m.mse += (log_sigma - targets[i]) * (log_sigma - targets[i]) / n;
    if (targets[i] > 2.f) {
      m.inside += log_sigma;
      ++n_in;
    } else if (targets[i] < -3.9f) {
      m.outside += log_sigma;
      ++n_out;
    }
  }
  EXPECT_GT(n_in, 50);
  EXPECT_GT(n_out, 100);
  m.inside /= n_in;
  m.outside /= n_out;
  return m;
}

std::unique_ptr<AvatarModel> TinyModel() {
  ModelSetup setup = testing_model::TinySetup();
  setup.aabb = Aabb{Vec3f::Constant(-1.f), Vec3f::Constant(1.f)};
  auto model = AvatarModel::Create(testing_model::TinyModelConfig("icef"), setup, Executor(1));
  ICEF_CHECK(model.ok(), model.status().message());
  (*model)->Initialize(3);
  return std::move(model).value();
}

TEST(DensityStartTest, SeedsTheHeadIntoTheFieldDeterministically) {
  face::FaceFit fit;  // the average head at twice its size in the world
  fit.head_from_world.scale = 0.5;
  DensityStartOptions o;
  o.points = 4096;
  o.steps = 100;
  std::unique_ptr<AvatarModel> before = TinyModel(), a = TinyModel(), b = TinyModel();
  const FieldStats start = MeasureField(*before, fit);
  EXPECT_NEAR(start.inside, start.outside, 0.5);  // the uniform start knows no head

  const Result<double> mse_a = SeedDensityFromFaceModel(fit, o, 11, a.get(), Executor(1));
  ASSERT_TRUE(mse_a.ok()) << mse_a.status().message();
  const FieldStats seeded = MeasureField(*a, fit);
  EXPECT_GT(seeded.inside - seeded.outside, 3.0);
  EXPECT_NEAR(seeded.outside, -4.0, 1.0);
  EXPECT_LT(seeded.mse, 0.3 * start.mse);

  const Result<double> mse_b = SeedDensityFromFaceModel(fit, o, 11, b.get(), Executor(1));
  ASSERT_TRUE(mse_b.ok());
  EXPECT_EQ(*mse_a, *mse_b);
  const nn::ParameterStore& pa = a->store();
  const nn::ParameterStore& pb = b->store();
  ASSERT_EQ(pa.size(), pb.size());
  EXPECT_TRUE(std::equal(pa.params(), pa.params() + pa.size(), pb.params()));
  for (int64_t i = 0; i < pa.size(); ++i) ASSERT_EQ(pa.grads()[i], 0.f);  // nothing left for the trainer
}

TEST(DensityStartTest, RejectsBadOptions) {
  std::unique_ptr<AvatarModel> model = TinyModel();
  DensityStartOptions o;
  o.steps = 1;
  o.width = 0.f;
  EXPECT_FALSE(SeedDensityFromFaceModel(face::FaceFit{}, o, 1, model.get(), Executor(1)).ok());
}

}  // namespace
}  // namespace icef
