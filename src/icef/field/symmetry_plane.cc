#include "icef/field/symmetry_plane.h"

#include <Eigen/Dense>
#include <cmath>
#include <sstream>
#include <utility>

namespace icef {
namespace {

// iBUG 68 pairs that swap under left-right mirroring (mouth left out, see the header).
constexpr std::pair<int, int> kMirrorPairs[] = {
    {0, 16},  {1, 15},  {2, 14},  {3, 13},  {4, 12},  {5, 11},  {6, 10}, {7, 9},  // jaw
    {17, 26}, {18, 25}, {19, 24}, {20, 23}, {21, 22},                             // brows
    {31, 35}, {32, 34},                                                           // nostrils
    {36, 45}, {37, 44}, {38, 43}, {39, 42}, {40, 47}, {41, 46},                   // eyes
};
constexpr int kMidline[] = {8, 27, 28, 29, 30, 33};

}  // namespace

SymmetryPlane::SymmetryPlane(const Vec3f& normal, float offset)
    : normal_(normal.normalized()), offset_(offset) {}

Result<SymmetryPlane> SymmetryPlane::FromLandmarks(std::span<const Vec3f> landmarks) {
  if (landmarks.size() != 68)
    return Status::Error("symmetry plane: need 68 landmarks, got " + std::to_string(landmarks.size()));
  for (size_t i = 0; i < landmarks.size(); ++i)
    if (!landmarks[i].allFinite())
      return Status::Error("symmetry plane: landmark " + std::to_string(i) + " is not finite");
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const auto& [l, r] : kMirrorPairs) {
    const Eigen::Vector3d d = (landmarks[l] - landmarks[r]).cast<double>();
    scatter += d * d.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(scatter);
  const Eigen::Vector3d values = eig.eigenvalues();  // ascending
  if (!(values(2) > 0) || values(1) > 0.5 * values(2))
    return Status::Error("symmetry plane: the landmark pairs do not share one left-right direction");
  Eigen::Vector3d n = eig.eigenvectors().col(2);
  // Orient n from the right-hand landmarks (low indices) to the left-hand ones, for a stable sign.
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const auto& [l, r] : kMirrorPairs) sum += (landmarks[r] - landmarks[l]).cast<double>();
  if (n.dot(sum) < 0) n = -n;
  double offset = 0;
  int count = 0;
  for (const auto& [l, r] : kMirrorPairs) {
    offset += n.dot(0.5 * (landmarks[l] + landmarks[r]).cast<double>());
    ++count;
  }
  for (int m : kMidline) {
    offset += n.dot(landmarks[m].cast<double>());
    ++count;
  }
  SymmetryPlane plane(n.cast<float>(), static_cast<float>(offset / count));
  const Vec3f eye_r = (landmarks[36] + landmarks[39]) * 0.5f, eye_l = (landmarks[42] + landmarks[45]) * 0.5f;
  const float iod = (eye_l - eye_r).norm();
  if (!(iod > 0)) return Status::Error("symmetry plane: the eye centres coincide");
  double sq = 0;
  for (const auto& [l, r] : kMirrorPairs)
    sq += (plane.ReflectPoint(landmarks[l]) - landmarks[r]).squaredNorm();
  plane.residual_ = static_cast<float>(std::sqrt(sq / std::size(kMirrorPairs)) / iod);
  return plane;
}

std::string SymmetryPlane::ToString() const {
  std::ostringstream os;
  os.precision(4);
  os << "SymmetryPlane(n=[" << normal_.x() << ", " << normal_.y() << ", " << normal_.z()
     << "], offset=" << offset_ << ", residual=" << residual_ << " iod)";
  return os.str();
}

}  // namespace icef
