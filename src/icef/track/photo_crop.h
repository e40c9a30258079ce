// The square crop of a photo around the fitted head, resampled to the dataset's resolution, and
// what it does to the camera and the landmarks; plus the photo's focal length (EXIF).
#pragma once

#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "icef/core/status.h"
#include "icef/io/image.h"
#include "icef/math/camera.h"
#include "icef/math/types.h"

namespace icef::track {

// A square in the photo's image coordinates: [x0, x0 + size) x [y0, y0 + size).
struct CropBox {
  double x0 = 0, y0 = 0, size = 1;
  std::string ToString() const;
};

// The square around the head (crown with room for hair down to the upper neck, in the head frame)
// seen by `camera` (world = head frame), enlarged by `margin`.
CropBox HeadCropBox(const Camera& camera, double margin = 1.15);

// The crop resampled to resolution x resolution (bilinear; area-averaged when shrinking). Pixels
// outside the photo repeat its border; `outside`, when non-null, gets a 1-channel image that is 1
// there. Channels as in the photo.
Image CropImage(const Image& photo, const CropBox& box, int resolution, Image* outside = nullptr);

// The image resized to width x height (area-averaged when shrinking, bilinear otherwise).
Image ResizeImage(const Image& image, int width, int height);

// The intrinsics and landmarks of the crop (pixel centres at +0.5 in both).
Intrinsics CropIntrinsics(const Intrinsics& photo, const CropBox& box, int resolution);
std::vector<Vec2f> CropPoints(std::span<const Vec2f> points, const CropBox& box, int resolution);

// The focal length in pixels recorded in a JPEG's EXIF (FocalLengthIn35mmFilm, by the diagonal of
// 35 mm film); nullopt when the file has no such tag.
std::optional<double> ExifFocalPixels(const std::filesystem::path& path, int width, int height);

// The EXIF orientation of a JPEG (1-8, as the tag defines it; 1 = as stored), 1 without the tag.
int ExifOrientation(const std::filesystem::path& path);

// The image as it is meant to be seen: the stored pixels turned/mirrored by the EXIF orientation
// (3: 180 degrees, 6: 90 degrees clockwise, 8: 90 counter-clockwise, 2/4/5/7 their mirrored forms).
Image Oriented(const Image& stored, int orientation);

// The focal length assumed without --focal or EXIF: a 35 mm-equivalent lens (between phones' and
// webcams' 24-28 mm and portrait lenses' 50-85 mm), 0.81 x the photo's diagonal in pixels.
double DefaultFocalPixels(int width, int height);

}  // namespace icef::track
