#include "icef/landmarks/dlib_image.h"

#include <algorithm>
#include <cmath>

namespace icef {

dlib::matrix<dlib::rgb_pixel> ToDlibRgb(const Image& image) {
  dlib::matrix<dlib::rgb_pixel> out(image.height, image.width);
  auto q = [](float v) { return static_cast<unsigned char>(std::lround(std::clamp(v, 0.f, 1.f) * 255.f)); };
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      const Vec3f rgb = image.Rgb(x, y);
      out(y, x) = dlib::rgb_pixel(q(rgb.x()), q(rgb.y()), q(rgb.z()));
    }
  }
  return out;
}

}  // namespace icef
