#include "icef/track/photo_crop.h"

#include <libexif/exif-data.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>

namespace icef::track {

namespace {

constexpr double kFilmDiagonalMm = 43.2666;  // 36 x 24 mm
constexpr double kDefaultFocal35mm = 35.0;

cv::Mat AsMat(const Image& image) {
  return cv::Mat(image.height, image.width, CV_32FC(image.channels), const_cast<float*>(image.pixels.data()));
}

}  // namespace

std::string CropBox::ToString() const {
  return "CropBox(x0=" + std::to_string(x0) + ", y0=" + std::to_string(y0) +
         ", size=" + std::to_string(size) + ")";
}

CropBox HeadCropBox(const Camera& camera, double margin) {
  // The average head spans x +-0.28 (+-0.36 with the ears), y from -0.34 (chin) to 0.39 (crown),
  // z +-0.34; the box adds room for hair and keeps the neck down to y = -0.55.
  Aabb box;
  box.min = Vec3f(-0.36f, -0.55f, -0.36f);
  box.max = Vec3f(0.36f, 0.47f, 0.36f);
  double u0 = std::numeric_limits<double>::max(), v0 = u0, u1 = -u0, v1 = -u0;
  for (int corner = 0; corner < 8; ++corner) {
    const Vec3d p((corner & 1) ? box.max.x() : box.min.x(), (corner & 2) ? box.max.y() : box.min.y(),
                  (corner & 4) ? box.max.z() : box.min.z());
    if (const auto proj = camera.Project(p)) {
      u0 = std::min(u0, proj->uv.x()), u1 = std::max(u1, proj->uv.x());
      v0 = std::min(v0, proj->uv.y()), v1 = std::max(v1, proj->uv.y());
    }
  }
  CropBox c;
  c.size = std::max(u1 - u0, v1 - v0) * margin;
  c.x0 = 0.5 * (u0 + u1) - 0.5 * c.size;
  c.y0 = 0.5 * (v0 + v1) - 0.5 * c.size;
  return c;
}

Image CropImage(const Image& photo, const CropBox& box, int resolution, Image* outside) {
  // First the crop at the photo's own scale (a translation), then the resize.
  const int side = std::max(1, static_cast<int>(std::lround(box.size)));
  const double s = side / box.size;  // ~1: the crop at its own scale
  // OpenCV maps pixel indices (centres at integers): crop index j <- photo index (j + 0.5) / s + x0 - 0.5.
  const cv::Mat affine =
      (cv::Mat_<double>(2, 3) << s, 0, -s * box.x0 + 0.5 * (s - 1), 0, s, -s * box.y0 + 0.5 * (s - 1));
  cv::Mat at_scale;
  cv::warpAffine(AsMat(photo), at_scale, affine, cv::Size(side, side), cv::INTER_LINEAR,
                 cv::BORDER_REPLICATE);
  cv::Mat resized;
  cv::resize(at_scale, resized, cv::Size(resolution, resolution), 0, 0,
             resolution < side ? cv::INTER_AREA : cv::INTER_LINEAR);
  Image out(resolution, resolution, photo.channels);
  std::copy(resized.ptr<float>(), resized.ptr<float>() + out.pixels.size(), out.pixels.begin());
  if (outside) {
    *outside = Image(resolution, resolution, 1);
    const double scale = box.size / resolution;
    for (int y = 0; y < resolution; ++y)
      for (int x = 0; x < resolution; ++x) {
        const double px = box.x0 + (x + 0.5) * scale, py = box.y0 + (y + 0.5) * scale;
        outside->At(x, y, 0) = (px < 0 || py < 0 || px > photo.width || py > photo.height) ? 1.f : 0.f;
      }
  }
  return out;
}

Image ResizeImage(const Image& image, int width, int height) {
  cv::Mat resized;
  const bool shrink = width < image.width || height < image.height;
  cv::resize(AsMat(image), resized, cv::Size(width, height), 0, 0,
             shrink ? cv::INTER_AREA : cv::INTER_LINEAR);
  Image out(width, height, image.channels);
  std::copy(resized.ptr<float>(), resized.ptr<float>() + out.pixels.size(), out.pixels.begin());
  return out;
}

Intrinsics CropIntrinsics(const Intrinsics& photo, const CropBox& box, int resolution) {
  const double scale = resolution / box.size;
  Intrinsics k;
  k.width = k.height = resolution;
  k.fl_x = photo.fl_x * scale;
  k.fl_y = photo.fl_y * scale;
  k.cx = (photo.cx - box.x0) * scale;
  k.cy = (photo.cy - box.y0) * scale;
  return k;
}

std::vector<Vec2f> CropPoints(std::span<const Vec2f> points, const CropBox& box, int resolution) {
  const double scale = resolution / box.size;
  std::vector<Vec2f> out;
  for (const Vec2f& p : points)
    out.push_back(
        Vec2f(static_cast<float>((p.x() - box.x0) * scale), static_cast<float>((p.y() - box.y0) * scale)));
  return out;
}

std::optional<double> ExifFocalPixels(const std::filesystem::path& path, int width, int height) {
  ExifData* data = exif_data_new_from_file(path.c_str());
  if (!data) return std::nullopt;
  std::optional<double> focal;
  if (ExifEntry* e = exif_data_get_entry(data, EXIF_TAG_FOCAL_LENGTH_IN_35MM_FILM);
      e && e->format == EXIF_FORMAT_SHORT && e->components >= 1) {
    const double mm = exif_get_short(e->data, exif_data_get_byte_order(data));
    if (mm > 0) focal = mm / kFilmDiagonalMm * std::hypot(width, height);
  }
  exif_data_unref(data);
  return focal;
}

int ExifOrientation(const std::filesystem::path& path) {
  ExifData* data = exif_data_new_from_file(path.c_str());
  if (!data) return 1;
  int orientation = 1;
  if (ExifEntry* e = exif_data_get_entry(data, EXIF_TAG_ORIENTATION);
      e && e->format == EXIF_FORMAT_SHORT && e->components >= 1) {
    const int v = exif_get_short(e->data, exif_data_get_byte_order(data));
    if (v >= 1 && v <= 8) orientation = v;
  }
  exif_data_unref(data);
  return orientation;
}

Image Oriented(const Image& stored, int orientation) {
  if (orientation <= 1 || orientation > 8) return stored;
  const bool swap = orientation >= 5;  // 5-8 exchange width and height
  Image out(swap ? stored.height : stored.width, swap ? stored.width : stored.height, stored.channels);
  for (int y = 0; y < out.height; ++y)
    for (int x = 0; x < out.width; ++x) {
      int sx = x, sy = y;  // the stored pixel shown at (x, y)
      switch (orientation) {
        case 2:
          sx = stored.width - 1 - x;
          break;
        case 3:
          sx = stored.width - 1 - x, sy = stored.height - 1 - y;
          break;
        case 4:
          sy = stored.height - 1 - y;
          break;
        case 5:
          sx = y, sy = x;
          break;
        case 6:
          sx = y, sy = stored.height - 1 - x;
          break;
        case 7:
          sx = stored.width - 1 - y, sy = stored.height - 1 - x;
          break;
        case 8:
          sx = stored.width - 1 - y, sy = x;
          break;
      }
      for (int c = 0; c < stored.channels; ++c) out.At(x, y, c) = stored.At(sx, sy, c);
    }
  return out;
}

double DefaultFocalPixels(int width, int height) {
  return kDefaultFocal35mm / kFilmDiagonalMm * std::hypot(width, height);
}

}  // namespace icef::track
