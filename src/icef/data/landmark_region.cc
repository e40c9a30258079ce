#include "icef/data/landmark_region.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace icef {

namespace {

double Cross(const Vec2d& o, const Vec2d& a, const Vec2d& b) {
  return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
}

// Convex hull, counter-clockwise (Andrew's monotone chain); degenerate inputs give fewer points.
std::vector<Vec2d> ConvexHull(std::vector<Vec2d> p) {
  std::sort(p.begin(), p.end(),
            [](const Vec2d& a, const Vec2d& b) { return a.x() != b.x() ? a.x() < b.x() : a.y() < b.y(); });
  p.erase(std::unique(p.begin(), p.end()), p.end());
  if (p.size() < 3) return p;
  std::vector<Vec2d> h(2 * p.size());
  size_t k = 0;
  for (size_t i = 0; i < p.size(); ++i) {
    while (k >= 2 && Cross(h[k - 2], h[k - 1], p[i]) <= 0) --k;
    h[k++] = p[i];
  }
  for (size_t i = p.size() - 1, t = k + 1; i-- > 0;) {
    while (k >= t && Cross(h[k - 2], h[k - 1], p[i]) <= 0) --k;
    h[k++] = p[i];
  }
  h.resize(k - 1);
  return h;
}

double SegmentDistance(const Vec2d& p, const Vec2d& a, const Vec2d& b) {
  const Vec2d ab = b - a;
  const double len2 = ab.squaredNorm();
  const double s = len2 > 0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (p - (a + s * ab)).norm();
}

// Inside the hull (counter-clockwise), or within `dilation` of its boundary.
bool InDilatedHull(const std::vector<Vec2d>& hull, const Vec2d& p, double dilation) {
  if (hull.empty()) return false;
  if (hull.size() >= 3) {
    bool inside = true;
    for (size_t i = 0; i < hull.size() && inside; ++i)
      inside = Cross(hull[i], hull[(i + 1) % hull.size()], p) >= 0;
    if (inside) return true;
  }
  double d = (p - hull[0]).norm();
  for (size_t i = 0; i < hull.size(); ++i)
    d = std::min(d, SegmentDistance(p, hull[i], hull[(i + 1) % hull.size()]));
  return d <= dilation;
}

std::vector<Vec2d> RegionHull(const std::vector<Vec2f>& landmarks) {
  std::vector<Vec2d> points;
  if (landmarks.empty()) return points;
  for (int i : ExpressionLandmarkIndices()) {
    if (i >= static_cast<int>(landmarks.size())) continue;
    const Vec2f& l = landmarks[i];
    if (std::isfinite(l.x()) && std::isfinite(l.y())) points.emplace_back(l.x(), l.y());
  }
  return ConvexHull(std::move(points));
}

}  // namespace

const std::vector<int>& ExpressionLandmarkIndices() {
  static const std::vector<int> kIndices = [] {
    std::vector<int> v;
    for (int i = 17; i <= 26; ++i) v.push_back(i);  // brows
    for (int i = 36; i <= 67; ++i) v.push_back(i);  // eyes, mouth
    return v;
  }();
  return kIndices;
}

int DefaultRegionDilation(int width) {
  return std::max(1, static_cast<int>(std::lround(3.0 * width / 128.0)));
}

Image ExpressionRegion(int width, int height, const std::vector<Vec2f>& frame_landmarks,
                       const std::vector<Vec2f>& neutral_landmarks, int dilation) {
  Image region(width, height, 1, 0.f);
  const std::vector<Vec2d> a = RegionHull(frame_landmarks);
  const std::vector<Vec2d> b = RegionHull(neutral_landmarks);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const Vec2d p(x + 0.5, y + 0.5);
      if (InDilatedHull(a, p, dilation) || InDilatedHull(b, p, dilation)) region.At(x, y, 0) = 1.f;
    }
  return region;
}

Image LandmarkHullRegion(int width, int height, const std::vector<Vec2f>& landmarks) {
  Image region(width, height, 1, 0.f);
  std::vector<Vec2d> points;
  for (const Vec2f& l : landmarks)
    if (std::isfinite(l.x()) && std::isfinite(l.y())) points.emplace_back(l.x(), l.y());
  const std::vector<Vec2d> hull = ConvexHull(std::move(points));
  if (hull.size() < 3) return region;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      if (InDilatedHull(hull, Vec2d(x + 0.5, y + 0.5), 0.0)) region.At(x, y, 0) = 1.f;
  return region;
}

}  // namespace icef
