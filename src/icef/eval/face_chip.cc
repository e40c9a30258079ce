#include "icef/eval/face_chip.h"

#include <dlib/image_processing.h>
#include <dlib/image_transforms.h>
#include <dlib/serialize.h>

#include <algorithm>
#include <cmath>

#include "icef/eval/face_descriptor.h"
#include "icef/landmarks/dlib_image.h"

namespace icef::eval {
namespace {

Image FromDlib(const dlib::matrix<dlib::rgb_pixel>& chip) {
  Image out(int(chip.nc()), int(chip.nr()), 3);
  for (int y = 0; y < out.height; ++y) {
    for (int x = 0; x < out.width; ++x) {
      out.At(x, y, 0) = chip(y, x).red / 255.f;
      out.At(x, y, 1) = chip(y, x).green / 255.f;
      out.At(x, y, 2) = chip(y, x).blue / 255.f;
    }
  }
  return out;
}

}  // namespace

Result<Image> ExtractFaceChip(const Image& image, const std::vector<Vec2f>& landmarks) {
  if (landmarks.size() != 68)
    return Status::Error("face chip: expected 68 landmarks, got " + std::to_string(landmarks.size()));
  if (image.empty()) return Status::Error("face chip: empty image");
  std::vector<dlib::point> parts;
  parts.reserve(landmarks.size());
  for (size_t i = 0; i < landmarks.size(); ++i) {
    const Vec2f& p = landmarks[i];
    if (!std::isfinite(p.x()) || !std::isfinite(p.y()))
      return Status::Error("face chip: landmark " + std::to_string(i) + " is not finite");
    // dlib::point is integer-valued, as dlib's own shape predictor output is.
    parts.emplace_back(std::lround(p.x() - 0.5f), std::lround(p.y() - 0.5f));
  }
  dlib::rectangle box;  // the landmarks' bounding box (get_face_chip_details uses only the parts)
  for (const dlib::point& p : parts) box += p;
  const dlib::full_object_detection shape(box, parts);
  const dlib::chip_details details = dlib::get_face_chip_details(shape, kFaceChipSize, 0.25);
  dlib::matrix<dlib::rgb_pixel> chip;
  dlib::extract_image_chip(ToDlibRgb(image), details, chip);
  return FromDlib(chip);
}

}  // namespace icef::eval
