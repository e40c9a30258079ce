// The eyelid slide of PriorWarp (face_model.h): closing lids as a warp of the neutral lids.
#include <cmath>

#include "icef/face/face_model.h"
#include "icef/face/sdf_primitives.h"

namespace icef::face {

namespace {
constexpr float kTop = 1.5707963f;  // elevation of the top of the eye (straight up)
}  // namespace

Vec3f FaceModel::LidSlide(const Vec3f& x_c, const ExpressionState& s) const {
  const FaceGeometry& g = geometry_;
  const int side = x_c.x() < 0.f ? 0 : 1;
  const float edge = s.lid_upper[side], neutral = g.lid_upper_neutral;
  if (edge >= neutral) return x_c;  // open (or more open): nothing covers the eyeball
  const Vec3f q = x_c - g.eye_c[side];
  const float r = q.norm();
  const float shell = g.eye_r + g.lid_thickness;
  // The lid's own thickness and the blend with the skin around it (face_sdf.cc: 0.006), then a falloff.
  const float weight = 1.f - SmoothStep(shell + 0.004f, shell + 0.012f, r);
  if (weight <= 0.f || q.z() <= 0.f) return x_c;
  const float theta = std::atan2(q.y(), q.z());
  if (theta < edge || theta > kTop) return x_c;
  const float mapped = neutral + (theta - edge) * (kTop - neutral) / (kTop - edge);
  const float a = weight * (mapped - theta);
  const float c = std::cos(a), sn = std::sin(a);
  // Rotation about the x axis through the eye centre raising the elevation by a.
  const Vec3f rotated(q.x(), q.y() * c + q.z() * sn, -q.y() * sn + q.z() * c);
  return g.eye_c[side] + rotated;
}

Vec3f FaceModel::PriorWarp(const Vec3f& x, const ExpressionState& s) const {
  if (s.neutral) return x;
  return LidSlide(Warp(x, s), s);
}

}  // namespace icef::face
