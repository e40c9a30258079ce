#include "icef/eval/expression_fidelity.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "icef/eval/metrics.h"

namespace icef::eval {

double DefaultCoarseSigma(int width) { return 2.0 * width / 128.0; }

Image FaceRegion(int width, int height, const std::vector<Vec2f>& landmarks) {
  return LandmarkHullRegion(width, height, landmarks);
}

Result<ExpressionFidelity> MeasureExpression(const Image& render, const Image& render_neutral,
                                             const Image& truth, const Image& truth_neutral,
                                             const Image& region, double coarse_sigma) {
  for (const Image* image : {&render, &render_neutral, &truth, &truth_neutral}) {
    if (image->width != region.width || image->height != region.height || image->channels < 3)
      return Status::Error("expression fidelity: images must be RGB(A) of the region's size " +
                           std::to_string(region.width) + "x" + std::to_string(region.height) + ", got " +
                           image->ToString());
  }
  ExpressionFidelity f;
  double mt = 0, mm = 0, tt = 0;
  for (int y = 0; y < region.height; ++y)
    for (int x = 0; x < region.width; ++x) {
      if (region.At(x, y, 0) <= 0.5f) continue;
      ++f.pixels;
      for (int c = 0; c < 3; ++c) {
        const double m = double(render.At(x, y, c)) - render_neutral.At(x, y, c);
        const double t = double(truth.At(x, y, c)) - truth_neutral.At(x, y, c);
        mt += m * t, mm += m * m, tt += t * t;
      }
    }
  if (f.pixels == 0) return f;
  f.true_rms = std::sqrt(tt / (3.0 * f.pixels));
  f.negligible = f.true_rms < kNegligibleExpressionRms;
  if (f.negligible) return f;
  f.gain = mt / tt;
  if (mm > 0) f.corr = mt / std::sqrt(mm * tt);
  if (coarse_sigma > 0) {
    const int w = region.width, h = region.height;
    double cmt = 0, ctt = 0;
    std::vector<double> m(size_t(w) * h), t(size_t(w) * h);
    for (int c = 0; c < 3; ++c) {
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
          m[size_t(y) * w + x] = double(render.At(x, y, c)) - render_neutral.At(x, y, c);
          t[size_t(y) * w + x] = double(truth.At(x, y, c)) - truth_neutral.At(x, y, c);
        }
      const std::vector<double> ms = GaussianFilter(m, w, h, coarse_sigma),
                                ts = GaussianFilter(t, w, h, coarse_sigma);
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
          if (region.At(x, y, 0) <= 0.5f) continue;
          const size_t i = size_t(y) * w + x;
          cmt += ms[i] * ts[i], ctt += ts[i] * ts[i];
        }
    }
    if (ctt > 0) f.gain_coarse = cmt / ctt;
  }
  return f;
}

}  // namespace icef::eval
