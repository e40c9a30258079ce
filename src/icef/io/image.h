// Float images: values in [0, 1] as stored in the file (no colour-space conversion: NeRF-family
// datasets are trained directly on the stored values). Interleaved channels, row-major, row 0 at
// the top. Reading via libpng and libjpeg-turbo (PNG, JPEG; 8- or 16-bit; grey, grey+alpha, RGB,
// RGBA; palette PNGs and CMYK JPEGs as RGB(A)), with a corrupt file an error naming it, never a
// crash (io/image_decode.h); writing PNG (8-bit, stb_image_write) atomically.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "icef/core/status.h"
#include "icef/math/types.h"

namespace icef {

struct Image {
  int width = 0;
  int height = 0;
  int channels = 0;           // 1 (grey), 3 (RGB) or 4 (RGBA)
  std::vector<float> pixels;  // [height, width, channels]

  Image() = default;
  Image(int w, int h, int c, float fill = 0.f)
      : width(w), height(h), channels(c), pixels(size_t(w) * h * c, fill) {}

  float& At(int x, int y, int c) { return pixels[(size_t(y) * width + x) * channels + c]; }
  float At(int x, int y, int c) const { return pixels[(size_t(y) * width + x) * channels + c]; }
  Vec3f Rgb(int x, int y) const;  // grey images repeat the single channel
  bool HasAlpha() const { return channels == 4; }
  bool empty() const { return pixels.empty(); }
  std::string ToString() const;
};

// Size and channel count from the file header, without decoding the pixels. The file's structure
// is checked too (complete PNG chunks with valid CRCs up to IEND; complete JPEG segments up to the
// end-of-image marker), so a truncated or bit-flipped PNG and a truncated JPEG are refused here;
// damage inside compressed data that leaves the structure intact shows only in ReadImage.
struct ImageInfo {
  int width = 0;
  int height = 0;
  int channels = 0;  // as stored: 1 grey, 2 grey+alpha (read as RGBA), 3 RGB, 4 RGBA
};
Result<ImageInfo> ReadImageInfo(const std::filesystem::path& path);

// Reads a PNG or JPEG; grey+alpha becomes RGBA, grey stays 1 channel. Errors name the file.
Result<Image> ReadImage(const std::filesystem::path& path);

// Writes an 8-bit PNG (1, 3 or 4 channels; values clamped to [0, 1]) via a temporary file and
// rename, so an existing file is never left half-written.
Status WritePng(const std::filesystem::path& path, const Image& image);
// Encodes to PNG bytes in memory.
std::string EncodePng(const Image& image);

// RGB image: the RGBA image composited over `background` (alpha-weighted); RGB and grey images
// are returned as RGB unchanged.
Image CompositeOver(const Image& image, const Vec3f& background);
// The alpha channel as a 1-channel image (all ones when the image has no alpha).
Image AlphaChannel(const Image& image);

}  // namespace icef
