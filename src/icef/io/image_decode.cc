#include "icef/io/image_decode.h"

#include <jerror.h>
#include <jpeglib.h>  // after <cstdio>: jpeglib.h needs FILE and size_t
#include <png.h>
#include <zlib.h>

#include <algorithm>
#include <bit>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <string>

namespace icef {

namespace {

// Deflate never expands data by more than 1032:1 (zlib FAQ), so a PNG cannot hold more raw pixel
// bytes than this many times its IDAT bytes.
constexpr uint64_t kMaxDeflateRatio = 1032;

uint32_t Be32(const unsigned char* p) {
  return uint32_t(p[0]) << 24 | uint32_t(p[1]) << 16 | uint32_t(p[2]) << 8 | p[3];
}

// Writes "unsupported image size" into `error` when w x h is beyond the bounds; true when it is not.
bool SizeWithinBounds(uint64_t w, uint64_t h, char* error, size_t n) {
  if (w > 0 && h > 0 && w <= uint64_t(kMaxImageSide) && h <= uint64_t(kMaxImageSide) &&
      w * h <= uint64_t(kMaxImagePixels))
    return true;
  std::snprintf(error, n, "unsupported image size %llux%llu (at most %d pixels a side and %lld in all)",
                static_cast<unsigned long long>(w), static_cast<unsigned long long>(h), kMaxImageSide,
                static_cast<long long>(kMaxImagePixels));
  return false;
}

// ---- PNG --------------------------------------------------------------------------------------

bool IsPng(std::string_view b) {
  return b.size() >= 8 && png_sig_cmp(reinterpret_cast<png_const_bytep>(b.data()), 0, 8) == 0;
}

// Walks the chunks without inflating anything; returns what is wrong ("" when nothing) and adds up
// the IDAT bytes. Ancillary chunks' CRCs are not checked: libpng only warns about them too.
std::string CheckPngChunks(std::string_view bytes, uint64_t* idat_bytes) {
  const auto* b = reinterpret_cast<const unsigned char*>(bytes.data());
  const size_t n = bytes.size();
  size_t pos = 8;
  bool seen_idat = false;
  for (int index = 0;; ++index) {
    if (n - pos < 12)
      return "truncated file: it ends " +
             std::string(index ? "after chunk " + std::to_string(index) : "after the signature") +
             ", before IEND";
    const uint32_t length = Be32(b + pos);
    const unsigned char* type = b + pos + 4;
    for (int k = 0; k < 4; ++k)
      if (!((type[k] >= 'A' && type[k] <= 'Z') || (type[k] >= 'a' && type[k] <= 'z')))
        return "corrupt chunk type at byte " + std::to_string(pos + 4);
    const std::string name(reinterpret_cast<const char*>(type), 4);
    if (length > 0x7fffffffu) return "chunk '" + name + "' has an invalid length";
    if (n - pos - 12 < length)
      return "truncated file: chunk '" + name + "' needs " + std::to_string(length) + " bytes, " +
             std::to_string(n - pos - 12) + " are left";
    if (index == 0 && name != "IHDR") return "the first chunk is '" + name + "', not IHDR";
    const bool critical = (type[0] & 0x20) == 0;
    if (critical) {
      if (crc32(crc32(0, nullptr, 0), type, length + 4) != Be32(type + 4 + length))
        return "CRC error in chunk '" + name + "' (corrupt file)";
      if (name == "IDAT") {
        seen_idat = true;
        *idat_bytes += length;
      } else if (name == "IEND") {
        return seen_idat ? "" : "no IDAT chunk (no pixel data)";
      } else if (name != "IHDR" && name != "PLTE") {
        return "unknown critical chunk '" + name + "'";
      }
    }
    pos += 12 + size_t(length);
  }
}

// Everything RunPng must not lose when libpng longjmps out of it.
struct PngReader {
  png_structp png = nullptr;
  png_infop info = nullptr;
  const unsigned char* data = nullptr;
  size_t size = 0;
  size_t pos = 0;
  char error[256] = "";
  std::vector<png_bytep> rows;

