#include "icef/train/visual_hull.h"

#include <algorithm>
#include <cmath>

namespace icef {

namespace {
// Summed-area table of the foreground indicator, (w + 1) x (h + 1).
struct ForegroundTable {
  int w = 0, h = 0;
  std::vector<int32_t> sum;
  ForegroundTable(const Image& alpha, float threshold)
      : w(alpha.width), h(alpha.height), sum(size_t(w + 1) * (h + 1), 0) {
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        sum[size_t(y + 1) * (w + 1) + x + 1] =
            (alpha.At(x, y, 0) >= threshold ? 1 : 0) + sum[size_t(y) * (w + 1) + x + 1] +
            sum[size_t(y + 1) * (w + 1) + x] - sum[size_t(y) * (w + 1) + x];
  }
  // Foreground pixels in columns [x0, x1), rows [y0, y1).
  int32_t Count(int x0, int y0, int x1, int y1) const {
    return sum[size_t(y1) * (w + 1) + x1] - sum[size_t(y0) * (w + 1) + x1] - sum[size_t(y1) * (w + 1) + x0] +
           sum[size_t(y0) * (w + 1) + x0];
  }
};
}  // namespace

std::vector<uint8_t> VisualHullCells(const Aabb& aabb, int resolution, const std::vector<Camera>& cameras,
                                     const std::vector<Image>& alphas, const VisualHullOptions& options,
                                     const Executor& executor) {
  ICEF_CHECK(cameras.size() == alphas.size(), "one alpha image per camera");
  std::vector<ForegroundTable> tables;
  for (const Image& a : alphas) tables.emplace_back(a, options.alpha_threshold);
  const int r = resolution;
  const Vec3d cell = (aabb.Extent() / float(r)).cast<double>();
  const double radius = 0.5 * cell.norm();
  std::vector<uint8_t> allowed(size_t(r) * r * r, 1);
  ParallelFor(executor, int64_t(r) * r * r, [&](int64_t begin, int64_t end, int) {
    for (int64_t c = begin; c < end; ++c) {
      const int x = int(c % r), y = int((c / r) % r), z = int(c / (int64_t(r) * r));
      const Vec3d centre = aabb.min.cast<double>() + cell.cwiseProduct(Vec3d(x + 0.5, y + 0.5, z + 0.5));
      int seen_by = 0;
      for (size_t k = 0; k < cameras.size() && allowed[c]; ++k) {
        const Camera& cam = cameras[k];
        const auto proj = cam.Project(centre);
        if (!proj || proj->depth <= radius) continue;
        // Focal lengths are signed (a mirrored camera has fl_x < 0, math/camera.h).
        const double fl = std::max(std::abs(cam.intrinsics().fl_x), std::abs(cam.intrinsics().fl_y));
        const double rad = fl * radius / (proj->depth - radius) + options.margin_px;
        const double u = proj->uv.x(), v = proj->uv.y();
        if (u < 0 || v < 0 || u > cam.width() || v > cam.height()) continue;  // centre not seen
        ++seen_by;
        const ForegroundTable& t = tables[k];
        const int x0 = std::max(0, int(std::floor(u - rad))), y0 = std::max(0, int(std::floor(v - rad)));
        const int x1 = std::min(t.w, int(std::ceil(u + rad))), y1 = std::min(t.h, int(std::ceil(v + rad)));
        if (t.Count(x0, y0, x1, y1) == 0) allowed[c] = 0;
      }
      if (seen_by < options.min_views) allowed[c] = 0;
    }
  });
  return allowed;
}

}  // namespace icef
