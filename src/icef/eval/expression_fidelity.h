// Expression fidelity (docs/design.md §6, docs/evaluation.md): how much of a test frame's expression a
// render reproduces, measured against the ground truth inside the frame's expression region.
//
// - Expression region: the pixels within `dilation` pixels of the 2D convex hull of the frame's
//   ground-truth landmarks of brows, eyes and mouth (iBUG 17–26, 36–67), united with the same
//   hull of its neutral's landmarks (same view, expression zero).
// - With m = render − the model's neutral render (same view) and t = ground truth − ground-truth
//   neutral, both over the RGB values of the region's pixels:
//     expr_gain = <m, t> / <t, t>   (1 = the expression at full strength, 0 = none, < 0 = the
//                                    opposite way, > 1 = exaggerated)
//     expr_corr = <m, t> / (|m| |t|) (cosine; null when the model's change is exactly zero)
//     expr_gain_coarse = expr_gain with m and t each first filtered by a Gaussian of `coarse_sigma`
//                        pixels (DefaultCoarseSigma: 2 px at 128): the expression at the scale of the
//                        features, where a render that is merely softer than the truth still scores
//                        nearly 1 (the truth blurred by 1 px: 0.3-0.5 on pixels, about 0.9 here)
// - A frame whose true change is negligible (RMS of t over the region below
//   kNegligibleExpressionRms) gets no gain or cosine: they would divide by nearly nothing.
// - Face region (FaceRegion): the filled hull of all 68 landmarks, for the training-view fit
//   (eval/evaluate.h).
#pragma once

#include <optional>
#include <vector>

#include "icef/core/status.h"
#include "icef/data/landmark_region.h"
#include "icef/io/image.h"
#include "icef/math/types.h"

namespace icef::eval {

// RMS (per RGB value, [0, 1] units) below which a frame's true change counts as negligible.
constexpr double kNegligibleExpressionRms = 0.004;

// The region geometry lives in data/landmark_region.h (training draws rays from the same region).
using ::icef::DefaultRegionDilation;
using ::icef::ExpressionLandmarkIndices;
using ::icef::ExpressionRegion;

// Default Gaussian sigma (pixels) of expr_gain_coarse for an image `width` wide: 2 px at 128, scaled.
double DefaultCoarseSigma(int width);

// 1-channel mask (1 inside, 0 outside) of the face region: the pixels whose centres (+0.5) lie in
// or on the filled 2D convex hull of all finite landmarks (the 68 points, jaw line included;
// visibility flags are not consulted: an occluded point still projects onto the face):
// LandmarkHullRegion.
Image FaceRegion(int width, int height, const std::vector<Vec2f>& landmarks);

struct ExpressionFidelity {
  int pixels = 0;          // pixels in the region
  double true_rms = 0;     // RMS of t over the region's RGB values
  bool negligible = true;  // true_rms < kNegligibleExpressionRms: gain and corr are null
  std::optional<double> gain;
  std::optional<double> corr;
  std::optional<double> gain_coarse;  // with m and t low-passed (null with the gain, or coarse_sigma <= 0)
};

// All four images RGB (or RGBA, alpha ignored) of the region's size. Errors: size mismatches.
Result<ExpressionFidelity> MeasureExpression(const Image& render, const Image& render_neutral,
                                             const Image& truth, const Image& truth_neutral,
                                             const Image& region, double coarse_sigma = 0);

}  // namespace icef::eval
