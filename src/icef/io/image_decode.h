// PNG (libpng) and JPEG (libjpeg-turbo) decoding from memory, used by io/image.cc. Corrupt input
// is an error, never a crash: both libraries report errors through callbacks that longjmp back
// into the decoder, which keeps every object that must be freed outside the jumped-over frames.
//
// Before anything is decoded the file's structure is checked: a PNG must start with IHDR, every
// chunk must be complete, critical chunks must have a correct CRC, and IEND must follow an IDAT;
// a JPEG's segments must be complete up to the end-of-image marker. This costs one pass over the
// bytes (no inflating, no IDCT), so a header-only read (ReadImageInfo) still refuses truncated
// and bit-flipped PNGs and truncated JPEGs. Sizes are bounded before any pixel buffer exists:
// at most kMaxImageSide per side and kMaxImagePixels in all, and never more pixels than the
// compressed data could hold (deflate expands at most 1032:1; a Huffman-coded JPEG spends at
// least one bit on every 8x8 block), so a small corrupt file cannot make the reader allocate
// gigabytes.
#pragma once

#include <cstdint>
#include <string_view>
#include <vector>

#include "icef/core/status.h"

namespace icef {

inline constexpr int kMaxImageSide = 16384;
inline constexpr int64_t kMaxImagePixels = int64_t(1) << 26;

struct DecodedImage {
  int width = 0;
  int height = 0;
  int channels = 0;              // samples per pixel: 1 grey, 2 grey+alpha, 3 RGB, 4 RGBA
  int bit_depth = 0;             // 8 or 16 bits per sample
  std::vector<uint8_t> samples;  // [height, width, channels]; 16-bit samples in native byte order
};

// Checks and reads a PNG or JPEG held in `bytes`; with `decode` false only the structure and the
// header are read (samples stays empty). Channels and bit depth are those decoding gives: palette
// PNGs become RGB (RGBA with transparency), low-bit grey becomes 8-bit, CMYK JPEGs become RGB.
// Errors say what is wrong ("corrupt PNG: CRC error in chunk 'IDAT'"), not which file: callers add
// the path.
Result<DecodedImage> DecodeImage(std::string_view bytes, bool decode);

}  // namespace icef
