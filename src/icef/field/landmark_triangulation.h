// Triangulation of the 68 facial landmarks from their 2D positions in K calibrated views
// (docs/design.md §2, expression-region mask): a linear least-squares (DLT) solution per landmark,
// optionally refined by Gauss-Newton on the reprojection error. Cameras follow math/camera.h (NeRF
// convention); 2D landmarks are image coordinates with pixel centres at +0.5 (Camera::Project).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "icef/core/status.h"
#include "icef/data/dataset.h"
#include "icef/math/camera.h"
#include "icef/math/types.h"

namespace icef {

struct TriangulationOptions {
  bool refine = true;       // Gauss-Newton refinement of the reprojection error after the DLT
  int max_iterations = 10;  // Gauss-Newton iterations (each stops early once the step is tiny)
  int min_views = 2;        // landmarks seen in fewer views are an error

  Status Validate() const;
  std::string ToString() const;
};

// One observation of a point: the camera and the image coordinates (pixels).
struct PointObservation {
  const Camera* camera;
  Vec2d uv;
};

// Linear least squares: each view contributes two equations linear in the point (rows scaled by
// 1/focal so all views weigh alike). nullopt when the system is degenerate (e.g. all centres on
// one ray) or fewer than 2 observations.
std::optional<Vec3d> TriangulateLinear(const std::vector<PointObservation>& observations);

// Gauss-Newton on sum |Project(p) - uv|^2 starting from `initial`; returns the refined point, or
// `initial` when a step would put the point behind a camera.
Vec3d RefineReprojection(const std::vector<PointObservation>& observations, const Vec3d& initial,
                         int max_iterations);

// Reprojection residual Project(p) - uv and its Jacobian w.r.t. p (2x3); nullopt behind the camera.
struct ReprojectionResidual {
  Vec2d residual;
  Eigen::Matrix<double, 2, 3> jacobian;
};
std::optional<ReprojectionResidual> ReprojectionResidualAt(const PointObservation& observation,
                                                           const Vec3d& p);

struct TriangulatedLandmarks {
  std::vector<Vec3f> points;             // [68] world frame
  std::vector<int> num_views;            // [68] views the landmark was visible in
  std::vector<double> rms_reprojection;  // [68] pixels
  double MeanRms() const;
  std::string ToString() const;
};

// Triangulates the 68 landmarks from `frames` that carry landmarks_2d (frames without are skipped;
// landmarks flagged invisible in landmarks_2d_visible are ignored). Errors name the landmark when
// it is seen in fewer than min_views views or lies behind a camera.
Result<TriangulatedLandmarks> TriangulateLandmarks(const std::vector<Frame>& frames,
                                                   const TriangulationOptions& options = {});

}  // namespace icef
