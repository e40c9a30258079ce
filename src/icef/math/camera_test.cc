#include "icef/math/camera.h"

#include <gtest/gtest.h>

#include <cmath>

#include "icef/core/rng.h"

namespace icef {
namespace {

Intrinsics TestIntrinsics() {
  Intrinsics k;
  k.width = 128;
  k.height = 96;
  k.fl_x = 160;
  k.fl_y = 150;
  k.cx = 64;
  k.cy = 48;
  return k;
}

TEST(CameraTest, HandComputedConventions) {
  // Identity pose: camera at the origin looking down -Z, +Y up, +X right.
  Camera cam(TestIntrinsics(), Mat4d::Identity());
  // The principal point looks straight down -Z.
  Ray r = cam.RayThrough(64, 48);
  EXPECT_NEAR(r.direction.z(), -1.f, 1e-6);
  // Pixel (0, 0)'s centre is (0.5, 0.5): up (+Y) and left (-X) of the principal point.
  Ray tl = cam.PixelRay(0, 0);
  EXPECT_LT(tl.direction.x(), 0.f);
  EXPECT_GT(tl.direction.y(), 0.f);
  const Vec3d expected = Vec3d((0.5 - 64) / 160, -(0.5 - 48) / 150, -1).normalized();
  EXPECT_NEAR((tl.direction.cast<double>() - expected).norm(), 0.0, 1e-6);
  // A point 2 units in front, 0.5 right and 0.25 up lands at u = 64 + 160*0.25, v = 48 - 150*0.125.
  auto p = cam.Project(Vec3d(0.5, 0.25, -2.0));
  ASSERT_TRUE(p.has_value());
  EXPECT_NEAR(p->uv.x(), 104.0, 1e-9);
  EXPECT_NEAR(p->uv.y(), 29.25, 1e-9);
  EXPECT_NEAR(p->depth, 2.0, 1e-12);
  // Points behind the camera do not project.
  EXPECT_FALSE(cam.Project(Vec3d(0, 0, 1)).has_value());
}

TEST(CameraTest, LookAtMatchesConvention) {
  // A camera at +Z looking at the origin is the identity rotation shifted by 3 along Z.
  Camera cam = Camera::LookAt(TestIntrinsics(), Vec3d(0, 0, 3), Vec3d::Zero());
  EXPECT_NEAR((cam.world_from_cam().block<3, 3>(0, 0) - Mat3d::Identity()).norm(), 0.0, 1e-12);
  auto p = cam.Project(Vec3d::Zero());
  ASSERT_TRUE(p);
  EXPECT_NEAR(p->uv.x(), 64, 1e-9);
  EXPECT_NEAR(p->uv.y(), 48, 1e-9);
  EXPECT_NEAR(p->depth, 3, 1e-12);
  EXPECT_TRUE(ValidateRigid(cam.world_from_cam()).ok());
}

TEST(CameraTest, ProjectThenUnprojectPassesThroughPoint) {
  Rng rng(7, StreamId("camera_test"));
  for (int trial = 0; trial < 200; ++trial) {
    const Vec3d eye(rng.Uniform(-3, 3), rng.Uniform(-3, 3), rng.Uniform(2, 4));
    const Vec3d target(rng.Uniform(-.3, .3), rng.Uniform(-.3, .3), rng.Uniform(-.3, .3));
    Camera cam = Camera::LookAt(TestIntrinsics(), eye, target);
    const Vec3d point = target + Vec3d(rng.Uniform(-.5, .5), rng.Uniform(-.5, .5), rng.Uniform(-.5, .5));
    auto proj = cam.Project(point);
    ASSERT_TRUE(proj);
    Ray ray = cam.RayThrough(proj->uv.x(), proj->uv.y());
    const Vec3d o = ray.origin.cast<double>(), d = ray.direction.cast<double>();
    const double t = (point - o).dot(d);
    EXPECT_NEAR((o + t * d - point).norm(), 0.0, 1e-5) << cam.ToString();
  }
}

TEST(CameraTest, CameraAngleAndRigidity) {
  Intrinsics k = Intrinsics::FromCameraAngle(200, 100, 2 * std::atan(0.5));
  EXPECT_NEAR(k.fl_x, 200.0, 1e-9);
  EXPECT_NEAR(k.fl_y, 200.0, 1e-9);
  EXPECT_NEAR(k.cx, 100.0, 1e-12);
  EXPECT_NEAR(k.cy, 50.0, 1e-12);
  EXPECT_TRUE(k.Validate().ok());
  k.fl_x = -1;  // signed: a negative focal length flips that image axis
  EXPECT_TRUE(k.Validate().ok());
  k.fl_x = 0;
  EXPECT_FALSE(k.Validate().ok());
  k.fl_x = 1;
  k.fl_y = INFINITY;
  EXPECT_FALSE(k.Validate().ok());
  Mat4d scaled = Mat4d::Identity();
  scaled(0, 0) = 2;
  EXPECT_FALSE(ValidateRigid(scaled).ok());
  Mat4d reflect = Mat4d::Identity();
  reflect(0, 0) = -1;
  EXPECT_FALSE(ValidateRigid(reflect).ok());
  Mat4d nan = Mat4d::Identity();
  nan(1, 3) = NAN;
  EXPECT_FALSE(ValidateRigid(nan).ok());
}

TEST(CameraTest, SignedFocalLengthsFlipImageAxes) {
  // Direction through (u, v) = ((u - cx) / fl_x, -(v - cy) / fl_y, -1) whatever the signs (NerFace).
  Rng rng(11, StreamId("camera_test/signed"));
  for (const auto& [sx, sy] : {std::pair{1, 1}, std::pair{-1, -1}, std::pair{-1, 1}, std::pair{1, -1}}) {
    Intrinsics k = TestIntrinsics();
    k.fl_x *= sx;
    k.fl_y *= sy;
    const Vec3d eye(rng.Uniform(-3, 3), rng.Uniform(-3, 3), rng.Uniform(2, 4));
    const Camera given(k, Camera::LookAt(k, eye, Vec3d::Zero()).world_from_cam());
    const Camera upright = Camera::Upright(k, given.world_from_cam());
    EXPECT_TRUE(ValidateRigid(upright.world_from_cam()).ok());
    EXPECT_GT(upright.intrinsics().fl_y, 0);
    EXPECT_EQ(upright.intrinsics().fl_x < 0, sx != sy);  // only a mirrored camera keeps a negative focal
    EXPECT_EQ(upright.intrinsics().cx, k.cx);
    EXPECT_EQ(upright.intrinsics().cy, k.cy);
    const Mat3d r = given.world_from_cam().block<3, 3>(0, 0);
    for (int trial = 0; trial < 20; ++trial) {
      const double u = rng.Uniform(0, k.width), v = rng.Uniform(0, k.height);
      const Vec3d expected = (r * Vec3d((u - k.cx) / k.fl_x, -(v - k.cy) / k.fl_y, -1)).normalized();
      for (const Camera* cam : {&given, &upright}) {
        const Ray ray = cam->RayThrough(u, v);
        EXPECT_LT((ray.direction.cast<double>() - expected).norm(), 1e-6) << cam->ToString();
        EXPECT_EQ(ray.direction, given.RayThrough(u, v).direction);  // Upright: bit for bit
        const auto p = cam->Project(eye + 2.0 * expected);
        ASSERT_TRUE(p.has_value());
        EXPECT_NEAR(p->uv.x(), u, 1e-9);
        EXPECT_NEAR(p->uv.y(), v, 1e-9);
        EXPECT_NEAR(p->depth,
                    2.0 / std::sqrt(1 + std::pow((u - k.cx) / k.fl_x, 2) + std::pow((v - k.cy) / k.fl_y, 2)),
                    1e-9);
      }
    }
  }
  // A negative fl_x really mirrors: the pixel left of the principal point looks to camera +X.
  Intrinsics mirrored = TestIntrinsics();
  mirrored.fl_x = -mirrored.fl_x;
  EXPECT_GT(Camera(mirrored, Mat4d::Identity()).PixelRay(0, 48).direction.x(), 0.f);
  // An upright camera's pose is left as it is, and Upright writes no -0 into the pose.
  const Camera same = Camera::Upright(TestIntrinsics(), Mat4d::Identity());
  EXPECT_EQ(same.world_from_cam(), Mat4d::Identity());
  Intrinsics both = TestIntrinsics();
  both.fl_x = -both.fl_x;
  both.fl_y = -both.fl_y;
  const Mat4d turned = Camera::Upright(both, Mat4d::Identity()).world_from_cam();
  EXPECT_EQ(turned, Vec4d(-1, -1, 1, 1).asDiagonal().toDenseMatrix());
  EXPECT_FALSE(std::signbit(turned(1, 0)));
}

TEST(AabbTest, IntersectsRays) {
  Aabb box;
  auto hit = box.Intersect(Ray{Vec3f(0, 0, 5), Vec3f(0, 0, -1)});
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->t_near, 4.f, 1e-6);
  EXPECT_NEAR(hit->t_far, 6.f, 1e-6);
  EXPECT_FALSE(box.Intersect(Ray{Vec3f(0, 2, 5), Vec3f(0, 0, -1)}));
  auto inside = box.Intersect(Ray{Vec3f(0, 0, 0), Vec3f(1, 0, 0)});
  ASSERT_TRUE(inside);
  EXPECT_EQ(inside->t_near, 0.f);
  EXPECT_NEAR(inside->t_far, 1.f, 1e-6);
  Aabb off{Vec3f(1, 2, 3), Vec3f(2, 4, 6)};
  EXPECT_TRUE(off.Contains(off.Center()));
  EXPECT_NEAR((off.Normalize(off.max) - Vec3f::Ones()).norm(), 0.f, 1e-6);
}

}  // namespace
}  // namespace icef
