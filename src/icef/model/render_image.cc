#include "icef/model/render_image.h"

#include <algorithm>
#include <cmath>

namespace icef {

RenderedImage RenderImage(const AvatarModel& model, const Camera& camera, std::span<const float> beta,
                          const Vec3f& background, const Executor& executor) {
  const int w = camera.width(), h = camera.height();
  const int s = model.config().render_supersample, s2 = s * s;
  // s x s rays per pixel on a regular sub-pixel grid, consecutive per pixel.
  std::vector<Ray> rays(size_t(w) * h * s2);
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i)
      for (int q = 0; q < s2; ++q)
        rays[(size_t(j) * w + i) * s2 + q] = camera.RayThrough(i + (q % s + 0.5) / s, j + (q / s + 0.5) / s);
  RenderOutput out;
  model.Render(rays, beta, background, executor, &out);
  if (s2 > 1) {
    const float inv = 1.f / float(s2);
    auto average = [&](std::vector<float>& v, int channels) {
      const size_t pixels = size_t(w) * h;
      for (size_t p = 0; p < pixels; ++p)
        for (int c = 0; c < channels; ++c) {
          float sum = 0.f;
          for (int q = 0; q < s2; ++q) sum += v[(p * s2 + q) * channels + c];
          v[p * channels + c] = sum * inv;
        }
      v.resize(pixels * channels);
    };
    average(out.color, 3);
    average(out.depth, 1);
    average(out.opacity, 1);
    average(out.mask, 1);
    average(out.deformation, 1);
  }
  RenderedImage img;
  img.color = Image(w, h, 3);
  img.color.pixels.assign(out.color.begin(), out.color.end());
  img.depth = Image(w, h, 1);
  img.depth.pixels = out.depth;
  img.opacity = Image(w, h, 1);
  img.opacity.pixels = out.opacity;
  img.mask = Image(w, h, 1);
  img.mask.pixels = out.mask;
  img.deformation = Image(w, h, 1);
  img.deformation.pixels = out.deformation;
  img.nearest = model.Nearest(beta);
  return img;
}

Image ColorizeScalar(const Image& scalar, float lo, float hi) {
  if (!(hi > lo)) {
    lo = 1e30f, hi = -1e30f;
    for (float v : scalar.pixels) lo = std::min(lo, v), hi = std::max(hi, v);
    if (!(hi > lo)) hi = lo + 1.f;
  }
  // Five control points of viridis.
  static const float kMap[5][3] = {
      {0.267f, 0.005f, 0.329f}, {0.230f, 0.322f, 0.546f}, {0.128f, 0.567f, 0.551f}, {0.369f, 0.789f, 0.383f},
      {0.993f, 0.906f, 0.144f}};
  Image out(scalar.width, scalar.height, 3);
  for (size_t p = 0; p < scalar.pixels.size(); ++p) {
    const float t = std::clamp((scalar.pixels[p] - lo) / (hi - lo), 0.f, 1.f) * 4.f;
    const int k = std::min(3, static_cast<int>(t));
    const float f = t - k;
    for (int c = 0; c < 3; ++c) out.pixels[3 * p + c] = (1 - f) * kMap[k][c] + f * kMap[k + 1][c];
  }
  return out;
}

double MeanSquaredError(const Image& a, const Image& b) {
  ICEF_CHECK(a.width == b.width && a.height == b.height, "image sizes differ");
  double sum = 0;
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) sum += (a.Rgb(x, y) - b.Rgb(x, y)).cast<double>().squaredNorm();
  return sum / (3.0 * a.width * a.height);
}

double PsnrFromMse(double mse) { return mse > 0 ? -10.0 * std::log10(mse) : 99.0; }

}  // namespace icef
