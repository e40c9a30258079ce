// The expression warp: backward displacements x_c - x of the jaw rotation and of compact bump
// terms (smile, pucker, press, brows, furrow, cheek puff). Every term is exactly zero outside its
// window, so each parameter moves only its own region. The model's ExpressionStyle scales the
// weights (ExpressionState::styled), the jaw hinge, the smile's motion and window, and the brow
// windows; the generic style multiplies by 1 and adds 0, so it reproduces the generic warp exactly.
#include <cmath>

#include "icef/core/status.h"
#include "icef/face/face_model.h"
#include "icef/face/sdf_primitives.h"

namespace icef::face {

namespace {
constexpr float kJawAnglePerUnit = 0.20f;  // radians of jaw rotation at jaw_open = 1
}  // namespace

ExpressionState FaceModel::Prepare(std::span<const float> expression) const {
  const Status valid = ValidateExpression(expression);
  ICEF_CHECK(valid.ok(), valid.message());
  const FaceGeometry& g = geometry_;
  ExpressionState s;
  float max_weight = 0.f;  // of the styled weights (every gain is > 0: zero exactly when beta is)
  for (int i = 0; i < kNumExpressions; ++i) {
    s.beta[i] = expression[i];
    s.styled[i] = expression[i] * style_.WeightGain(i);
    max_weight = std::max(max_weight, s.styled[i]);
  }
  s.neutral = max_weight == 0.f;
  s.jaw_angle = kJawAnglePerUnit * s.styled[kJawOpen];
  for (int side = 0; side < 2; ++side) {
    const float close = std::min(1.f, s.styled[side == 1 ? kEyeCloseLeft : kEyeCloseRight]);
    s.lid_upper[side] = g.lid_upper_neutral - close * (g.lid_upper_neutral - g.lid_lower);
  }
  const float jaw = s.styled[kJawOpen];
  if (jaw > 0.f) {
    const float open_y = s.jaw_angle * (g.lip_z - jaw_hinge_.z());
    const float ramp = std::min(1.f, jaw * 10.f);
    const float pucker = std::min(1.5f, s.styled[kLipPucker]);
    s.cavity = true;
    s.cavity_r = Vec3f(g.mouth_half_width * 0.9f * (1.f - 0.3f * pucker) * ramp + 1e-4f,
                       0.5f * open_y + 0.004f * ramp + 1e-4f, 0.075f);
    s.cavity_c = Vec3f(0.f, g.mouth_y - 0.5f * open_y, g.lip_z + 0.005f - 0.075f);
  }
  s.step_scale = std::clamp(0.85f / (1.f + 0.4f * max_weight), 0.35f, 0.85f);
  return s;
}

Vec3f FaceModel::JawDisplacement(const Vec3f& x, float angle, float weight_override) const {
  const FaceGeometry& g = geometry_;
  float w = weight_override;
  if (w < 0.f) {
    const float ax = std::max(0.f, std::abs(x.x()) - 0.045f);
    const float above = 0.002f + 0.6f * ax;  // the transition rises and widens towards the cheeks
    const float band = 0.022f + 1.2f * ax;
    const float t = (g.mouth_y + above - x.y()) / band;
    if (t <= 0.f) return Vec3f::Zero();
    w = SmoothStep(0.f, 1.f, t) * SmoothStep(-0.08f, 0.04f, x.z()) * SmoothStep(-0.62f, -0.42f, x.y());
  }
  if (w <= 0.f) return Vec3f::Zero();
  // Backward warp: rotate by -angle * w about the hinge's x axis (the forward motion opens the jaw:
  // the chin goes down and back).
  const float a = -angle * w;
  const float c = std::cos(a), sn = std::sin(a);
  const Vec3f r = x - jaw_hinge_;
  const Vec3f rotated(r.x(), r.y() * c - r.z() * sn, r.y() * sn + r.z() * c);
  return rotated - r;
}

Vec3f FaceModel::BumpDisplacement(const Vec3f& x, const ExpressionState& s) const {
  const FaceGeometry& g = geometry_;
  const ExpressionStyle& st = style_;
  Vec3f forward = Vec3f::Zero();  // forward motion at x; the backward displacement is its negative
  auto inv = [](float a, float b, float c) { return Vec3f(1.f / a, 1.f / b, 1.f / c); };
  for (int side = 0; side < 2; ++side) {
    const float sg = side == 0 ? -1.f : 1.f;
    const float smile = s.styled[side == 1 ? kSmileLeft : kSmileRight];
    if (smile > 0.f) {
      const Vec3f corner(sg * (g.mouth_half_width + 0.012f + st.smile_corner_shift), g.mouth_y + 0.012f,
                         g.lip_z - 0.03f);
      forward += smile * EllipsoidBump(x, corner, inv(0.09f, 0.085f, 0.09f)) *
                 Vec3f(sg * 0.018f * st.smile_width, 0.022f * st.smile_lift, -0.01f);
      forward += smile * EllipsoidBump(x, Vec3f(sg * 0.11f, -0.06f, 0.2f), inv(0.075f, 0.075f, 0.075f)) *
                 Vec3f(0.f, 0.012f * st.smile_lift, 0.008f);
    }
    const float raise = s.styled[side == 1 ? kBrowRaiseLeft : kBrowRaiseRight];
    if (raise > 0.f)
      forward += raise *
                 EllipsoidBump(x, Vec3f(g.eye_c[side].x() + sg * st.brow_raise_shift, g.brow_y, 0.25f),
                               inv(0.09f, 0.075f, 0.09f)) *
                 Vec3f(0.f, 0.022f, 0.002f);
    const float furrow = s.styled[kBrowFurrow];
    if (furrow > 0.f)
      forward += furrow *
                 EllipsoidBump(x, Vec3f(sg * 0.035f, g.brow_y - 0.005f, 0.27f), inv(0.055f, 0.05f, 0.07f)) *
                 Vec3f(-sg * 0.01f, -0.012f, 0.003f);
    const float puff = s.styled[kCheekPuff];
    if (puff > 0.f)
      forward += puff *
                 EllipsoidBump(x, Vec3f(sg * 0.115f, g.mouth_y + 0.03f, 0.18f), inv(0.085f, 0.085f, 0.09f)) *
                 Vec3f(sg * 0.02f, 0.f, 0.014f);
  }
  const Vec3f mouth(0.f, g.mouth_y, g.lip_z - 0.02f);
  const float pucker = s.styled[kLipPucker];
  if (pucker > 0.f)
    forward += pucker * EllipsoidBump(x, mouth, inv(0.085f, 0.06f, 0.08f)) *
               Vec3f(-0.3f * x.x(), -0.15f * (x.y() - g.mouth_y), 0.022f);
  const float press = s.styled[kLipPress];
  if (press > 0.f)
    forward += press * EllipsoidBump(x, mouth, inv(0.08f, 0.05f, 0.08f)) *
               Vec3f(0.f, -0.4f * (x.y() - g.mouth_y), -0.006f);
  return -forward;
}

Vec3f FaceModel::Warp(const Vec3f& x, const ExpressionState& s) const {
  if (s.neutral) return x;
  return x + JawDisplacement(x, s.jaw_angle, -1.f) + BumpDisplacement(x, s);
}

Vec3f FaceModel::InverseWarp(const Vec3f& x_c, const ExpressionState& s, float jaw_weight_override) const {
  if (s.neutral) return x_c;
  // x_c = x + D(x)  =>  x = x_c - D(x), iterated from x = x_c.
  Vec3f x = x_c;
  for (int it = 0; it < 80; ++it) {
    const Vec3f next = x_c - JawDisplacement(x, s.jaw_angle, jaw_weight_override) - BumpDisplacement(x, s);
    const float change = (next - x).squaredNorm();
    x = next;
    if (change < 1e-14f) break;
  }
  return x;
}

}  // namespace icef::face
