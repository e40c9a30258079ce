// Renders whole images from an AvatarModel at one expression: s x s rays per pixel on a regular
// sub-pixel grid (s = the model config's render.supersample; 1 = the pixel centre), averaged.
#pragma once

#include <span>

#include "icef/io/image.h"
#include "icef/math/camera.h"
#include "icef/model/avatar_model.h"

namespace icef {

struct RenderedImage {
  Image color;                    // RGB over the background
  Image depth;                    // 1 channel, expected depth (world units; 0 where nothing is hit)
  Image opacity;                  // 1 channel
  Image mask;                     // 1 channel: expected region mask M along each ray
  Image deformation;              // 1 channel: expected ||D_final(x) - x|| (world units)
  NearestExpression nearest;      // beta_n, delta, kappa of the expression
  int64_t samples_evaluated = 0;  // field evaluations (all sub-pixel rays)
};

// Which occupancy grid places the samples: the one built for the rendered expression
// (AvatarModel::RenderOccupancy, the default) or the training grid as it is (training expressions
// only, cut to the training visual hull: clips geometry a far expression moves; for comparisons).
enum class RenderOccupancyMode { kExpression, kTraining };

RenderedImage RenderImage(const AvatarModel& model, const Camera& camera, std::span<const float> beta,
                          const Vec3f& background, const Executor& executor,
                          RenderOccupancyMode occupancy = RenderOccupancyMode::kExpression);

// Maps a 1-channel image to RGB for viewing: values over [lo, hi] through a perceptual colour map
// (viridis-like); hi <= lo uses the image's own range.
Image ColorizeScalar(const Image& scalar, float lo, float hi);

// Mean squared error and PSNR of two RGB images of the same size.
double MeanSquaredError(const Image& a, const Image& b);
double PsnrFromMse(double mse);

}  // namespace icef
