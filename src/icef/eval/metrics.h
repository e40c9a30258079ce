// Full-reference image metrics on [0, 1] images (docs/design.md §6).
//
// Both images must have the same size and channel count; RGB and RGBA images are compared on
// their RGB channels (composite RGBA over a background first if alpha matters), grey images on
// their one channel. A mask (same size; its first channel is read) restricts a metric to the
// pixels where mask > 0.5: PSNR averages the squared error over them, SSIM averages its map over
// them (within the interior where the window fits, as below).
#pragma once

#include <string>
#include <vector>

#include "icef/core/status.h"
#include "icef/io/image.h"

namespace icef::eval {

// PSNR in dB: 10 log10(data_range^2 / MSE), MSE over pixels and compared channels. +infinity
// when the images are identical (as skimage's peak_signal_noise_ratio).
Result<double> Psnr(const Image& a, const Image& b, const Image* mask = nullptr, double data_range = 1.0);

struct SsimOptions {
  double sigma = 1.5;       // Gaussian window standard deviation, pixels
  int radius = 5;           // window half-width: int(3.5 * sigma + 0.5) = 5 gives skimage's 11 taps
  double k1 = 0.01;         // luminance stabiliser: C1 = (k1 * data_range)^2
  double k2 = 0.03;         // contrast stabiliser: C2 = (k2 * data_range)^2
  double data_range = 1.0;  // value range of the images
  Status Validate() const;
  std::string ToString() const;
};

// Mean SSIM with skimage's conventions (structural_similarity with gaussian_weights=True,
// sigma=1.5, use_sample_covariance=False, data_range=1): local means, variances and covariance
// from a normalised Gaussian window (population statistics), the SSIM map averaged over the
// pixels at least `radius` from the border, then over channels. Images must be at least
// 2 * radius + 1 pixels in each dimension; a mask with no pixel in that interior is an error.
Result<double> Ssim(const Image& a, const Image& b, const SsimOptions& options = {},
                    const Image* mask = nullptr);

// One image plane [h, w] (row-major) filtered by a normalised Gaussian of `sigma` pixels (taps to
// ceil(3 sigma)), separably, with scipy's 'reflect' boundary. sigma <= 0: the plane unchanged.
std::vector<double> GaussianFilter(const std::vector<double>& plane, int width, int height, double sigma);

// Fine detail of `render` relative to `truth`: sqrt(E(render) / E(truth)), E the mean squared
// Laplacian (4-neighbour, of the mean over compared channels) over the masked pixels at least one
// pixel from the border. 1: as much pixel-scale detail as the truth; below 1: detail blurred away
// (0.5: half the amplitude); above 1: more edges than the truth (blocks, noise). Errors: a size
// mismatch, no masked interior pixel, or a truth without detail (E = 0).
Result<double> DetailRatio(const Image& render, const Image& truth, const Image* mask = nullptr);

}  // namespace icef::eval
