// Where dlib's 68-point detector puts its landmarks on the face model: renders of validation
// identities (seeds 101+, generic expression style, neutral) from a grid of views are run through
// the detector, and each landmark's offset from the face model's own landmark (canonical head frame)
// is fitted, over all views and identities, as a linear function of the viewing direction
// (track/detector_landmarks.h: dlib's bias changes as the head turns), by Gauss-Newton on the
// pixel residuals through the known cameras with a small ridge on the coefficients.
// `icef track --calibrate-detector` prints the table that track/detector_landmarks.inc holds.
#pragma once

#include <array>
#include <ostream>
#include <vector>

#include "icef/core/parallel.h"
#include "icef/core/status.h"
#include "icef/math/types.h"

namespace icef {

struct DetectorCalibration {
  // Per landmark, the offset's coefficients of track::ViewFeatures (head units).
  std::array<std::array<Vec3f, 4>, 68> coefficients{};
  std::array<double, 68> residual_px{};  // mean reprojection residual per landmark (pixels)
  int identities = 0, views = 0;
};

// mesh: calibrate the face mesh's 68 landmarks (DetectFaceWithMesh) instead of dlib's.
Result<DetectorCalibration> CalibrateDetector(const std::vector<uint64_t>& seeds, const Executor& executor,
                                              std::ostream* log = nullptr, bool mesh = false);

// The table as C++ (track/detector_landmarks.inc, the body of detector_landmarks.cc's array).
void PrintDetectorTable(const DetectorCalibration& calibration, std::ostream& out);

}  // namespace icef
