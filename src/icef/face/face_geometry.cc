#include <cmath>

#include "icef/face/face_model.h"

namespace icef::face {

FaceGeometry FaceGeometry::FromShape(const ShapeParams& p) {
  FaceGeometry g;
  const float eye_y = 0.045f;
  const float eye_x = 0.098f * p.eye_spacing;
  g.cranium_c = Vec3f(0.f, 0.07f, -0.03f);
  g.cranium_r = Vec3f(0.265f * p.head_width, 0.32f * p.head_height, 0.335f * p.head_depth);
  g.face_c = Vec3f(0.f, -0.10f, 0.05f);
  g.face_r = Vec3f(0.212f * p.jaw_width, 0.22f, 0.215f);
  g.chin_c = Vec3f(0.f, -0.285f - 0.035f * (p.chin_length - 1.f), 0.165f);
  g.chin_r = Vec3f(0.08f * std::sqrt(p.jaw_width), 0.055f * (0.5f + 0.5f * p.chin_length), 0.06f);
  g.cheek_r = Vec3f(0.07f, 0.07f, 0.07f) * p.cheek_fullness;
  g.ear_r = Vec3f(0.022f, 0.062f, 0.04f);
  g.eye_r = 0.036f;
  g.lid_thickness = 0.0045f;
  g.brow_ridge_r = Vec3f(0.06f, 0.022f, 0.04f);
  g.brow_y = eye_y + 0.058f * p.brow_height;
  g.nostril_r = Vec3f(0.02f * p.nose_width, 0.016f, 0.02f);
  for (int side = 0; side < 2; ++side) {
    const float s = side == 0 ? -1.f : 1.f;
    g.cheek_c[side] = Vec3f(s * 0.118f * std::sqrt(p.jaw_width), -0.055f, 0.175f);
    g.ear_c[side] = Vec3f(s * 0.262f * p.head_width, eye_y - 0.045f, -0.035f);
    g.eye_c[side] = Vec3f(s * eye_x, eye_y, 0.241f);
    g.brow_ridge_c[side] = Vec3f(s * eye_x, eye_y + 0.05f * p.brow_height, 0.245f);
  }
  g.nose_top = Vec3f(0.f, eye_y + 0.005f, 0.262f + 0.012f * (p.nose_bridge - 1.f));
  g.nose_tip = Vec3f(0.f, eye_y - 0.12f * p.nose_length,
                     0.312f + 0.02f * (p.nose_bridge - 1.f) + 0.012f * (p.nose_length - 1.f));
  g.nose_top_r = 0.012f * std::sqrt(p.nose_bridge);
  g.nose_tip_r = 0.022f * p.nose_width;
  for (int side = 0; side < 2; ++side) {
    const float s = side == 0 ? -1.f : 1.f;
    g.nostril_c[side] = g.nose_tip + Vec3f(s * 0.027f * p.nose_width, -0.012f, -0.03f);
  }
  g.mouth_y = g.nose_tip.y() - 0.065f;
  g.mouth_half_width = 0.056f * p.mouth_width;
  g.lip_z = 0.285f;
  g.upper_lip_c = Vec3f(0.f, g.mouth_y + 0.011f * p.lip_thickness, 0.258f);
  g.upper_lip_r =
      Vec3f(g.mouth_half_width * 1.05f, 0.012f * p.lip_thickness, 0.028f + 0.008f * (p.lip_thickness - 1.f));
  g.lower_lip_c = Vec3f(0.f, g.mouth_y - 0.013f * p.lip_thickness, 0.253f);
  g.lower_lip_r =
      Vec3f(g.mouth_half_width * 0.95f, 0.014f * p.lip_thickness, 0.029f + 0.008f * (p.lip_thickness - 1.f));
  g.neck_a = Vec3f(0.f, -0.18f, -0.045f);
  g.neck_b = Vec3f(0.f, -0.9f, -0.06f);
  g.neck_r = 0.14f;
  g.neck_cut_y = -0.8f;
  g.jaw_hinge = Vec3f(0.f, eye_y - 0.06f, -0.045f);
  g.lid_upper_neutral = 0.38f;
  g.lid_lower = -0.32f;
  return g;
}

}  // namespace icef::face
