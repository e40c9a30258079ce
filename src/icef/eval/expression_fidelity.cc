#include "icef/eval/expression_fidelity.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "icef/eval/metrics.h"

namespace icef::eval {

namespace {

double Cross(const Vec2d& o, const Vec2d& a, const Vec2d& b) {
  return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
}

// Convex hull, counter-clockwise (Andrew's monotone chain); degenerate inputs give fewer points.
std::vector<Vec2d> ConvexHull(std::vector<Vec2d> p) {
  std::sort(p.begin(), p.end(), [](const Vec2d& a, const Vec2d& b) {
    return a.x() != b.x() ? a.x() < b.x() : a.y() < b.y();
  });
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
    for (size_t i = 0; i < hull.size() && inside; ++i) inside = Cross(hull[i], hull[(i + 1) % hull.size()], p) >= 0;
    if (inside) return true;
  }
  double d = (p - hull[0]).norm();
  for (size_t i = 0; i < hull.size(); ++i) d = std::min(d, SegmentDistance(p, hull[i], hull[(i + 1) % hull.size()]));
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

int DefaultRegionDilation(int width) { return std::max(1, static_cast<int>(std::lround(3.0 * width / 128.0))); }

double DefaultCoarseSigma(int width) { return 2.0 * width / 128.0; }

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

Image FaceRegion(int width, int height, const std::vector<Vec2f>& landmarks) {
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

Result<ExpressionFidelity> MeasureExpression(const Image& render, const Image& render_neutral, const Image& truth,
                                             const Image& truth_neutral, const Image& region, double coarse_sigma) {
  for (const Image* image : {&render, &render_neutral, &truth, &truth_neutral}) {
    if (image->width != region.width || image->height != region.height || image->channels < 3)
      return Status::Error("expression fidelity: images must be RGB(A) of the region's size " +
                           std::to_string(region.width) + "x" + std::to_string(region.height) + ", got " +
                           image->ToString());
  }
  ExpressionFidelity f;
  double mt = 0, mm = 0, tt = 0;
  for (int y = 0; y < region.height; ++y)
    for (int x = 0; x < region.width; ++x) {
      if (region.At(x, y, 0) <= 0.5f) continue;
      ++f.pixels;
      for (int c = 0; c < 3; ++c) {
        const double m = double(render.At(x, y, c)) - render_neutral.At(x, y, c);
        const double t = double(truth.At(x, y, c)) - truth_neutral.At(x, y, c);
        mt += m * t, mm += m * m, tt += t * t;
      }
    }
  if (f.pixels == 0) return f;
  f.true_rms = std::sqrt(tt / (3.0 * f.pixels));
  f.negligible = f.true_rms < kNegligibleExpressionRms;
  if (f.negligible) return f;
  f.gain = mt / tt;
  if (mm > 0) f.corr = mt / std::sqrt(mm * tt);
  if (coarse_sigma > 0) {
    const int w = region.width, h = region.height;
    double cmt = 0, ctt = 0;
    std::vector<double> m(size_t(w) * h), t(size_t(w) * h);
    for (int c = 0; c < 3; ++c) {
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
          m[size_t(y) * w + x] = double(render.At(x, y, c)) - render_neutral.At(x, y, c);
          t[size_t(y) * w + x] = double(truth.At(x, y, c)) - truth_neutral.At(x, y, c);
        }
      const std::vector<double> ms = GaussianFilter(m, w, h, coarse_sigma), ts = GaussianFilter(t, w, h, coarse_sigma);
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
          if (region.At(x, y, 0) <= 0.5f) continue;
          const size_t i = size_t(y) * w + x;
          cmt += ms[i] * ts[i], ctt += ts[i] * ts[i];
        }
    }
    if (ctt > 0) f.gain_coarse = cmt / ctt;
  }
  return f;
}

}  // namespace icef::eval
