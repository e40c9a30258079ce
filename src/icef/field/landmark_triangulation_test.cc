#include "icef/field/landmark_triangulation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "icef/core/rng.h"

namespace icef {
namespace {

Camera RandomCamera(Rng& rng) {
  Intrinsics k;
  k.width = 128;
  k.height = 96;
  k.fl_x = rng.Uniform(100, 200);
  k.fl_y = k.fl_x * rng.Uniform(0.9, 1.1);
  k.cx = 64 + rng.Uniform(-5, 5);
  k.cy = 48 + rng.Uniform(-5, 5);
  const double yaw = rng.Uniform(-0.7, 0.7), pitch = rng.Uniform(-0.3, 0.3), radius = rng.Uniform(2.5, 4.0);
  const Vec3d eye(radius * std::sin(yaw) * std::cos(pitch), radius * std::sin(pitch),
                  radius * std::cos(yaw) * std::cos(pitch));
  return Camera::LookAt(k, eye, Vec3d(rng.Uniform(-0.1, 0.1), rng.Uniform(-0.1, 0.1), 0));
}

std::vector<Vec3f> RandomPoints(Rng& rng) {
  std::vector<Vec3f> p;
  for (int i = 0; i < kNumLandmarks; ++i)
    p.emplace_back(rng.Uniform(-0.6, 0.6), rng.Uniform(-0.6, 0.6), rng.Uniform(-0.4, 0.4));
  return p;
}

std::vector<Frame> MakeFrames(const std::vector<Vec3f>& points, int views, double noise_px, Rng& rng) {
  std::vector<Frame> frames;
  for (int v = 0; v < views; ++v) {
    Frame f;
    f.camera = RandomCamera(rng);
    std::vector<Vec2f> uv;
    for (const Vec3f& p : points) {
      const auto proj = f.camera.Project(p.cast<double>());
      EXPECT_TRUE(proj.has_value());
      uv.push_back((proj->uv + noise_px * Vec2d(rng.Normal(), rng.Normal())).cast<float>());
    }
    f.landmarks_2d = uv;
    frames.push_back(f);
  }
  return frames;
}

TEST(LandmarkTriangulationTest, RecoversExactPointsFromRandomCameras) {
  for (int views : {2, 3, 5}) {
    Rng rng(views, StreamId("triangulation_test"));
    const std::vector<Vec3f> points = RandomPoints(rng);
    const std::vector<Frame> frames = MakeFrames(points, views, 0.0, rng);
    Result<TriangulatedLandmarks> tri = TriangulateLandmarks(frames);
    ASSERT_TRUE(tri.ok()) << tri.status().ToString();
    for (int i = 0; i < kNumLandmarks; ++i) {
      EXPECT_LT((tri->points[i] - points[i]).norm(), 1e-4) << "landmark " << i << " views " << views;
      EXPECT_EQ(tri->num_views[i], views);
    }
    EXPECT_LT(tri->MeanRms(), 1e-2);
  }
}

TEST(LandmarkTriangulationTest, RefinementLowersReprojectionErrorUnderNoise) {
  Rng rng(11, StreamId("triangulation_test"));
  const std::vector<Vec3f> points = RandomPoints(rng);
  const std::vector<Frame> frames = MakeFrames(points, 5, 1.0, rng);
  TriangulationOptions linear_only;
  linear_only.refine = false;
  Result<TriangulatedLandmarks> dlt = TriangulateLandmarks(frames, linear_only);
  Result<TriangulatedLandmarks> refined = TriangulateLandmarks(frames);
  ASSERT_TRUE(dlt.ok() && refined.ok());
  EXPECT_LE(refined->MeanRms(), dlt->MeanRms() + 1e-9);
  double err = 0;
  for (int i = 0; i < kNumLandmarks; ++i) err += (refined->points[i] - points[i]).norm();
  EXPECT_LT(err / kNumLandmarks, 0.03);  // 1 px noise at ~150 px focal, 3 m away: about 1-2 cm
  EXPECT_GT(refined->MeanRms(), 0.3);    // the noise is really there
}

TEST(LandmarkTriangulationTest, IgnoresInvisibleLandmarksAndReportsTooFewViews) {
  Rng rng(3, StreamId("triangulation_test"));
  const std::vector<Vec3f> points = RandomPoints(rng);
  std::vector<Frame> frames = MakeFrames(points, 3, 0.0, rng);
  // View 0 says landmark 5 is occluded and gives it a wild position: it must be ignored.
  frames[0].landmarks_2d_visible = std::vector<bool>(kNumLandmarks, true);
  (*frames[0].landmarks_2d_visible)[5] = false;
  (*frames[0].landmarks_2d)[5] = Vec2f(-500, 900);
  Result<TriangulatedLandmarks> tri = TriangulateLandmarks(frames);
  ASSERT_TRUE(tri.ok());
  EXPECT_EQ(tri->num_views[5], 2);
  EXPECT_LT((tri->points[5] - points[5]).norm(), 1e-4);
  // Invisible in two of three views: fewer than min_views.
  frames[1].landmarks_2d_visible = frames[0].landmarks_2d_visible;
  Result<TriangulatedLandmarks> bad = TriangulateLandmarks(frames);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("landmark 5"), std::string::npos) << bad.status().message();
}

TEST(LandmarkTriangulationTest, ReprojectionJacobianMatchesCentralDifferences) {
  Rng rng(5, StreamId("triangulation_test"));
  for (int trial = 0; trial < 5; ++trial) {
    const Camera cam = RandomCamera(rng);
    const PointObservation obs{&cam, Vec2d(rng.Uniform(0, 128), rng.Uniform(0, 96))};
    const Vec3d p(rng.Uniform(-0.5, 0.5), rng.Uniform(-0.5, 0.5), rng.Uniform(-0.5, 0.5));
    const auto r = ReprojectionResidualAt(obs, p);
    ASSERT_TRUE(r.has_value());
    const double h = 1e-6;
    for (int a = 0; a < 3; ++a) {
      Vec3d pp = p, pm = p;
      pp[a] += h;
      pm[a] -= h;
      const Vec2d fd =
          (ReprojectionResidualAt(obs, pp)->residual - ReprojectionResidualAt(obs, pm)->residual) / (2 * h);
      EXPECT_NEAR(r->jacobian(0, a), fd.x(), 1e-6 * (1 + std::abs(fd.x())));
      EXPECT_NEAR(r->jacobian(1, a), fd.y(), 1e-6 * (1 + std::abs(fd.y())));
    }
    // The residual is Camera::Project minus the observation.
    EXPECT_LT((r->residual - (cam.Project(p)->uv - obs.uv)).norm(), 1e-9);
  }
}

TEST(LandmarkTriangulationTest, DegenerateGeometryIsRejected) {
  Rng rng(8, StreamId("triangulation_test"));
  const Camera cam = RandomCamera(rng);
  // The same camera twice: both rays coincide, depth is unobservable.
  const std::vector<PointObservation> obs = {{&cam, Vec2d(60, 40)}, {&cam, Vec2d(60, 40)}};
  EXPECT_FALSE(TriangulateLinear(obs).has_value());
  EXPECT_FALSE(TriangulateLinear({{&cam, Vec2d(60, 40)}}).has_value());
  TriangulationOptions o;
  o.min_views = 1;
  EXPECT_FALSE(o.Validate().ok());
}

}  // namespace
}  // namespace icef
