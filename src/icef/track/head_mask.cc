#include "icef/track/head_mask.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <sstream>

namespace icef::track {

namespace {
Image LargestFilledComponent(const cv::Mat& fore);
}  // namespace

Status HeadMaskOptions::Validate() const {
  if (!(sure_inside >= 0 && sure_inside < 0.5)) return Status::Error("sure_inside must be in [0, 0.5)");
  if (!(band > 0 && band < 1)) return Status::Error("band must be in (0, 1)");
  if (iterations < 1) return Status::Error("iterations must be >= 1");
  if (!(person_background >= 0 && person_background < 1))
    return Status::Error("person_background must be in [0, 1)");
  if (!(person_foreground > person_background && person_foreground <= 1))
    return Status::Error("person_foreground must be in (person_background, 1]");
  return Status::Ok();
}

std::string HeadMaskOptions::ToString() const {
  std::ostringstream os;
  os << "HeadMaskOptions(sure_inside=" << sure_inside << ", band=" << band << ", iterations=" << iterations
     << ", person_background=" << person_background << ", person_foreground=" << person_foreground << ")";
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
        if (hit && model.Trace(ray, hit->t_near, hit->t_far, state) >= 0)
          out.At(x, static_cast<int>(y), 0) = 1.f;
      }
  });
  return out;
}

Image HeadMask(const Image& image, const Image& silhouette, const Image& outside, const Image& person,
               const HeadMaskOptions& options) {
  const int w = image.width, h = image.height;
  cv::Mat rgb(h, w, CV_8UC3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c)
        rgb.at<cv::Vec3b>(y, x)[c] =
            static_cast<uint8_t>(std::lround(std::clamp(image.Rgb(x, y)[c], 0.f, 1.f) * 255));
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
      } else if (inside.at<uint8_t>(y, x) && depth_in.at<float>(y, x) > options.sure_inside * w) {
        label = cv::GC_FGD;
      } else if (!person.empty() && person.At(x, y, 0) < options.person_background) {
        label = cv::GC_BGD;
      } else if (inside.at<uint8_t>(y, x)) {
        label = cv::GC_PR_FGD;
      } else if (dist_out.at<float>(y, x) < options.band * w) {
        // Near the head: hair where the person segmentation sees the person (hair as dark as the
        // background behind it is otherwise cut off flat along the skull), else probably background.
        label =
            !person.empty() && person.At(x, y, 0) > options.person_foreground ? cv::GC_PR_FGD : cv::GC_PR_BGD;
      } else {
        label = cv::GC_BGD;
      }
      fg += label == cv::GC_FGD || label == cv::GC_PR_FGD;
      bg += label == cv::GC_BGD || label == cv::GC_PR_BGD;
      mask.at<uint8_t>(y, x) = label;
    }
  Image out(w, h, 1);
  if (fg == 0) return out;        // nothing of the head in view
  if (bg > 0) {                   // GrabCut needs both sides
    cv::theRNG().state = 0x1cef;  // its k-means starts from OpenCV's thread RNG: pin it
    cv::Mat bgd_model, fgd_model;
    cv::grabCut(rgb, mask, cv::Rect(), bgd_model, fgd_model, options.iterations, cv::GC_INIT_WITH_MASK);
  }
  return LargestFilledComponent((mask == cv::GC_FGD) | (mask == cv::GC_PR_FGD));
}

