#include "icef/track/head_mask.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <sstream>

namespace icef::track {

Status HeadMaskOptions::Validate() const {
  if (!(sure_inside >= 0 && sure_inside < 0.5)) return Status::Error("sure_inside must be in [0, 0.5)");
  if (!(band > 0 && band < 1)) return Status::Error("band must be in (0, 1)");
  if (iterations < 1) return Status::Error("iterations must be >= 1");
  return Status::Ok();
}

std::string HeadMaskOptions::ToString() const {
  std::ostringstream os;
  os << "HeadMaskOptions(sure_inside=" << sure_inside << ", band=" << band << ", iterations=" << iterations << ")";
  return os.str();
}

Image HeadSilhouette(const face::FaceModel& model, const std::vector<float>& expression, const Camera& camera,
                     const Executor& executor) {
  const face::ExpressionState state = model.Prepare(expression);
  Aabb box = model.Bounds();
  box.min -= Vec3f::Constant(0.05f);
  box.max += Vec3f::Constant(0.05f);
  Image out(camera.width(), camera.height(), 1);
  ParallelFor(executor, camera.height(), [&](int64_t begin, int64_t end, int) {
    for (int64_t y = begin; y < end; ++y)
      for (int x = 0; x < camera.width(); ++x) {
        const Ray ray = camera.PixelRay(x, static_cast<int>(y));
        const auto hit = box.Intersect(ray);
        if (hit && model.Trace(ray, hit->t_near, hit->t_far, state) >= 0) out.At(x, static_cast<int>(y), 0) = 1.f;
      }
  });
  return out;
}

Image HeadMask(const Image& image, const Image& silhouette, const Image& outside, const HeadMaskOptions& options) {
  const int w = image.width, h = image.height;
  cv::Mat rgb(h, w, CV_8UC3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c)
        rgb.at<cv::Vec3b>(y, x)[c] = static_cast<uint8_t>(std::lround(std::clamp(image.Rgb(x, y)[c], 0.f, 1.f) * 255));
  cv::Mat inside(h, w, CV_8U), not_inside(h, w, CV_8U);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      inside.at<uint8_t>(y, x) = silhouette.At(x, y, 0) > 0.5f ? 255 : 0;
      not_inside.at<uint8_t>(y, x) = 255 - inside.at<uint8_t>(y, x);
    }
  cv::Mat depth_in, dist_out;
  cv::distanceTransform(inside, depth_in, cv::DIST_L2, 5);
  cv::distanceTransform(not_inside, dist_out, cv::DIST_L2, 5);
  cv::Mat mask(h, w, CV_8U);
  int fg = 0, bg = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      uint8_t label;
      if (!outside.empty() && outside.At(x, y, 0) > 0.5f) {
        label = cv::GC_BGD;
      } else if (inside.at<uint8_t>(y, x)) {
        label = depth_in.at<float>(y, x) > options.sure_inside * w ? cv::GC_FGD : cv::GC_PR_FGD;
      } else {
        label = dist_out.at<float>(y, x) < options.band * w ? cv::GC_PR_BGD : cv::GC_BGD;
      }
      fg += label == cv::GC_FGD || label == cv::GC_PR_FGD;
      bg += label == cv::GC_BGD || label == cv::GC_PR_BGD;
      mask.at<uint8_t>(y, x) = label;
    }
  Image out(w, h, 1);
  if (fg == 0) return out;                  // nothing of the head in view
  if (bg > 0) {                             // GrabCut needs both sides
    cv::theRNG().state = 0x1cef;            // its k-means starts from OpenCV's thread RNG: pin it
    cv::Mat bgd_model, fgd_model;
    cv::grabCut(rgb, mask, cv::Rect(), bgd_model, fgd_model, options.iterations, cv::GC_INIT_WITH_MASK);
  }
  cv::Mat fore = (mask == cv::GC_FGD) | (mask == cv::GC_PR_FGD);
  // The largest component, then its holes filled (flood the background from the border).
  cv::Mat labels, stats, centroids;
  const int n = cv::connectedComponentsWithStats(fore, labels, stats, centroids, 8);
  int best = 0;
  for (int i = 1; i < n; ++i)
    if (best == 0 || stats.at<int>(i, cv::CC_STAT_AREA) > stats.at<int>(best, cv::CC_STAT_AREA)) best = i;
  cv::Mat keep = labels == best;
  if (best == 0) keep.setTo(0);
  cv::Mat padded;
  cv::copyMakeBorder(keep, padded, 1, 1, 1, 1, cv::BORDER_CONSTANT, 0);
  cv::floodFill(padded, cv::Point(0, 0), 128);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) out.At(x, y, 0) = padded.at<uint8_t>(y + 1, x + 1) != 128 ? 1.f : 0.f;
  return out;
}

std::vector<Vec2f> MaskEdgePoints(const Image& mask, const Image& outside, int max_points) {
  const int w = mask.width, h = mask.height;
  const auto in = [&](int x, int y) { return mask.At(x, y, 0) > 0.5f; };
  const auto off_photo = [&](int x, int y) { return !outside.empty() && outside.At(x, y, 0) > 0.5f; };
  std::vector<Vec2f> all;
  for (int y = 1; y + 1 < h; ++y)
    for (int x = 1; x + 1 < w; ++x) {
      if (!in(x, y) || off_photo(x, y)) continue;
      constexpr int kDx[4] = {1, -1, 0, 0}, kDy[4] = {0, 0, 1, -1};
      for (int k = 0; k < 4; ++k) {
        const int nx = x + kDx[k], ny = y + kDy[k];
        if (in(nx, ny) || off_photo(nx, ny) || nx == 0 || ny == 0 || nx + 1 == w || ny + 1 == h) continue;
        all.emplace_back(x + 0.5f + 0.5f * kDx[k], y + 0.5f + 0.5f * kDy[k]);
      }
    }
  if (max_points <= 0 || static_cast<int>(all.size()) <= max_points) return all;
  std::vector<Vec2f> out;
  for (int i = 0; i < max_points; ++i) out.push_back(all[size_t(i) * all.size() / max_points]);
  return out;
}

double MaskIou(const Image& a, const Image& b) {
  int64_t inter = 0, uni = 0;
  for (int y = 0; y < std::min(a.height, b.height); ++y)
    for (int x = 0; x < std::min(a.width, b.width); ++x) {
      const bool p = a.At(x, y, a.channels - 1) > 0.5f, q = b.At(x, y, b.channels - 1) > 0.5f;
      inter += p && q;
      uni += p || q;
    }
  return uni == 0 ? 1.0 : double(inter) / double(uni);
}

}  // namespace icef::track
