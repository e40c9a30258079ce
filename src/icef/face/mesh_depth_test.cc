#include "icef/face/mesh_depth.h"

#include <gtest/gtest.h>

#include <cmath>

namespace icef::face {
namespace {

Camera FrontCamera() {
  Intrinsics k;
  k.width = k.height = 32;
  k.fl_x = k.fl_y = 40;
  k.cx = k.cy = 16;
  return Camera::LookAt(k, Vec3d(0.1, 0.05, 3), Vec3d(0.1, 0.05, 0));
}

// A square in the plane z = z0 (two triangles) and, in front of its left half, a smaller one at z1.
TEST(MeshDepth, EachPixelGetsItsRaysFirstHit) {
  const std::vector<Vec3f> v = {{-1, -1, 0},       {1, -1, 0},    {1, 1, 0},    {-1, 1, 0},         // z = 0
                                {-0.5f, -0.5f, 1}, {0, -0.5f, 1}, {0, 0.5f, 1}, {-0.5f, 0.5f, 1}};  // z = 1
  const std::vector<std::array<uint32_t, 3>> t = {{0, 1, 2}, {0, 2, 3}, {4, 5, 6}, {4, 6, 7}};
  const Camera camera = FrontCamera();
  std::vector<int32_t> hit;
  const std::vector<float> depth = MeshDepthImage(v, t, camera, &hit);
  ASSERT_EQ(depth.size(), 32u * 32u);
  ASSERT_EQ(hit.size(), depth.size());
  int near = 0, far = 0, miss = 0;
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 32; ++x) {
      const Ray ray = camera.PixelRay(x, y);
      const float d = depth[size_t(y) * 32 + x];
      // Where the ray crosses each plane, and whether that point lies on the square there.
      const double t1 = (1.0 - ray.origin.z()) / ray.direction.z(), t0 = -ray.origin.z() / ray.direction.z();
      const Vec3f p1 = ray.At(float(t1)), p0 = ray.At(float(t0));
      const bool on1 = p1.x() > -0.5f && p1.x() < 0.f && std::abs(p1.y()) < 0.5f;
      const bool on0 = std::abs(p0.x()) < 1.f && std::abs(p0.y()) < 1.f;
      if (on1) {
        EXPECT_NEAR(d, t1, 1e-4) << x << "," << y;
        EXPECT_GE(hit[size_t(y) * 32 + x], 2) << x << "," << y;  // the near square's triangles
        ++near;
      } else if (on0) {
        EXPECT_NEAR(d, t0, 1e-4) << x << "," << y;
        EXPECT_LE(hit[size_t(y) * 32 + x], 1) << x << "," << y;
        ++far;
      } else {
        // Off both (or on an edge, within rounding): no hit, or one exactly on the edge's plane.
        EXPECT_TRUE(std::isinf(d) || std::abs(d - t0) < 1e-4 || std::abs(d - t1) < 1e-4) << x << "," << y;
        miss += std::isinf(d);
      }
    }
  EXPECT_GT(near, 20);
  EXPECT_GT(far, 100);
  EXPECT_GT(miss, 100);
  // A triangle behind the camera is not seen.
  const std::vector<Vec3f> behind = {{-1, -1, 5}, {1, -1, 5}, {0, 1, 5}};
  for (const float d : MeshDepthImage(behind, std::vector<std::array<uint32_t, 3>>{{0, 1, 2}}, camera))
    EXPECT_TRUE(std::isinf(d));
}

}  // namespace
}  // namespace icef::face
