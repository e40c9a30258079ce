// The face's left-right symmetry plane, fitted to the 68 iBUG landmarks in the world frame: the
// few-shot prior of the trainer's symmetry loss (the auxiliary terms of docs/design.md §2.2) mirrors
// canonical-space samples across it.
//
// Fit: every landmark pair that swaps under mirroring (jaw 0-16, brows 17-26, nose 31-35, eyes
// 36-47; the mouth is left out because expressions move it asymmetrically) gives a difference
// d_i = left_i - right_i, which a mirror plane is perpendicular to. The normal n is the principal
// direction of sum_i d_i d_i^T; the offset c puts the plane through the mean of the pair midpoints
// and the midline landmarks (nose bridge 27-30, nose tip 33, chin 8). The residual is the RMS of
// |Reflect(left_i) - right_i| in units of the inter-ocular distance, so a caller can tell a
// symmetric face from an asymmetric one (or from landmarks that are wrong).
#pragma once

#include <span>
#include <string>

#include "icef/core/status.h"
#include "icef/math/types.h"

namespace icef {

class SymmetryPlane {
 public:
  SymmetryPlane() = default;
  // n is normalised; the plane is { x : n.x = offset }.
  SymmetryPlane(const Vec3f& normal, float offset);

  // From 68 world-frame landmarks. Errors: wrong count, non-finite values, coincident pairs.
  static Result<SymmetryPlane> FromLandmarks(std::span<const Vec3f> landmarks);

  // x - 2 (n.x - offset) n
  Vec3f ReflectPoint(const Vec3f& x) const { return x - 2.f * (normal_.dot(x) - offset_) * normal_; }
  // d - 2 (n.d) n
  Vec3f ReflectDirection(const Vec3f& d) const { return d - 2.f * normal_.dot(d) * normal_; }

  const Vec3f& normal() const { return normal_; }
  float offset() const { return offset_; }
  // RMS mirror error of the landmark pairs, in inter-ocular distances (0 for FromLandmarks only).
  float residual() const { return residual_; }
  std::string ToString() const;

 private:
  Vec3f normal_ = Vec3f::UnitX();
  float offset_ = 0.f;
  float residual_ = 0.f;
};

}  // namespace icef
