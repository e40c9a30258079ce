#include "icef/track/photometric.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "icef/core/status.h"
#include "icef/face/expression.h"
#include "icef/math/ray.h"

namespace icef::track {

BlurredImage::BlurredImage(const Image& image, double sigma_px) : width_(image.width), height_(image.height) {
  ICEF_CHECK(image.channels == 3 || image.channels == 4,
             "BlurredImage: 3 or 4 channels, got " + std::to_string(image.channels));
  ICEF_CHECK(sigma_px >= 0, "BlurredImage: sigma_px must be >= 0");
  cv::Mat rgb(height_, width_, CV_32FC3);
  for (int y = 0; y < height_; ++y)
    for (int x = 0; x < width_; ++x)
      for (int c = 0; c < 3; ++c) rgb.ptr<float>(y)[3 * x + c] = image.At(x, y, c);
  if (sigma_px > 0) cv::GaussianBlur(rgb, rgb, cv::Size(0, 0), sigma_px, sigma_px, cv::BORDER_REPLICATE);
  rgb_.assign(size_t(width_) * height_ * 3, 0.f);
  for (int y = 0; y < height_; ++y)
    std::copy_n(rgb.ptr<float>(y), 3 * width_, rgb_.data() + size_t(y) * width_ * 3);
}

bool BlurredImage::Sample(double u, double v, Vec3d* rgb) const {
  const double x = u - 0.5, y = v - 0.5;  // pixel centres at integers
  if (!(x >= 0 && y >= 0 && x <= width_ - 1 && y <= height_ - 1)) return false;
  const int x0 = std::min(static_cast<int>(x), width_ - 2 < 0 ? 0 : width_ - 2);
  const int y0 = std::min(static_cast<int>(y), height_ - 2 < 0 ? 0 : height_ - 2);
  const int x1 = std::min(x0 + 1, width_ - 1), y1 = std::min(y0 + 1, height_ - 1);
  const double fx = x - x0, fy = y - y0;
  const auto at = [&](int xi, int yi, int c) { return double(rgb_[(size_t(yi) * width_ + xi) * 3 + c]); };
  for (int c = 0; c < 3; ++c)
    (*rgb)[c] = (1 - fy) * ((1 - fx) * at(x0, y0, c) + fx * at(x1, y0, c)) +
                fy * ((1 - fx) * at(x0, y1, c) + fx * at(x1, y1, c));
  return true;
}

std::string BlurredImage::ToString() const {
  std::ostringstream os;
  os << "BlurredImage(" << width_ << "x" << height_ << ")";
  return os.str();
}

namespace {

// Whether (x, y) lies inside the closed polygon (even-odd rule).
bool InsidePolygon(const std::vector<Vec2f>& polygon, float x, float y) {
  bool inside = false;
  for (size_t i = 0, j = polygon.size() - 1; i < polygon.size(); j = i++) {
    const Vec2f& a = polygon[i];
    const Vec2f& b = polygon[j];
    if ((a.y() > y) != (b.y() > y) && x < (b.x() - a.x()) * (y - a.y()) / (b.y() - a.y()) + a.x())
      inside = !inside;
  }
  return inside;
}

std::vector<Vec3f> SamplesAtSpacing(const face::FaceModel& model, const face::ExpressionState& neutral,
                                    float spacing) {
  const std::array<Vec3f, 68>& lm = model.NeutralLandmarks();
  // The face's outline seen from the front: the jaw line (0-16), then the brows back (26-17).
  std::vector<Vec2f> outline;
  for (int i = 0; i <= 16; ++i) outline.push_back(lm[i].head<2>());
  for (int i = 26; i >= 17; --i) outline.push_back(lm[i].head<2>());
  Vec2f lo = outline[0], hi = outline[0];
  for (const Vec2f& p : outline) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  // The eyes with a margin: an ellipse around each eye's six landmarks.
  std::array<Vec2f, 2> eye_c;
  std::array<float, 2> eye_rx{}, eye_ry{};
  for (int e = 0; e < 2; ++e) {
    Vec2f c = Vec2f::Zero();
    for (int i = 36 + 6 * e; i < 42 + 6 * e; ++i) c += lm[i].head<2>() / 6.f;
    eye_c[e] = c;
    const float half_width = 0.5f * (lm[39 + 6 * e].head<2>() - lm[36 + 6 * e].head<2>()).norm();
    eye_rx[e] = 1.5f * half_width;
    eye_ry[e] = 1.1f * half_width;
  }
  const Aabb box = model.Bounds();
  std::vector<Vec3f> out;
  for (float y = lo.y() + 0.5f * spacing; y < hi.y(); y += spacing) {
    for (float x = lo.x() + 0.5f * spacing; x < hi.x(); x += spacing) {
      if (!InsidePolygon(outline, x, y)) continue;
      bool near_eye = false;
      for (int e = 0; e < 2; ++e) {
        const float dx = (x - eye_c[e].x()) / eye_rx[e], dy = (y - eye_c[e].y()) / eye_ry[e];
        near_eye = near_eye || dx * dx + dy * dy < 1.f;
      }
      if (near_eye) continue;
      const Ray ray{Vec3f(x, y, box.max.z() + 0.1f), Vec3f(0, 0, -1)};
      const float t = model.Trace(ray, 0.f, box.max.z() - box.min.z() + 0.2f, neutral);
      if (t < 0) continue;
      const Vec3f p = ray.At(t);
      if (model.Evaluate(p, neutral).material != face::Material::kSkin) continue;
      if (model.Normal(p, neutral).z() < 0.3f) continue;  // grazing: its colour is the outline's
      out.push_back(p);
    }
  }
  return out;
}

}  // namespace

std::vector<Vec3f> CanonicalFaceSamples(const face::FaceModel& model, int count) {
  ICEF_CHECK(count > 0, "CanonicalFaceSamples: count must be > 0");
  const face::ExpressionState neutral = model.Prepare(std::vector<float>(face::kNumExpressions, 0.f));
  const std::array<Vec3f, 68>& lm = model.NeutralLandmarks();
  // First guess: the outline's box, then the spacing corrected by the count it gave.
  const float width = lm[16].x() - lm[0].x(), height = lm[19].y() - lm[8].y();
  float spacing = std::sqrt(width * height / count);
  std::vector<Vec3f> out = SamplesAtSpacing(model, neutral, spacing);
  if (!out.empty()) {
    spacing *= std::sqrt(static_cast<float>(out.size()) / count);
    out = SamplesAtSpacing(model, neutral, spacing);
  }
  return out;
}

}  // namespace icef::track