namespace {

// The largest 8-connected component of `fore` (CV_8U, non-zero inside), its holes filled (the
// background flooded from the border), as a 1-channel image of 0 and 1.
Image LargestFilledComponent(const cv::Mat& fore) {
  const int w = fore.cols, h = fore.rows;
  Image out(w, h, 1);
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

}  // namespace

Image PersonMask(const Image& person, const Image& outside, double threshold) {
  const int w = person.width, h = person.height;
  cv::Mat fore(h, w, CV_8U);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      fore.at<uint8_t>(y, x) =
          person.At(x, y, 0) > threshold && (outside.empty() || outside.At(x, y, 0) <= 0.5f) ? 255 : 0;
  return LargestFilledComponent(fore);
}

Image BackgroundDifferenceMask(const Image& frame, const Image& background, double threshold) {
  ICEF_CHECK(frame.width == background.width && frame.height == background.height,
             "BackgroundDifferenceMask: the frame and the background differ in size");
  const int w = frame.width, h = frame.height;
  cv::Mat fore(h, w, CV_8U);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      fore.at<uint8_t>(y, x) =
          (frame.Rgb(x, y) - background.Rgb(x, y)).cwiseAbs().maxCoeff() > threshold ? 255 : 0;
  // Lone pixels of sensor noise and compression out, thin gaps closed.
  const cv::Mat kernel = cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(3, 3));
  cv::morphologyEx(fore, fore, cv::MORPH_OPEN, kernel);
  cv::morphologyEx(fore, fore, cv::MORPH_CLOSE, kernel);
  return LargestFilledComponent(fore);
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

namespace {

Vec3d SkinFeature(const Vec3f& rgb) {
  const Vec3d c = rgb.cast<double>().cwiseMax(0.0) + Vec3d::Constant(1e-3);
  const double sum = c.sum();
  return Vec3d(c.x() / sum, c.y() / sum, std::log(sum));
}

}  // namespace

double SkinModel::Distance(const Vec3f& rgb) const {
  const Vec3d d = SkinFeature(rgb) - mean;
  return std::sqrt(std::max(0.0, d.dot(inverse_covariance * d)));
}

SkinModel FitSkinModel(const Image& image, const std::vector<Vec2f>& lm) {
  SkinModel skin;
  if (lm.size() < 68 || image.channels < 3) return skin;
  const float iod = ((lm[36] + lm[39]) * 0.5f - (lm[42] + lm[45]) * 0.5f).norm();
  const Vec2f centres[] = {0.5f * (lm[2] + lm[30]), 0.5f * (lm[14] + lm[30]), 0.5f * (lm[4] + lm[48]),
                           0.5f * (lm[12] + lm[54]), lm[29]};
  const int r = std::max(1, static_cast<int>(0.12f * iod));
  std::vector<Vec3d> samples;
  for (const Vec2f& c : centres) {
    if (!c.allFinite()) continue;
    for (int dy = -r; dy <= r; ++dy)
      for (int dx = -r; dx <= r; ++dx) {
        const int x = static_cast<int>(c.x()) + dx, y = static_cast<int>(c.y()) + dy;
        if (dx * dx + dy * dy > r * r || x < 0 || y < 0 || x >= image.width || y >= image.height) continue;
        samples.push_back(SkinFeature(image.Rgb(x, y)));
      }
  }
  if (samples.size() < 8) return skin;
  for (const Vec3d& s : samples) skin.mean += s;
  skin.mean /= static_cast<double>(samples.size());
  Mat3d cov = Mat3d::Zero();
  for (const Vec3d& s : samples) cov += (s - skin.mean) * (s - skin.mean).transpose();
  cov /= static_cast<double>(samples.size() - 1);
  // A floor under the spread: lighting and shading vary more across a face than across five patches.
  cov += Vec3d(1e-4, 1e-4, 1e-2).asDiagonal();
  skin.inverse_covariance = cov.inverse();
  skin.valid = true;
  return skin;
}

std::vector<bool> SkinEdges(const Image& image, const Image& mask, const std::vector<Vec2f>& points,
                            const SkinModel& skin, double depth, double max_distance) {
  std::vector<bool> keep(points.size(), true);
  if (!skin.valid) return keep;
  const int w = mask.width, h = mask.height;
  for (size_t i = 0; i < points.size(); ++i) {
    // The inward normal: the mean offset of the mask's inside pixels around the point.
    const int px = static_cast<int>(points[i].x()), py = static_cast<int>(points[i].y());
    Vec2d g = Vec2d::Zero();
    for (int dy = -3; dy <= 3; ++dy)
      for (int dx = -3; dx <= 3; ++dx) {
        const int x = px + dx, y = py + dy;
        if (x >= 0 && y >= 0 && x < w && y < h && mask.At(x, y, 0) > 0.5f) g += Vec2d(dx, dy);
      }
    if (g.norm() == 0) continue;
    const Vec2d q = points[i].cast<double>() + depth * g.normalized();
    const int qx = static_cast<int>(q.x()), qy = static_cast<int>(q.y());
    if (qx < 1 || qy < 1 || qx + 1 >= image.width || qy + 1 >= image.height) continue;
    Vec3f mean = Vec3f::Zero();
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) mean += image.Rgb(qx + dx, qy + dy);
    keep[i] = skin.Distance(mean / 9.f) <= max_distance;
  }
  return keep;
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
