#include "icef/train/visual_hull.h"

#include <gtest/gtest.h>

namespace icef {
namespace {

TEST(VisualHullTest, CarvesAroundADiscSilhouette) {
  // Three views of a sphere of radius 0.3 at the origin: the hull keeps the sphere's cells and
  // carves the corners of the box.
  Intrinsics k;
  k.width = k.height = 64;
  k.fl_x = k.fl_y = 80;
  k.cx = k.cy = 32;
  std::vector<Camera> cams = {Camera::LookAt(k, Vec3d(0, 0, 3), Vec3d::Zero()),
                              Camera::LookAt(k, Vec3d(3, 0, 0), Vec3d::Zero()),
                              Camera::LookAt(k, Vec3d(0, 2.9, 0.5), Vec3d::Zero(), Vec3d::UnitZ())};
  std::vector<Image> alphas;
  for (const Camera& cam : cams) {
    Image a(64, 64, 1, 0.f);
    for (int y = 0; y < 64; ++y)
      for (int x = 0; x < 64; ++x) {
        const Ray ray = cam.PixelRay(x, y);
        const Vec3f o = ray.origin;
        const float b = o.dot(ray.direction), c = o.squaredNorm() - 0.09f;
        a.At(x, y, 0) = (b * b - c) >= 0 ? 1.f : 0.f;
      }
    alphas.push_back(a);
  }
  const int r = 16;
  Aabb box;
  const auto allowed = VisualHullCells(box, r, cams, alphas, VisualHullOptions{}, Executor(2));
  int kept = 0;
  for (int z = 0; z < r; ++z)
    for (int y = 0; y < r; ++y)
      for (int x = 0; x < r; ++x) {
        const Vec3f centre =
            box.min + box.Extent().cwiseProduct(Vec3f(x + 0.5f, y + 0.5f, z + 0.5f)) / float(r);
        const uint8_t a = allowed[(size_t(z) * r + y) * r + x];
        kept += a;
        if (centre.norm() < 0.3f) EXPECT_EQ(a, 1) << "carved a cell inside the sphere";
      }
  EXPECT_EQ(allowed[0], 0);  // a corner of the box is outside every silhouette
  EXPECT_LT(kept, r * r * r / 4);
  // Requiring every view keeps the sphere (all three see it) and carves more of the rest.
  VisualHullOptions all;
  all.min_views = 3;
  const auto strict = VisualHullCells(box, r, cams, alphas, all, Executor(2));
  int kept_strict = 0;
  for (int64_t c = 0; c < int64_t(strict.size()); ++c) {
    kept_strict += strict[c];
    EXPECT_LE(strict[c], allowed[c]);
  }
  EXPECT_EQ(strict[(size_t(r / 2) * r + r / 2) * r + r / 2], 1);
  EXPECT_LE(kept_strict, kept);
  // Space no view sees is carved too.
  const auto none = VisualHullCells(box, r, {}, {}, VisualHullOptions{}, Executor(1));
  EXPECT_EQ(std::count(none.begin(), none.end(), 1), 0);
}

}  // namespace
}  // namespace icef
