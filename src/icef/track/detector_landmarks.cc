#include "icef/track/detector_landmarks.h"

namespace icef::track {

namespace {

// `icef track --calibrate-detector`:
// 12 identities, 417 views; per landmark the offset's coefficients of ViewFeatures (head units), then the
// reprojection residual in pixels at 360x480
const std::array<std::array<Vec3f, 4>, 68> kCoefficients = {{
#include "icef/track/detector_landmarks.inc"
}};

// `icef track --calibrate-detector --detector mesh`:
// 12 identities, 417 views; per landmark the offset's coefficients of ViewFeatures (head units), then the
// reprojection residual in pixels at 360x480
const std::array<std::array<Vec3f, 4>, 68> kMeshCoefficients = {{
#include "icef/track/mesh_landmarks.inc"
}};

}  // namespace

std::array<float, 4> ViewFeatures(const Vec3f& camera_head) {
  const Vec3f v = camera_head.normalized();
  return {1.f, v.x(), v.y(), v.x() * v.x()};
}

const char* LandmarkDetectorName(LandmarkDetector detector) {
  return detector == LandmarkDetector::kMesh ? "mesh" : "dlib";
}

std::array<Vec3f, 68> DetectorLandmarkOffsets(LandmarkDetector detector, const Vec3f& camera_head) {
  const auto& table = detector == LandmarkDetector::kMesh ? kMeshCoefficients : kCoefficients;
  const std::array<float, 4> f = ViewFeatures(camera_head);
  std::array<Vec3f, 68> out;
  for (int i = 0; i < 68; ++i) {
    out[i] = Vec3f::Zero();
    for (int c = 0; c < 4; ++c) out[i] += table[i][c] * f[c];
  }
  return out;
}

std::array<Vec3f, 68> DlibLandmarkOffsets(const Vec3f& camera_head) {
  return DetectorLandmarkOffsets(LandmarkDetector::kDlib, camera_head);
}

}  // namespace icef::track
