#include "icef/eval/metrics.h"

#include <cmath>
#include <limits>
#include <sstream>
#include <vector>

namespace icef::eval {
namespace {

Result<int> CheckPair(const Image& a, const Image& b, const Image* mask, const char* metric) {
  if (a.empty() || b.empty()) return Status::Error(std::string(metric) + ": empty image");
  if (a.width != b.width || a.height != b.height || a.channels != b.channels)
    return Status::Error(std::string(metric) + ": images differ in size or channels: " + a.ToString() +
                         " vs " + b.ToString());
  if (mask != nullptr && (mask->width != a.width || mask->height != a.height))
    return Status::Error(std::string(metric) + ": mask " + mask->ToString() + " does not match image " +
                         a.ToString());
  return a.channels >= 3 ? 3 : a.channels;
}

bool InMask(const Image* mask, int x, int y) { return mask == nullptr || mask->At(x, y, 0) > 0.5f; }

// Separable Gaussian filter of one plane [h, w] with scipy's 'reflect' boundary (d c b a | a b c d).
std::vector<double> Blur(const std::vector<double>& plane, int w, int h, const std::vector<double>& kernel) {
  const int r = int(kernel.size() / 2);
  auto reflect = [](int i, int n) {
    while (i < 0 || i >= n) i = i < 0 ? -i - 1 : 2 * n - i - 1;
    return i;
  };
  std::vector<double> tmp(plane.size()), out(plane.size());
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      double s = 0.0;
      for (int k = -r; k <= r; ++k) s += kernel[k + r] * plane[size_t(y) * w + reflect(x + k, w)];
      tmp[size_t(y) * w + x] = s;
    }
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      double s = 0.0;
      for (int k = -r; k <= r; ++k) s += kernel[k + r] * tmp[size_t(reflect(y + k, h)) * w + x];
      out[size_t(y) * w + x] = s;
    }
  return out;
}

std::vector<double> GaussianKernel(double sigma, int radius) {
  std::vector<double> kernel(2 * radius + 1);
  double sum = 0.0;
  for (int k = -radius; k <= radius; ++k)
    sum += kernel[k + radius] = std::exp(-0.5 * k * k / (sigma * sigma));
  for (double& k : kernel) k /= sum;
  return kernel;
}

}  // namespace

std::vector<double> GaussianFilter(const std::vector<double>& plane, int width, int height, double sigma) {
  if (!(sigma > 0)) return plane;
  return Blur(plane, width, height, GaussianKernel(sigma, static_cast<int>(std::ceil(3.0 * sigma))));
}

Result<double> Psnr(const Image& a, const Image& b, const Image* mask, double data_range) {
  ICEF_ASSIGN_OR_RETURN(const int channels, CheckPair(a, b, mask, "PSNR"));
  double sum = 0.0;
  size_t count = 0;
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) {
      if (!InMask(mask, x, y)) continue;
      for (int c = 0; c < channels; ++c) {
        const double d = double(a.At(x, y, c)) - double(b.At(x, y, c));
        sum += d * d;
      }
      count += channels;
    }
  if (count == 0) return Status::Error("PSNR: the mask selects no pixel");
  const double mse = sum / double(count);
  if (mse == 0.0) return std::numeric_limits<double>::infinity();
  return 10.0 * std::log10(data_range * data_range / mse);
}

Result<double> DetailRatio(const Image& render, const Image& truth, const Image* mask) {
  ICEF_ASSIGN_OR_RETURN(const int channels, CheckPair(render, truth, mask, "detail ratio"));
  auto grey = [&](const Image& im, int x, int y) {
    double v = 0.0;
    for (int c = 0; c < channels; ++c) v += im.At(x, y, c);
    return v / channels;
  };
  auto laplacian = [&](const Image& im, int x, int y) {
    return grey(im, x - 1, y) + grey(im, x + 1, y) + grey(im, x, y - 1) + grey(im, x, y + 1) -
           4.0 * grey(im, x, y);
  };
  double e_render = 0.0, e_truth = 0.0;
  size_t count = 0;
  for (int y = 1; y + 1 < truth.height; ++y)
    for (int x = 1; x + 1 < truth.width; ++x) {
      if (!InMask(mask, x, y)) continue;
      const double lr = laplacian(render, x, y), lt = laplacian(truth, x, y);
      e_render += lr * lr, e_truth += lt * lt, ++count;
    }
  if (count == 0) return Status::Error("detail ratio: the mask selects no interior pixel");
  if (e_truth == 0.0) return Status::Error("detail ratio: the ground truth has no detail in the mask");
  return std::sqrt(e_render / e_truth);
}

Status SsimOptions::Validate() const {
  if (!(sigma > 0.0)) return Status::Error("ssim.sigma: must be > 0");
  if (radius < 1) return Status::Error("ssim.radius: must be >= 1");
  if (!(k1 > 0.0) || !(k2 > 0.0)) return Status::Error("ssim.k1/k2: must be > 0");
  if (!(data_range > 0.0)) return Status::Error("ssim.data_range: must be > 0");
  return Status::Ok();
}

std::string SsimOptions::ToString() const {
  std::ostringstream s;
  s << "SsimOptions(sigma=" << sigma << ", radius=" << radius << ", k1=" << k1 << ", k2=" << k2
    << ", data_range=" << data_range << ")";
  return s.str();
}

Result<double> Ssim(const Image& a, const Image& b, const SsimOptions& options, const Image* mask) {
  ICEF_RETURN_IF_ERROR(options.Validate());
  ICEF_ASSIGN_OR_RETURN(const int channels, CheckPair(a, b, mask, "SSIM"));
  const int r = options.radius, w = a.width, h = a.height;
  if (w < 2 * r + 1 || h < 2 * r + 1)
    return Status::Error("SSIM: image " + a.ToString() + " smaller than the " + std::to_string(2 * r + 1) +
                         "-pixel window");
  const std::vector<double> kernel = GaussianKernel(options.sigma, r);
  const double c1 = std::pow(options.k1 * options.data_range, 2),
               c2 = std::pow(options.k2 * options.data_range, 2);

  double total = 0.0;
  size_t count = 0;
  const size_t n = size_t(w) * h;
  std::vector<double> pa(n), pb(n), paa(n), pbb(n), pab(n);
  for (int c = 0; c < channels; ++c) {
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const size_t i = size_t(y) * w + x;
        pa[i] = a.At(x, y, c);
        pb[i] = b.At(x, y, c);
        paa[i] = pa[i] * pa[i];
        pbb[i] = pb[i] * pb[i];
        pab[i] = pa[i] * pb[i];
      }
    const auto ua = Blur(pa, w, h, kernel), ub = Blur(pb, w, h, kernel);
    const auto uaa = Blur(paa, w, h, kernel), ubb = Blur(pbb, w, h, kernel), uab = Blur(pab, w, h, kernel);
    for (int y = r; y < h - r; ++y)
      for (int x = r; x < w - r; ++x) {
        if (!InMask(mask, x, y)) continue;
        const size_t i = size_t(y) * w + x;
        const double va = uaa[i] - ua[i] * ua[i], vb = ubb[i] - ub[i] * ub[i], cov = uab[i] - ua[i] * ub[i];
        total += ((2.0 * ua[i] * ub[i] + c1) * (2.0 * cov + c2)) /
                 ((ua[i] * ua[i] + ub[i] * ub[i] + c1) * (va + vb + c2));
        ++count;
      }
  }
  if (count == 0) return Status::Error("SSIM: the mask selects no pixel inside the window-sized border");
  return total / double(count);
}

}  // namespace icef::eval
