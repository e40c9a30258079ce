// The head's signed distance: a smooth union of ellipsoids and cones (cranium, face, chin,
// cheeks, ears, neck, brow ridges, nose, lips), eye sockets with eyeballs and eyelid caps, and the
// mouth cavity carved in observation space.
#include <cmath>
#include <sstream>

#include "icef/core/status.h"
#include "icef/face/face_model.h"
#include "icef/face/sdf_primitives.h"

namespace icef::face {

FaceModel::FaceModel(const ShapeParams& shape, const ExpressionStyle& style)
    : shape_(shape), style_(style), geometry_(FaceGeometry::FromShape(shape)) {
  const Status valid = style.Validate();
  ICEF_CHECK(valid.ok(), valid.message());
  jaw_hinge_ = geometry_.jaw_hinge + Vec3f(0.f, style.jaw_hinge_dy, style.jaw_hinge_dz);
  neutral_state_ = Prepare(std::vector<float>(kNumExpressions, 0.f));
  BuildNeutralLandmarks();
}

Aabb FaceModel::Bounds() const {
  Aabb box;
  box.min = Vec3f(-0.36f, -0.81f, -0.42f);
  box.max = Vec3f(0.36f, 0.45f, 0.45f);
  return box;
}

float FaceModel::CanonicalDistance(const Vec3f& p, const ExpressionState& s, Material* material) const {
  const FaceGeometry& g = geometry_;
  float d = SmoothMin(SdEllipsoid(p - g.cranium_c, g.cranium_r), SdEllipsoid(p - g.face_c, g.face_r), 0.07f);
  d = SmoothMin(d, SdEllipsoid(p - g.chin_c, g.chin_r), 0.05f);
  const float neck = std::max(SdCone(p, g.neck_a, g.neck_b, g.neck_r, g.neck_r), g.neck_cut_y - p.y());
  d = SmoothMin(d, neck, 0.06f);
  // Far from the face the details (which protrude < 0.07 from the base) cannot be the closest part.
  if (d > 0.12f && material == nullptr) return d - 0.08f;
  const float sx = std::abs(p.x());
  const int near_side = p.x() < 0.f ? 0 : 1;
  const Vec3f pm(sx, p.y(), p.z());  // mirrored to the left side for symmetric parts
  d = SmoothMin(d, SdEllipsoid(pm - g.cheek_c[1], g.cheek_r), 0.05f);
  d = SmoothMin(d, SdEllipsoid(pm - g.ear_c[1], g.ear_r), 0.015f);
  d = SmoothMin(d, SdEllipsoid(pm - g.brow_ridge_c[1], g.brow_ridge_r), 0.03f);
  // Nose: bridge cone, tip, nostril wings.
  float nose = SdCone(p, g.nose_top, g.nose_tip, g.nose_top_r, g.nose_tip_r * 0.8f);
  nose = SmoothMin(nose, SdSphere(p - g.nose_tip, g.nose_tip_r), 0.015f);
  nose = SmoothMin(nose, SdEllipsoid(pm - g.nostril_c[1], g.nostril_r), 0.012f);
  d = SmoothMin(d, nose, 0.025f);
  // Lips.
  const float lips = std::min(SdEllipsoid(p - g.upper_lip_c, g.upper_lip_r), SdEllipsoid(p - g.lower_lip_c, g.lower_lip_r));
  d = SmoothMin(d, lips, 0.012f);
  // Eye socket of the nearer eye (the two sockets are far apart), then the eyeball and the lids.
  const Vec3f q = p - g.eye_c[near_side];
  d = SmoothMax(d, -SdSphere(q - Vec3f(0.f, 0.f, 0.006f), g.eye_r + 0.009f), 0.012f);
  const float eyeball = SdSphere(q, g.eye_r);
  const float shell = q.norm() - (g.eye_r + g.lid_thickness);
  const float a_up = s.lid_upper[near_side], a_low = g.lid_lower;
  const float upper_lid = std::max(shell, -(q.y() * std::cos(a_up) - q.z() * std::sin(a_up)));
  const float lower_lid = std::max(shell, q.y() * std::cos(a_low) - q.z() * std::sin(a_low));
  const float lid = std::min(upper_lid, lower_lid);
  const float skin = d;
  d = SmoothMin(d, lid, 0.006f);
  d = std::min(d, eyeball);
  if (material) {
    if (eyeball <= d + 1e-6f && eyeball < lid - 1e-4f)
      *material = Material::kEyeball;
    else if (lid < skin && lid < 0.01f && q.norm() < g.eye_r + 0.02f)
      *material = Material::kEyelid;
    else
      *material = Material::kSkin;
  }
  return d;
}

float FaceModel::Distance(const Vec3f& x, const ExpressionState& s) const {
  const Vec3f x_c = Warp(x, s);
  float d = CanonicalDistance(x_c, s, nullptr);
  if (s.cavity) d = SmoothMax(d, -SdEllipsoid(x - s.cavity_c, s.cavity_r), 0.004f);
  return d;
}

FaceModel::Sample FaceModel::Evaluate(const Vec3f& x, const ExpressionState& s) const {
  Sample out;
  out.canonical = Warp(x, s);
  out.material = Material::kSkin;
  out.distance = CanonicalDistance(out.canonical, s, &out.material);
  if (s.cavity) {
    const float carve = -SdEllipsoid(x - s.cavity_c, s.cavity_r);
    if (carve > out.distance - 0.002f) out.material = Material::kMouthCavity;
    out.distance = SmoothMax(out.distance, carve, 0.004f);
  }
  return out;
}

Vec3f FaceModel::Normal(const Vec3f& x, const ExpressionState& s) const {
  const float h = 4e-4f;
  const Vec3f k0(1.f, -1.f, -1.f), k1(-1.f, -1.f, 1.f), k2(-1.f, 1.f, -1.f), k3(1.f, 1.f, 1.f);
  const Vec3f n = k0 * Distance(x + h * k0, s) + k1 * Distance(x + h * k1, s) + k2 * Distance(x + h * k2, s) +
                  k3 * Distance(x + h * k3, s);
  const float len = n.norm();
  return len > 0.f ? Vec3f(n / len) : Vec3f::UnitZ();
}

float FaceModel::Trace(const Ray& ray, float t_near, float t_far, const ExpressionState& s, int max_steps,
                       float epsilon) const {
  float t = t_near;
  for (int i = 0; i < max_steps && t <= t_far; ++i) {
    const float d = Distance(ray.At(t), s);
    if (d < epsilon) return t;
    t += std::max(d * s.step_scale, 0.5f * epsilon);
  }
  return -1.f;
}

std::string FaceModel::ToString() const {
  return "FaceModel(" + shape_.ToString() + ", " + style_.ToString() + ")";
}

}  // namespace icef::face
