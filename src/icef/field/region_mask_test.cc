#include "icef/field/region_mask.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "icef/core/rng.h"

namespace icef {
namespace {

constexpr double kPi = 3.14159265358979323846;

// A schematic iBUG-68 face in the world frame (x right, y up, +z towards the viewer), inter-ocular
// distance 0.6, centred at `centre` and scaled by `scale`.
std::vector<Vec3f> FaceLandmarks(const Vec3f& centre = Vec3f::Zero(), float scale = 1.f) {
  std::vector<Vec3f> p(kNumLandmarks);
  for (int i = 0; i <= 16; ++i) {  // jaw
    const double a = kPi * i / 16;
    p[i] = Vec3f(-0.7 * std::cos(a), 0.2 - 0.75 * std::sin(a), -0.3 + 0.45 * std::sin(a));
  }
  for (int i = 0; i < 5; ++i) {  // brows
    const float x = 0.12f + 0.43f * (4 - i) / 4.f, y = 0.45f + 0.05f * std::sin(kPi * i / 4);
    p[17 + i] = Vec3f(-x, y, 0.2f);
    p[26 - i] = Vec3f(x, y, 0.2f);
  }
  for (int i = 0; i < 4; ++i)
    p[27 + i] = Vec3f(0, 0.3f - 0.1f * i, 0.25f + 0.07f * i);                       // nose bridge, tip = 30
  for (int i = 0; i < 5; ++i) p[31 + i] = Vec3f(-0.12f + 0.06f * i, -0.08f, 0.3f);  // nostrils
  for (int e = 0; e < 2; ++e)
    for (int i = 0; i < 6; ++i) {  // eyes: 36-41 right eye (image left), 42-47 left eye
      const double a = kPi - 2 * kPi * i / 6;
      p[36 + 6 * e + i] = Vec3f((e == 0 ? -0.3 : 0.3) + 0.1 * std::cos(a), 0.3 + 0.04 * std::sin(a), 0.2);
    }
  for (int i = 0; i < 12; ++i) {  // outer lips
    const double a = kPi - 2 * kPi * i / 12;
    p[48 + i] = Vec3f(0.22 * std::cos(a), -0.28 + 0.09 * std::sin(a), 0.3 + 0.03 * std::sin(a) * std::sin(a));
  }
  for (int i = 0; i < 8; ++i) {  // inner lips
    const double a = kPi - 2 * kPi * i / 8;
    p[60 + i] = Vec3f(0.15 * std::cos(a), -0.28 + 0.04 * std::sin(a), 0.31);
  }
  for (Vec3f& q : p) q = centre + scale * q;
  return p;
}

RegionMask MakeMask(const RegionMaskOptions& options = {}) {
  Result<RegionMask> mask = RegionMask::FromLandmarks(FaceLandmarks(), options, Executor(2));
  EXPECT_TRUE(mask.ok()) << mask.status().ToString();
  return std::move(mask).value();
}

TEST(RegionMaskTest, OneOnTheExpressionLandmarks) {
  const RegionMask mask = MakeMask();
  EXPECT_NEAR(mask.inter_ocular_distance(), 0.6f, 1e-5);
  for (int i = 17; i < 27; ++i) EXPECT_GT(mask.Evaluate(mask.landmarks()[i]), 0.99f) << "brow " << i;
  for (int i = 36; i < 68; ++i) EXPECT_GT(mask.Evaluate(mask.landmarks()[i]), 0.99f) << "landmark " << i;
  for (int i = 36; i < 68; ++i) EXPECT_EQ(mask.EvaluateExact(mask.landmarks()[i]), 1.f);
  // Inside the open mouth and at the eye centres (filled loops).
  EXPECT_GT(mask.Evaluate(Vec3f(0, -0.28f, 0.3f)), 0.99f);
  EXPECT_GT(mask.Evaluate(Vec3f(0.3f, 0.3f, 0.2f)), 0.99f);
  EXPECT_EQ(mask.EvaluateRegionExact(FaceRegion::kMouth, Vec3f(0, -0.28f, 0.3f)), 1.f);
  EXPECT_EQ(mask.EvaluateRegionExact(FaceRegion::kEyes, Vec3f(0, -0.28f, 0.3f)), 0.f);
}

TEST(RegionMaskTest, ZeroAwayFromTheExpressionRegions) {
  const RegionMask mask = MakeMask();
  const std::vector<Vec3f> away = {
      mask.landmarks()[30],   // nose tip
      Vec3f(0, 0.95f, 0.1f),  // forehead top
      mask.landmarks()[2],    // cheek / jaw far points
      mask.landmarks()[14],
      mask.landmarks()[8],        // chin
      Vec3f(0.6f, -0.05f, 0.1f),  // cheek
      Vec3f(3, 3, 3),             // far away
      Vec3f(0, 0, -2),
  };
  for (const Vec3f& x : away) {
    EXPECT_EQ(mask.Evaluate(x), 0.f) << x.transpose();
    EXPECT_EQ(mask.EvaluateExact(x), 0.f) << x.transpose();
  }
}

TEST(RegionMaskTest, InUnitIntervalSmoothAndGridMatchesExact) {
  const RegionMask mask = MakeMask();
  Rng rng(1, StreamId("mask_test"));
  const float w = mask.options().softness * mask.inter_ocular_distance();
  // |dm/dsd| <= 15 / (16 w) per region; three regions in the union.
  const float lipschitz = 3.f * 15.f / (16.f * w);
  float max_grid_error = 0.f;
  for (int i = 0; i < 3000; ++i) {
    const Vec3f x(rng.Uniform(-0.9, 0.9), rng.Uniform(-0.7, 0.8), rng.Uniform(-0.3, 0.6));
    const float m = mask.Evaluate(x);
    ASSERT_GE(m, 0.f);
    ASSERT_LE(m, 1.f);
    const float exact = mask.EvaluateExact(x);
    max_grid_error = std::max(max_grid_error, std::abs(m - exact));
    const Vec3f dir = Vec3f(rng.Normal(), rng.Normal(), rng.Normal()).normalized();
    const float h = 1e-3f;
    EXPECT_LE(std::abs(mask.EvaluateExact(x + h * dir) - exact), lipschitz * h * 1.01f + 1e-6f);
  }
  EXPECT_LT(max_grid_error, 0.05f);
}

TEST(RegionMaskTest, GradientMatchesCentralDifferencesOfTheInterpolant) {
  const RegionMask mask = MakeMask();
  Rng rng(2, StreamId("mask_test"));
  int nonzero = 0;
  for (int i = 0; i < 300; ++i) {
    const Vec3f x = mask.landmarks()[17 + i % 51] + Vec3f(rng.Normal(), rng.Normal(), rng.Normal()) * 0.1f;
    const float h = 1e-4f;
    // Keep x +- h inside one cell: the trilinear interpolant's slope jumps across cell faces.
    const Vec3f q = (x - mask.grid_min()).cwiseQuotient(mask.grid_cell_size());
    const Vec3f frac = q - q.array().floor().matrix();
    const Vec3f margin = Vec3f::Constant(2 * h).cwiseQuotient(mask.grid_cell_size());
    if ((frac.array() < margin.array()).any() || (frac.array() > 1.f - margin.array()).any()) continue;
    Vec3f g;
    mask.EvaluateWithGradient(x, &g);
    if (g.norm() > 1e-3f) ++nonzero;
    for (int a = 0; a < 3; ++a) {
      Vec3f xp = x, xm = x;
      xp[a] += h;
      xm[a] -= h;
      const float fd = (mask.Evaluate(xp) - mask.Evaluate(xm)) / (2 * h);
      EXPECT_NEAR(g[a], fd, 2e-3f * (1.f + std::abs(fd))) << x.transpose();
    }
  }
  EXPECT_GT(nonzero, 50);  // the points really sample the transition band
  std::vector<float> positions, m(3), grads(9);
  for (int i = 0; i < 3; ++i)
    for (int a = 0; a < 3; ++a) positions.push_back(mask.landmarks()[50 + i][a] + 0.1f * a);
  mask.EvaluateBatch(positions.data(), 3, m.data(), grads.data());
  for (int i = 0; i < 3; ++i) {
    Vec3f g;
    EXPECT_EQ(m[i], mask.EvaluateWithGradient(
                        Vec3f(positions[3 * i], positions[3 * i + 1], positions[3 * i + 2]), &g));
    EXPECT_EQ(grads[3 * i + 1], g[1]);
  }
}

TEST(RegionMaskTest, ScalesWithTheFaceAndFollowsItsPosition) {
  const RegionMask unit = MakeMask();
  const Vec3f centre(5, -2, 1);
  Result<RegionMask> big = RegionMask::FromLandmarks(FaceLandmarks(centre, 10.f), RegionMaskOptions());
  ASSERT_TRUE(big.ok());
  EXPECT_NEAR(big->inter_ocular_distance(), 6.f, 1e-4);
  Rng rng(3, StreamId("mask_test"));
  for (int i = 0; i < 200; ++i) {
    const Vec3f x(rng.Uniform(-0.9, 0.9), rng.Uniform(-0.7, 0.8), rng.Uniform(-0.3, 0.6));
    EXPECT_NEAR(big->EvaluateExact(centre + 10.f * x), unit.EvaluateExact(x), 1e-3);
  }
}

TEST(RegionMaskTest, DisabledRegionsAreZero) {
  RegionMaskOptions options;
  options.mouth = false;
  const RegionMask mask = MakeMask(options);
  EXPECT_EQ(mask.Evaluate(Vec3f(0, -0.28f, 0.3f)), 0.f);
  EXPECT_GT(mask.Evaluate(mask.landmarks()[40]), 0.99f);
}

TEST(RegionMaskTest, OptionsAndInputsAreValidated) {
  RegionMaskOptions o;
  EXPECT_TRUE(o.Validate().ok());
  o.softness = 0.5f;  // larger than the margins
  EXPECT_FALSE(o.Validate().ok());
  o = RegionMaskOptions();
  o.brows = o.eyes = o.mouth = false;
  EXPECT_FALSE(o.Validate().ok());
  EXPECT_FALSE(RegionMask::FromLandmarks(std::vector<Vec3f>(10, Vec3f::Zero()), {}).ok());
  EXPECT_FALSE(RegionMask::FromLandmarks(std::vector<Vec3f>(68, Vec3f::Zero()), {}).ok());  // iod = 0
  std::vector<Vec3f> nan = FaceLandmarks();
  nan[3].x() = NAN;
  EXPECT_FALSE(RegionMask::FromLandmarks(nan, {}).ok());
}

Frame FrameLookingAtFace(double yaw, const std::vector<Vec3f>& landmarks, bool with_2d, bool with_3d) {
  Intrinsics k;
  k.width = 64;
  k.height = 64;
  k.fl_x = k.fl_y = 80;
  k.cx = k.cy = 32;
  Frame f;
  f.camera = Camera::LookAt(k, Vec3d(3 * std::sin(yaw), 0.2, 3 * std::cos(yaw)), Vec3d::Zero());
  if (with_2d) {
    std::vector<Vec2f> uv;
    for (const Vec3f& p : landmarks) uv.push_back(f.camera.Project(p.cast<double>())->uv.cast<float>());
    f.landmarks_2d = uv;
  }
  if (with_3d) f.landmarks_3d = landmarks;
  return f;
}

TEST(RegionMaskTest, FromDatasetUsesMean3dLandmarksElseTriangulates) {
  const std::vector<Vec3f> face = FaceLandmarks();
  Dataset with_3d;
  with_3d.root = "/tmp/face";
  std::vector<Vec3f> shifted = face;
  for (Vec3f& p : shifted) p += Vec3f(0, 0.1f, 0);
  with_3d.train = {FrameLookingAtFace(-0.4, face, false, true),
                   FrameLookingAtFace(0.4, shifted, false, true)};
  Result<RegionMask> a = RegionMask::FromDataset(with_3d, {});
  ASSERT_TRUE(a.ok()) << a.status().ToString();
  EXPECT_NEAR(a->landmarks()[48].y(), face[48].y() + 0.05f, 1e-5);  // the mean
  EXPECT_NE(a->source().find("landmarks_3d"), std::string::npos);

  Dataset with_2d;
  with_2d.root = "/tmp/face";
  for (double yaw : {-0.5, 0.0, 0.5}) with_2d.train.push_back(FrameLookingAtFace(yaw, face, true, false));
  Result<RegionMask> b = RegionMask::FromDataset(with_2d, {});
  ASSERT_TRUE(b.ok()) << b.status().ToString();
  EXPECT_NE(b->source().find("triangulated"), std::string::npos);
  for (int i = 0; i < kNumLandmarks; ++i) EXPECT_LT((b->landmarks()[i] - face[i]).norm(), 1e-3);
  EXPECT_GT(b->Evaluate(face[62]), 0.99f);

  Dataset none;
  none.root = "/tmp/face";
  none.train = {FrameLookingAtFace(0, face, false, false)};
  Result<RegionMask> c = RegionMask::FromDataset(none, {});
  ASSERT_FALSE(c.ok());
  EXPECT_NE(c.status().message().find("/tmp/face"), std::string::npos);
  EXPECT_NE(c.status().message().find("landmarks"), std::string::npos);
}

}  // namespace
}  // namespace icef
