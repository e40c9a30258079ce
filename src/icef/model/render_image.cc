#include "icef/model/render_image.h"

#include <algorithm>
#include <cmath>
#include <optional>

namespace icef {

RenderedImage RenderImage(const AvatarModel& model, const Camera& camera, std::span<const float> beta,
                          const Vec3f& background, const Executor& executor,
                          RenderOccupancyMode occupancy_mode) {
  std::optional<OccupancyGrid> occupancy;
  if (occupancy_mode == RenderOccupancyMode::kExpression) occupancy = model.RenderOccupancy(beta, executor);
  const int w = camera.width(), h = camera.height();
  const int s = model.config().render.supersample, s2 = s * s;
  RenderedImage img;
  img.color = Image(w, h, 3);
  img.depth = Image(w, h, 1);
  img.opacity = Image(w, h, 1);
  img.mask = Image(w, h, 1);
  img.deformation = Image(w, h, 1);
  // Bands of rows of at most kBandRays rays, so memory does not grow with the image (rendering
  // rays is independent per ray: the bands give the same pixels as one call for the whole image).
  constexpr int64_t kBandRays = 1 << 16;
  const int rows = static_cast<int>(std::max<int64_t>(1, kBandRays / (int64_t(w) * s2)));
  std::vector<Ray> rays;
  RenderOutput out;
  const float inv = 1.f / float(s2);
  for (int j0 = 0; j0 < h; j0 += rows) {
    const int j1 = std::min(h, j0 + rows);
    // s x s rays per pixel on a regular sub-pixel grid, consecutive per pixel.
    rays.resize(size_t(j1 - j0) * w * s2);
    for (int j = j0; j < j1; ++j)
      for (int i = 0; i < w; ++i)
        for (int q = 0; q < s2; ++q)
          rays[(size_t(j - j0) * w + i) * s2 + q] =
              camera.RayThrough(i + (q % s + 0.5) / s, j + (q / s + 0.5) / s);
    model.Render(rays, beta, background, executor, &out, occupancy ? &*occupancy : nullptr);
    img.samples_evaluated += out.samples_evaluated;
    const size_t first = size_t(j0) * w, pixels = size_t(j1 - j0) * w;
    auto average = [&](const std::vector<float>& v, int channels, Image& dst) {
      for (size_t p = 0; p < pixels; ++p)
        for (int c = 0; c < channels; ++c) {
          float sum = 0.f;
          for (int q = 0; q < s2; ++q) sum += v[(p * s2 + q) * channels + c];
          dst.pixels[(first + p) * channels + c] = s2 > 1 ? sum * inv : sum;
        }
    };
    average(out.color, 3, img.color);
    average(out.depth, 1, img.depth);
    average(out.opacity, 1, img.opacity);
    average(out.mask, 1, img.mask);
    average(out.deformation, 1, img.deformation);
  }
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
  static const float kMap[5][3] = {{0.267f, 0.005f, 0.329f},
                                   {0.230f, 0.322f, 0.546f},
                                   {0.128f, 0.567f, 0.551f},
                                   {0.369f, 0.789f, 0.383f},
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
