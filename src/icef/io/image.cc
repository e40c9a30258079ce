#include "icef/io/image.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <sstream>

#include "icef/io/atomic_file.h"
#include "icef/io/image_decode.h"

#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb_image_write.h>

namespace icef {

namespace fs = std::filesystem;

Vec3f Image::Rgb(int x, int y) const {
  const float* p = &pixels[(size_t(y) * width + x) * channels];
  if (channels < 3) return Vec3f::Constant(p[0]);
  return Vec3f(p[0], p[1], p[2]);
}

std::string Image::ToString() const {
  std::ostringstream os;
  os << "Image(" << width << "x" << height << ", channels=" << channels << ")";
  return os.str();
}

namespace {
// Reads and checks the file (io/image_decode.h); errors name the file.
Result<DecodedImage> ReadAndDecode(const fs::path& path, bool decode) {
  ICEF_ASSIGN_OR_RETURN(const std::string bytes, ReadFile(path));
  Result<DecodedImage> decoded = DecodeImage(bytes, decode);
  if (!decoded.ok()) return Status::Error(path.string() + ": " + decoded.status().message());
  return decoded;
}
}  // namespace

Result<ImageInfo> ReadImageInfo(const fs::path& path) {
  ICEF_ASSIGN_OR_RETURN(const DecodedImage d, ReadAndDecode(path, /*decode=*/false));
  return ImageInfo{d.width, d.height, d.channels};
}

Result<Image> ReadImage(const fs::path& path) {
  ICEF_ASSIGN_OR_RETURN(const DecodedImage d, ReadAndDecode(path, /*decode=*/true));
  const int c = d.channels;
  const int out_c = (c == 2) ? 4 : c;  // grey+alpha -> RGBA
  Image img(d.width, d.height, out_c);
  const size_t n = size_t(d.width) * d.height;
  auto expand = [&](const auto* src, float scale) {
    for (size_t i = 0; i < n; ++i) {
      float* dst = &img.pixels[i * out_c];
      if (c == 2) {
        dst[0] = dst[1] = dst[2] = src[i * 2] * scale;
        dst[3] = src[i * 2 + 1] * scale;
      } else {
        for (int k = 0; k < c; ++k) dst[k] = src[i * c + k] * scale;
      }
    }
  };
  if (d.bit_depth == 16) {
    std::vector<uint16_t> samples(d.samples.size() / 2);
    std::memcpy(samples.data(), d.samples.data(), samples.size() * 2);
    expand(samples.data(), 1.f / 65535.f);
  } else {
    expand(d.samples.data(), 1.f / 255.f);
  }
  return img;
}

std::string EncodePng(const Image& image) {
  ICEF_CHECK(image.channels >= 1 && image.channels <= 4 && !image.empty(), image.ToString());
  std::vector<unsigned char> bytes(image.pixels.size());
  for (size_t i = 0; i < bytes.size(); ++i) {
    const float v = image.pixels[i];
    bytes[i] =
        static_cast<unsigned char>(std::lround(std::clamp(std::isfinite(v) ? v : 0.f, 0.f, 1.f) * 255.f));
  }
  std::string out;
  stbi_write_png_to_func(
      [](void* ctx, void* data, int size) {
        static_cast<std::string*>(ctx)->append(static_cast<char*>(data), size);
      },
      &out, image.width, image.height, image.channels, bytes.data(), image.width * image.channels);
  return out;
}

Status WritePng(const fs::path& path, const Image& image) {
  if (image.empty()) return Status::Error(path.string() + ": refusing to write an empty image");
  return WriteFileAtomic(path, EncodePng(image));
}

Image CompositeOver(const Image& image, const Vec3f& background) {
  Image out(image.width, image.height, 3);
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      const Vec3f rgb = image.Rgb(x, y);
      const float a = image.HasAlpha() ? image.At(x, y, 3) : 1.f;
      const Vec3f c = a * rgb + (1.f - a) * background;
      for (int k = 0; k < 3; ++k) out.At(x, y, k) = c[k];
    }
  }
  return out;
}

Image AlphaChannel(const Image& image) {
  Image out(image.width, image.height, 1, 1.f);
  if (!image.HasAlpha()) return out;
  for (size_t i = 0; i < size_t(image.width) * image.height; ++i) out.pixels[i] = image.pixels[i * 4 + 3];
  return out;
}

}  // namespace icef
