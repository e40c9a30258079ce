// Fitting the face model to a subject (docs/design.md §2.1): shape parameters shared by all frames and
// one similarity transform head_from_world (dataset world frame -> head frame), from the 68
// landmarks of frames whose expressions are known (weights in the face model's expression order).
// Landmarks are 3D (world frame) when a frame has them, else 2D (pixels) reprojected through the
// frame's calibrated camera. Robust nonlinear least squares (Ceres, Levenberg-Marquardt): residuals
// in inter-ocular distances (IOD), a Gaussian plausibility prior on the shape scales around the
// average head, and a second pass without the landmarks the first pass left far off (outliers).
// Optionally (fit_style) the subject's expression style too (face/expression_style.h): its gains and
// offsets, each with a prior around the generic style, read off the landmarks of the frames whose
// expressions use them; a field no frame's expression moves keeps its generic value. The fitted
// style is kept only where it explains the landmarks clearly better than the generic one.
#pragma once

#include <optional>
#include <span>
#include <string>
#include <vector>

#include "icef/core/status.h"
#include "icef/face/expression_style.h"
#include "icef/face/shape_params.h"
#include "icef/math/camera.h"
#include "icef/math/types.h"

namespace icef::face {

// x_head = scale * rotation * x_world + translation.
struct Similarity {
  double scale = 1.0;
  Mat3d rotation = Mat3d::Identity();
  Vec3d translation = Vec3d::Zero();

  Vec3d Apply(const Vec3d& x_world) const { return scale * (rotation * x_world) + translation; }
  Vec3d ApplyInverse(const Vec3d& x_head) const {
    return rotation.transpose() * (x_head - translation) / scale;
  }
  std::string ToString() const;
};

// One frame of the fit: its expression and its landmarks (3D, else 2D with the camera).
struct FitFrame {
  std::vector<float> expression;                   // [kNumExpressions], face-model order
  std::optional<std::vector<Vec3f>> landmarks_3d;  // [68] world frame
  std::optional<std::vector<Vec2f>> landmarks_2d;  // [68] pixels
  std::optional<Camera> camera;                    // needed with landmarks_2d only
};

struct FaceFitOptions {
  double shape_prior_sigma = 0.15;   // std of each shape scale around 1 (the plausibility prior)
  bool fit_shape = true;             // false: the average head, similarity only
  int max_iterations = 60;           // Levenberg-Marquardt iterations per pass
  double outlier_iod = 0.08;         // second pass: drop landmarks farther than this (IOD) and 3x the median
  bool fit_style = false;            // also fit the expression style (else the generic one)
  double style_gain_sigma = 1.0;     // std of each style gain's log around 0 (generic: gain 1)
  double style_offset_sigma = 0.03;  // std of each style offset around 0 (head units)
  // The fitted style is kept when it explains the landmarks better than the generic style's fit
  // (which is fitted too) by an F statistic of at least this (its 17 fields against the noise left
  // over; 3 is past the 0.1 % point of F(17, 300+)); else the fit keeps the generic style.
  double style_min_f = 3.0;

  Status Validate() const;
  std::string ToString() const;
};

struct FaceFit {
  ShapeParams shape;
  ExpressionStyle style;             // generic unless FaceFitOptions::fit_style
  double generic_style_rms_iod = 0;  // with fit_style: the RMS of the fit in the generic style
  double style_f = 0;                // with fit_style: the F statistic of the style's fields
  bool style_rejected = false;       // with fit_style: F below style_min_f, the generic style kept
  double sum_squares = 0;            // sum of the inlier landmarks' squared errors (IOD^2)
  int residual_count = 0;            // inlier landmark coordinates (3 per 3D landmark, 2 per 2D)
  Similarity head_from_world;
  double rms_iod = 0;      // RMS landmark residual of the final pass (inter-ocular distances)
  double max_iod = 0;      // largest landmark residual
  int landmarks_used = 0;  // after outlier removal
  int landmarks_total = 0;
  int iterations = 0;

  // A fit worth warning about: RMS above 0.1 IOD.
  bool Poor() const { return rms_iod > 0.1; }
  std::string BriefReport() const;
};

// The inter-ocular distance of landmarks (distance between the centres of 36-41 and 42-47).
double InterOcularDistance(std::span<const Vec3f> landmarks);

// Errors: no frames, a frame with a wrong expression size or negative/non-finite weights, no
// landmarks, a 2D frame without a camera, invalid options, a solve that fails.
Result<FaceFit> FitFaceModel(std::span<const FitFrame> frames, const FaceFitOptions& options = {});

}  // namespace icef::face