  ~PngReader() {
    if (png) png_destroy_read_struct(&png, info ? &info : nullptr, nullptr);
  }
};

void PngError(png_structp png, png_const_charp message) {
  auto* r = static_cast<PngReader*>(png_get_error_ptr(png));
  std::snprintf(r->error, sizeof r->error, "corrupt PNG: %s", message);
  png_longjmp(png, 1);
}

// Warnings are about ancillary data (an odd colour profile, a bad text chunk), never the pixels.
void PngWarning(png_structp, png_const_charp) {}

void PngRead(png_structp png, png_bytep out, size_t n) {
  auto* r = static_cast<PngReader*>(png_get_io_ptr(png));
  if (r->size - r->pos < n) png_error(png, "truncated file");
  std::memcpy(out, r->data + r->pos, n);
  r->pos += n;
}

// libpng longjmps back here on any error, so only trivially destructible locals live in this
// function; what needs freeing is in *r and *out.
bool RunPng(PngReader* r, uint64_t idat_bytes, bool decode, DecodedImage* out) {
  r->png = png_create_read_struct(PNG_LIBPNG_VER_STRING, r, PngError, PngWarning);
  if (r->png) r->info = png_create_info_struct(r->png);
  if (!r->png || !r->info) {
    std::snprintf(r->error, sizeof r->error, "out of memory");
    return false;
  }
  if (setjmp(png_jmpbuf(r->png))) return false;
  png_set_read_fn(r->png, r, PngRead);
  png_read_info(r->png, r->info);
  const uint64_t w = png_get_image_width(r->png, r->info), h = png_get_image_height(r->png, r->info);
  if (!SizeWithinBounds(w, h, r->error, sizeof r->error)) return false;
  const uint64_t raw_bits = w * h * png_get_channels(r->png, r->info) * png_get_bit_depth(r->png, r->info);
  if (raw_bits / 8 > kMaxDeflateRatio * (idat_bytes + 1)) {
    std::snprintf(r->error, sizeof r->error,
                  "corrupt PNG: %llu bytes of IDAT data cannot hold %llux%llu pixels (truncated or corrupt)",
                  static_cast<unsigned long long>(idat_bytes), static_cast<unsigned long long>(w),
                  static_cast<unsigned long long>(h));
    return false;
  }
  png_set_expand(r->png);  // palette -> RGB(A), grey below 8 bits -> 8 bits, tRNS -> alpha
  if (png_get_bit_depth(r->png, r->info) == 16 && std::endian::native == std::endian::little)
    png_set_swap(r->png);
  png_set_interlace_handling(r->png);
  png_read_update_info(r->png, r->info);
  out->width = static_cast<int>(w);
  out->height = static_cast<int>(h);
  out->channels = png_get_channels(r->png, r->info);
  out->bit_depth = png_get_bit_depth(r->png, r->info);
  if (!decode) return true;
  const size_t row_bytes = png_get_rowbytes(r->png, r->info);
  if (row_bytes != size_t(w) * out->channels * (out->bit_depth / 8)) {
    std::snprintf(r->error, sizeof r->error, "corrupt PNG: unexpected row size %zu", row_bytes);
    return false;
  }
  out->samples.resize(row_bytes * h);
  r->rows.resize(h);
  for (uint64_t y = 0; y < h; ++y) r->rows[y] = out->samples.data() + y * row_bytes;
  png_read_image(r->png, r->rows.data());
  png_read_end(r->png, nullptr);  // reads on to IEND, checking the CRCs of the remaining chunks
  return true;
}

// ---- JPEG -------------------------------------------------------------------------------------

bool IsJpeg(std::string_view b) {
  return b.size() >= 3 && uint8_t(b[0]) == 0xFF && uint8_t(b[1]) == 0xD8 && uint8_t(b[2]) == 0xFF;
}

// Walks the marker segments to the end-of-image marker, skipping entropy-coded data (where 0xFF
// is followed by a stuffed 0x00 or a restart marker); returns what is wrong ("" when nothing).
std::string CheckJpegMarkers(std::string_view bytes) {
  const auto* b = reinterpret_cast<const unsigned char*>(bytes.data());
  const size_t n = bytes.size();
  const std::string truncated = "truncated file: it ends before the end-of-image marker";
  size_t pos = 2;  // after SOI
  bool seen_scan = false;
  while (true) {
    if (pos >= n) return truncated;
    if (b[pos] != 0xFF) return "corrupt file: no marker at byte " + std::to_string(pos);
    while (pos < n && b[pos] == 0xFF) ++pos;  // fill bytes
    if (pos >= n) return truncated;
    const unsigned char marker = b[pos++];
    if (marker == 0xD9) return seen_scan ? "" : "no image data (end-of-image before any scan)";
    if (marker == 0x01 || (marker >= 0xD0 && marker <= 0xD7)) continue;  // TEM, RSTn: no length
    if (marker == 0x00 || marker == 0xD8)
      return "corrupt file: unexpected marker at byte " + std::to_string(pos - 2);
    if (n - pos < 2) return truncated;
    const size_t length = size_t(b[pos]) << 8 | b[pos + 1];
    if (length < 2)
      return "corrupt file: segment length " + std::to_string(length) + " at byte " + std::to_string(pos);
    if (n - pos < length) return truncated;
    pos += length;
    if (marker != 0xDA) continue;
    seen_scan = true;  // SOS: entropy-coded data up to the next marker
    while (true) {
      const void* ff = pos < n ? std::memchr(b + pos, 0xFF, n - pos) : nullptr;
      if (!ff) return truncated;
      pos = static_cast<size_t>(static_cast<const unsigned char*>(ff) - b);
      if (pos + 1 >= n) return truncated;
      const unsigned char next = b[pos + 1];
      if (next == 0x00 || (next >= 0xD0 && next <= 0xD7)) {
        pos += 2;
      } else if (next == 0xFF) {
        ++pos;
      } else {
        break;
      }
    }
  }
}

struct JpegErrorManager {
  jpeg_error_mgr pub;
  std::jmp_buf jump;
  char message[JMSG_LENGTH_MAX + 64];
};

[[noreturn]] void JpegErrorExit(j_common_ptr cinfo) {
  auto* e = reinterpret_cast<JpegErrorManager*>(cinfo->err);
  char text[JMSG_LENGTH_MAX];
  (*cinfo->err->format_message)(cinfo, text);
  std::snprintf(e->message, sizeof e->message, "corrupt JPEG: %s", text);
  std::longjmp(e->jump, 1);
}

// Warnings that mean damaged pixel data (a truncated file, bad Huffman codes, lost restart markers)
// are errors: libjpeg would go on and fill the rest of the image with grey. The few that concern
// metadata only are ignored; trace messages (level > 0) too. Nothing is ever printed.
void JpegEmitMessage(j_common_ptr cinfo, int level) {
  if (level >= 0) return;
  switch (cinfo->err->msg_code) {
    case JWRN_ADOBE_XFORM:
    case JWRN_JFIF_MAJOR:
    case JWRN_NOT_SEQUENTIAL:
    case JWRN_BOGUS_ICC:
      return;
    default:
      JpegErrorExit(cinfo);
  }
}

void JpegOutputMessage(j_common_ptr) {}

// Everything RunJpeg must not lose when libjpeg longjmps out of it.
struct JpegReader {
  jpeg_decompress_struct cinfo{};  // zeroed: destroying it before jpeg_create_decompress is a no-op
  JpegErrorManager error{};
  ~JpegReader() { jpeg_destroy_decompress(&cinfo); }
};

// libjpeg longjmps back here on any error, so only trivially destructible locals live in this
// function; what needs freeing is in *r and *out.
bool RunJpeg(JpegReader* r, std::string_view bytes, bool decode, DecodedImage* out) {
  r->cinfo.err = jpeg_std_error(&r->error.pub);
  r->error.pub.error_exit = JpegErrorExit;
  r->error.pub.emit_message = JpegEmitMessage;
  r->error.pub.output_message = JpegOutputMessage;
  if (setjmp(r->error.jump)) return false;
  jpeg_create_decompress(&r->cinfo);
  jpeg_mem_src(&r->cinfo, reinterpret_cast<const unsigned char*>(bytes.data()),
               static_cast<unsigned long>(bytes.size()));
  jpeg_read_header(&r->cinfo, TRUE);
  jpeg_decompress_struct& c = r->cinfo;
  int channels = 3;
  switch (c.jpeg_color_space) {
    case JCS_GRAYSCALE:
      c.out_color_space = JCS_GRAYSCALE;
      channels = 1;
      break;
    case JCS_CMYK:
    case JCS_YCCK:
      c.out_color_space = JCS_CMYK;  // converted to RGB below
      break;
    case JCS_RGB:
    case JCS_YCbCr:
      c.out_color_space = JCS_RGB;
      break;
    default:
      std::snprintf(r->error.message, sizeof r->error.message,
                    "unsupported JPEG colour space (%d components)", c.num_components);
      return false;
  }
  const uint64_t w = c.image_width, h = c.image_height;
  if (!SizeWithinBounds(w, h, r->error.message, sizeof r->error.message)) return false;
  // Every MCU (one block per component at the coarsest sampling) costs a Huffman-coded stream at
  // least one bit; arithmetic coding has no such floor (its images are only bounded by size).
  int max_h = 1, max_v = 1;
  for (int i = 0; i < c.num_components; ++i) {
    max_h = std::max(max_h, c.comp_info[i].h_samp_factor);
    max_v = std::max(max_v, c.comp_info[i].v_samp_factor);
  }
  const uint64_t mcus = ((w + 8 * max_h - 1) / (8 * max_h)) * ((h + 8 * max_v - 1) / (8 * max_v));
  if (!c.arith_code && mcus > 8 * uint64_t(bytes.size())) {
    std::snprintf(r->error.message, sizeof r->error.message,
                  "corrupt JPEG: %zu bytes cannot hold %llux%llu pixels (truncated or corrupt)", bytes.size(),
                  static_cast<unsigned long long>(w), static_cast<unsigned long long>(h));
    return false;
  }
  out->width = static_cast<int>(w);
  out->height = static_cast<int>(h);
  out->channels = channels;
  out->bit_depth = 8;
  if (!decode) return true;
  jpeg_start_decompress(&c);
  const size_t stride = size_t(w) * c.output_components;
  if (c.output_width != w || c.output_height != h ||
      (c.output_components != channels && c.output_components != 4)) {
    std::snprintf(r->error.message, sizeof r->error.message, "corrupt JPEG: unexpected output layout");
    return false;
  }
  out->samples.resize(stride * h);
  while (c.output_scanline < c.output_height) {
    JSAMPROW row = out->samples.data() + size_t(c.output_scanline) * stride;
    if (jpeg_read_scanlines(&c, &row, 1) != 1) {
      std::snprintf(r->error.message, sizeof r->error.message, "corrupt JPEG: decoding stalled at row %u",
                    c.output_scanline);
      return false;
    }
  }
  jpeg_finish_decompress(&c);
  if (c.output_components == 4) {
    // Adobe CMYK as libjpeg gives it (inverted: 255 = no ink) to RGB, as stb_image and browsers do.
    auto mul = [](unsigned x, unsigned k) {
      const unsigned t = x * k + 128;
      return static_cast<uint8_t>((t + (t >> 8)) >> 8);
    };
    for (size_t i = 0; i < size_t(w) * h; ++i) {
      const uint8_t* s = &out->samples[i * 4];
      const uint8_t k = s[3];
      const uint8_t rgb[3] = {mul(s[0], k), mul(s[1], k), mul(s[2], k)};
      std::memcpy(&out->samples[i * 3], rgb, 3);
    }
    out->samples.resize(size_t(w) * h * 3);
  }
  return true;
}

}  // namespace

Result<DecodedImage> DecodeImage(std::string_view bytes, bool decode) {
  if (bytes.empty()) return Status::Error("empty file, not an image");
  DecodedImage out;
  if (IsPng(bytes)) {
    uint64_t idat_bytes = 0;
    if (const std::string why = CheckPngChunks(bytes, &idat_bytes); !why.empty())
      return Status::Error("corrupt PNG: " + why);
    // The size from IHDR (the walk checked it is the first chunk, complete, with a valid CRC),
    // bounded before libpng sees it.
    char error[256];
    const auto* ihdr = reinterpret_cast<const unsigned char*>(bytes.data()) + 16;
    if (Be32(reinterpret_cast<const unsigned char*>(bytes.data()) + 8) < 8)
      return Status::Error("corrupt PNG: IHDR is too short");
    if (!SizeWithinBounds(Be32(ihdr), Be32(ihdr + 4), error, sizeof error)) return Status::Error(error);
    PngReader reader;
    reader.data = reinterpret_cast<const unsigned char*>(bytes.data());
    reader.size = bytes.size();
    if (!RunPng(&reader, idat_bytes, decode, &out)) return Status::Error(reader.error);
    return out;
  }
  if (IsJpeg(bytes)) {
    if (const std::string why = CheckJpegMarkers(bytes); !why.empty())
      return Status::Error("corrupt JPEG: " + why);
    JpegReader reader;
    if (!RunJpeg(&reader, bytes, decode, &out)) return Status::Error(reader.error.message);
    return out;
  }
  return Status::Error("not a PNG or JPEG image (unknown file signature)");
}

}  // namespace icef
