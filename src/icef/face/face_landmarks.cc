// The 68 iBUG-68 landmarks of the face model. Neutral positions are defined per shape by projecting
// anchor points onto the neutral surface (jaw contour: outwards from inside the head; brows, nose
// and lips: along -z from the front); eye landmarks lie on the eyelid edges and follow the lid
// angle; every landmark is then carried to the expression by the inverse warp. The inner lower-lip
// landmarks (65-67) follow the full jaw rotation, so they stay on the lower lip when the mouth opens.
#include <cmath>

#include "icef/core/status.h"
#include "icef/face/face_model.h"

namespace icef::face {

Vec3f FaceModel::ProjectNeutral(const Vec3f& origin, const Vec3f& dir) const {
  const Vec3f d = dir.normalized();
  // March until the sign changes (outside -> inside or inside -> outside), then bisect.
  const bool start_inside = CanonicalDistance(origin, neutral_state_, nullptr) < 0.f;
  float t0 = 0.f, t1 = -1.f;
  for (float t = 0.002f; t <= 2.f; t += 0.002f) {
    const bool inside = CanonicalDistance(origin + t * d, neutral_state_, nullptr) < 0.f;
    if (inside != start_inside) {
      t1 = t;
      break;
    }
    t0 = t;
  }
  ICEF_CHECK(t1 > 0.f, "landmark projection missed the head");
  for (int i = 0; i < 30; ++i) {
    const float tm = 0.5f * (t0 + t1);
    const bool inside = CanonicalDistance(origin + tm * d, neutral_state_, nullptr) < 0.f;
    (inside == start_inside ? t0 : t1) = tm;
  }
  return origin + 0.5f * (t0 + t1) * d;
}

namespace {
// A point on the eyelid shell at azimuth phi (radians, +x) whose elevation is the lid-edge angle a.
Vec3f LidPoint(const Vec3f& centre, float radius, float phi, float a) {
  return centre + radius * Vec3f(std::sin(phi), std::cos(phi) * std::tan(a), std::cos(phi)).normalized();
}
}  // namespace

void FaceModel::BuildNeutralLandmarks() {
  const FaceGeometry& g = geometry_;
  std::array<Vec3f, 68>& lm = neutral_landmarks_;
  const Vec3f back(0.f, 0.f, -1.f);
  auto front = [&](float x, float y) { return ProjectNeutral(Vec3f(x, y, 0.6f), back); };
  // 0-16: jaw contour from the subject's right (x < 0) round the chin to the left.
  const Vec3f jaw_origin(0.f, g.mouth_y + 0.07f, 0.11f);
  for (int i = 0; i <= 16; ++i) {
    const float u = (i - 8) / 8.f;
    const float theta = -1.5707963f + 1.42f * u;
    lm[i] = ProjectNeutral(jaw_origin, Vec3f(std::cos(theta), std::sin(theta), 0.25f));
  }
  // 17-21 right brow (outer to inner), 22-26 left brow (inner to outer).
  for (int j = 0; j < 5; ++j) {
    const float lx_right = 1.f - 2.f * j / 4.f;  // +1 outer ... -1 inner
    for (int side = 0; side < 2; ++side) {
      const float s = side == 0 ? -1.f : 1.f;
      const float lx = side == 0 ? lx_right : -lx_right;
      const float x = g.eye_c[side].x() + s * 0.056f * lx;
      const float y = g.brow_y + 0.011f * (1.f - lx * lx) - 0.004f * lx;
      lm[side == 0 ? 17 + j : 22 + j] = front(x, y);
    }
  }
  // 27-30 nose ridge, 31-35 nostril base.
  for (int j = 0; j < 4; ++j) {
    const float y = g.eye_c[0].y() + (g.nose_tip.y() - g.eye_c[0].y()) * j / 3.f;
    lm[27 + j] = front(0.f, y);
  }
  for (int j = 0; j < 5; ++j) {
    const float x = (j - 2) / 2.f * 0.03f * shape_.nose_width;
    lm[31 + j] = front(x, g.nose_tip.y() - 0.026f + 0.006f * std::abs(j - 2) / 2.f);
  }
  // 36-47 eyes: placeholders on the neutral lids (recomputed per expression in Landmarks()).
  // 48-59 outer lip contour, 60-67 inner contour.
  const float mw = g.mouth_half_width, lt = shape_.lip_thickness, my = g.mouth_y;
  const float upper_top = my + 0.017f * lt, lower_bottom = my - 0.019f * lt;
  lm[48] = front(-mw, my);
  lm[49] = front(-0.6f * mw, my + 0.8f * (upper_top - my));
  lm[50] = front(-0.25f * mw, upper_top);
  lm[51] = front(0.f, upper_top - 0.003f);
  lm[52] = front(0.25f * mw, upper_top);
  lm[53] = front(0.6f * mw, my + 0.8f * (upper_top - my));
  lm[54] = front(mw, my);
  lm[55] = front(0.6f * mw, my + 0.8f * (lower_bottom - my));
  lm[56] = front(0.25f * mw, lower_bottom);
  lm[57] = front(0.f, lower_bottom);
  lm[58] = front(-0.25f * mw, lower_bottom);
  lm[59] = front(-0.6f * mw, my + 0.8f * (lower_bottom - my));
  lm[60] = front(-0.85f * mw, my);
  lm[61] = front(-0.4f * mw, my + 0.003f);
  lm[62] = front(0.f, my + 0.003f);
  lm[63] = front(0.4f * mw, my + 0.003f);
  lm[64] = front(0.85f * mw, my);
  lm[65] = front(0.4f * mw, my - 0.003f);
  lm[66] = front(0.f, my - 0.003f);
  lm[67] = front(-0.4f * mw, my - 0.003f);
  const std::array<Vec3f, 68> with_eyes = Landmarks(neutral_state_);
  for (int i = 36; i <= 47; ++i) lm[i] = with_eyes[i];
}

std::array<Vec3f, 68> FaceModel::Landmarks(const ExpressionState& s) const {
  static const std::array<Vec3f, 68> kNone = [] {
    std::array<Vec3f, 68> z;
    z.fill(Vec3f::Zero());
    return z;
  }();
  return Landmarks(s, kNone);
}

std::array<Vec3f, 68> FaceModel::Landmarks(const ExpressionState& s,
                                           std::span<const Vec3f, 68> canonical_offsets) const {
  const FaceGeometry& g = geometry_;
  std::array<Vec3f, 68> canonical = neutral_landmarks_;
  // Eyes, on the lid edges at the state's lid angles. iBUG order per eye: outer corner, two upper,
  // inner corner, two lower (right eye 36-41 starts at the outer corner, left eye 42-47 at the inner).
  const float r = g.eye_r + g.lid_thickness;
  for (int side = 0; side < 2; ++side) {
    const float sg = side == 0 ? -1.f : 1.f;
    const Vec3f c = g.eye_c[side];
    const float corner_a = 0.5f * (g.lid_upper_neutral + g.lid_lower) - 0.05f;
    const Vec3f outer = LidPoint(c, r, sg * 0.78f, corner_a), inner = LidPoint(c, r, -sg * 0.72f, corner_a);
    const Vec3f up_outer = LidPoint(c, r, sg * 0.3f, s.lid_upper[side]);
    const Vec3f up_inner = LidPoint(c, r, -sg * 0.25f, s.lid_upper[side]);
    const Vec3f low_outer = LidPoint(c, r, sg * 0.3f, g.lid_lower);
    const Vec3f low_inner = LidPoint(c, r, -sg * 0.25f, g.lid_lower);
    if (side == 0) {
      canonical[36] = outer, canonical[37] = up_outer, canonical[38] = up_inner;
      canonical[39] = inner, canonical[40] = low_inner, canonical[41] = low_outer;
    } else {
      canonical[42] = inner, canonical[43] = up_inner, canonical[44] = up_outer;
      canonical[45] = outer, canonical[46] = low_outer, canonical[47] = low_inner;
    }
  }
  std::array<Vec3f, 68> out;
  for (int i = 0; i < 68; ++i) {
    const bool lower_inner_lip = i >= 65 && i <= 67;
    out[i] = InverseWarp(canonical[i] + canonical_offsets[i], s,
                         lower_inner_lip && s.jaw_angle > 0.f ? 1.f : -1.f);
  }
  return out;
}

}  // namespace icef::face
