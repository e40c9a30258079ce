// The head's albedo, a function of the canonical (neutral) point so that it moves with every
// expression: skin tone, low-frequency blotches, cheek flush, pores, freckles, moles, lips, brows as
// hair strokes, scalp hair, eyes (sclera, iris, pupil), eyelids with lashes and the mouth cavity.
#include <cmath>

#include "icef/face/sdf_primitives.h"
#include "icef/synth/head_model.h"
#include "icef/synth/noise.h"

namespace icef::synth {

using face::EllipsoidBump;
using face::ExpressionState;
using face::Material;
using face::SmoothStep;

namespace {
Vec3f Mix(const Vec3f& a, const Vec3f& b, float t) { return a + t * (b - a); }
}  // namespace

Vec3f HeadModel::Albedo(const face::FaceModel::Sample& sample, const Vec3f& x,
                        const ExpressionState& state) const {
  const Vec3f& p = sample.canonical;
  switch (sample.material) {
    case Material::kEyeball:
      return EyeAlbedo(p, p.x() < 0.f ? 0 : 1);
    case Material::kEyelid:
      return LidAlbedo(p, state);
    case Material::kMouthCavity:
      return CavityAlbedo(x, state);
    case Material::kSkin:
      break;
  }
  return SkinAlbedo(p);
}

Vec3f HeadModel::SkinAlbedo(const Vec3f& p) const {
  const IdentityParams& id = identity_;
  const face::FaceGeometry& g = face_.geometry();
  const uint32_t seed = id.detail_seed;
  Vec3f c = id.skin_tone;
  // Low-frequency blotches and a cheek flush.
  const float b1 = FractalNoise(p * 6.f, seed, 3);
  const float b2 = FractalNoise(p * 11.f + Vec3f(3.1f, 7.7f, 1.3f), seed + 1u, 2);
  c *= 1.f + 0.10f * id.blotch_strength * b1;
  c += id.blotch_strength * 0.045f * b2 * Vec3f(1.f, -0.45f, -0.45f);
  const Vec3f pm(std::abs(p.x()), p.y(), p.z());
  const float flush = EllipsoidBump(pm, Vec3f(0.12f, -0.05f, 0.21f), Vec3f::Constant(1.f / 0.08f));
  c = c.cwiseProduct(Vec3f::Ones() + flush * Vec3f(0.05f, -0.09f, -0.08f));
  // Pores: high-frequency darkening at two scales.
  const float pores = std::max(0.f, ValueNoise(p * (160.f * id.pore_scale), seed + 2u)) +
                      0.5f * std::max(0.f, ValueNoise(p * (85.f * id.pore_scale), seed + 3u));
  c *= 1.f - 0.07f * id.pore_strength * pores;
  // Fine wrinkles: wavy horizontal lines across the forehead and fans at the outer eye corners.
  if (id.wrinkle_strength > 0.f && p.z() > 0.1f) {
    const float forehead = SmoothStep(g.brow_y + 0.02f, g.brow_y + 0.05f, p.y()) *
                           (1.f - SmoothStep(g.eye_c[0].y() + 0.14f, g.eye_c[0].y() + 0.18f, p.y())) *
                           (1.f - SmoothStep(0.09f, 0.14f, std::abs(p.x())));
    const float wave = p.y() * 330.f + 2.5f * ValueNoise(Vec3f(p.x() * 18.f, 0.f, 1.f), seed + 7u);
    const float line = std::pow(std::max(0.f, std::cos(wave)), 24.f);
    const Vec3f corner(g.eye_c[1].x() + 0.045f, g.eye_c[1].y(), 0.f);
    const Vec3f q(std::abs(p.x()) - corner.x(), p.y() - corner.y(), 0.f);
    const float fan = (1.f - SmoothStep(0.012f, 0.03f, q.norm())) * SmoothStep(0.f, 0.006f, q.x());
    const float fan_line = std::pow(std::max(0.f, std::cos(std::atan2(q.y(), q.x()) * 22.f)), 12.f);
    c *= 1.f - id.wrinkle_strength * (0.16f * forehead * line + 0.14f * fan * fan_line);
  }
  // Stubble: dense fine dark dots over the upper lip, chin and jaw.
  if (id.stubble_density > 0.f && p.z() > 0.f) {
    const float below_nose = 1.f - SmoothStep(g.mouth_y + 0.03f, g.mouth_y + 0.045f, p.y());
    const float cheek_edge =
        1.f - SmoothStep(g.mouth_y + 0.0f, g.mouth_y + 0.06f, p.y() + 0.5f * std::abs(p.x()));
    const float zone = below_nose * std::max(cheek_edge, 1.f - SmoothStep(0.04f, 0.07f, std::abs(p.x())));
    if (zone > 0.f) {
      const float dots = CellSpots(p, 380.f, id.stubble_density * zone, seed + 8u);
      c = Mix(c, id.hair_color * 0.6f, 0.7f * dots);
    }
  }
  // Freckles over the cheeks and the nose.
  const float freckle_zone =
      p.z() > 0.12f ? EllipsoidBump(p, Vec3f(0.f, -0.02f, 0.26f), Vec3f(1.f / 0.19f, 1.f / 0.1f, 1.f / 0.2f))
                    : 0.f;
  if (freckle_zone > 0.f) {
    const float spots =
        CellSpots(p, 55.f, id.freckle_density * std::min(1.f, 1.6f * freckle_zone), seed + 4u);
    c = Mix(c, c.cwiseProduct(Vec3f(0.72f, 0.58f, 0.48f)), 0.75f * spots);
  }
  // Moles.
  for (size_t m = 0; m < moles_.size(); ++m) {
    const float r = (p - moles_[m]).norm() / mole_radii_[m];
    if (r < 1.f) c = Mix(c, Vec3f(0.25f, 0.15f, 0.11f), 1.f - SmoothStep(0.55f, 1.f, r));
  }
  // Scalp hair above a hairline that drops from the forehead to the back of the head.
  const float front = SmoothStep(0.02f, 0.22f, p.z());
  const float temple = 0.05f * SmoothStep(0.1f, 0.2f, std::abs(p.x()));
  const float hair_y = (1.f - front) * (0.035f) + front * (g.eye_c[0].y() + 0.19f + id.hairline) - temple;
  float hair = SmoothStep(hair_y - 0.012f, hair_y + 0.012f, p.y());
  const float ear = EllipsoidBump(pm, g.ear_c[1], g.ear_r.cwiseInverse() * 0.8f);
  hair *= 1.f - std::min(1.f, 4.f * ear);
  if (hair > 0.f) {
    const float strands = ValueNoise(Vec3f(p.x() * 260.f, p.y() * 18.f, p.z() * 260.f), seed + 5u);
    const Vec3f hc = id.hair_color * (0.8f + 0.35f * strands);
    c = Mix(c, hc, hair);
  }
  if (ear > 0.f) c = c.cwiseProduct(Vec3f::Ones() + std::min(1.f, 2.f * ear) * Vec3f(0.04f, -0.06f, -0.06f));
  // Lips.
  if (p.z() > g.lip_z - 0.06f && std::abs(p.x()) < g.mouth_half_width * 1.1f) {
    const float lt = id.shape.lip_thickness;
    const float bow = 0.003f * std::exp(-p.x() * p.x() / (0.012f * 0.012f));  // cupid's bow dip
    const float ux = p.x() / (g.mouth_half_width * 1.02f);
    const float uy_up = (p.y() - (g.mouth_y + 0.0085f * lt)) /
                        (0.0095f * lt + (p.y() > g.mouth_y + 0.0085f * lt ? -bow : 0.f));
    const float uy_low = (p.y() - (g.mouth_y - 0.009f * lt)) / (0.011f * lt);
    const float e_up = ux * ux + uy_up * uy_up, e_low = ux * ux + uy_low * uy_low;
    const float lip = 1.f - SmoothStep(0.75f, 1.05f, std::min(e_up, e_low));
    c = Mix(c, id.lip_color.cwiseProduct(Vec3f::Ones() * (1.f + 0.05f * b1)), lip);
    // The seam between the lips.
    const float seam = (1.f - SmoothStep(0.0008f, 0.0028f, std::abs(p.y() - g.mouth_y))) *
                       (1.f - SmoothStep(0.8f, 1.f, std::abs(ux)));
    c = Mix(c, id.lip_color * 0.35f, seam);
  }
  // Brows: arched bands of dark hair strokes.
  for (int side = 0; side < 2; ++side) {
    const float s = side == 0 ? -1.f : 1.f;
    const float lx = (p.x() - g.eye_c[side].x()) * s / 0.062f;  // -1 inner end, +1 outer end
    if (std::abs(lx) > 1.15f || p.z() < 0.17f) continue;
    const float centre = g.brow_y + 0.011f * (1.f - lx * lx) - 0.004f * lx;
    const float half = 0.0105f * (1.f - 0.4f * lx);
    const float dy = (p.y() - centre) / half;
    const float band =
        (1.f - SmoothStep(0.55f, 1.f, std::abs(dy))) * (1.f - SmoothStep(0.9f, 1.15f, std::abs(lx)));
    if (band <= 0.f) continue;
    // Strokes grow upwards at the inner end and outwards along the arch elsewhere.
    const float angle = 1.25f - 1.0f * SmoothStep(-1.f, 0.2f, lx);
    const Vec3f dir(s * std::cos(angle), std::sin(angle), 0.f);
    const Vec3f across(-dir.y(), dir.x(), 0.f);
    const Vec3f local(across.dot(p) * 520.f, dir.dot(p) * 55.f, s * 4.f);
    const float stroke = SmoothStep(-0.1f, 0.45f, ValueNoise(local, seed + 6u));
    c = Mix(c, id.brow_color, band * (0.5f + 0.5f * stroke));
  }
  return c.cwiseMax(0.f).cwiseMin(1.f);
}

Vec3f HeadModel::EyeAlbedo(const Vec3f& p, int side) const {
  const Vec3f q = (p - face_.geometry().eye_c[side]).normalized();
  const float angle = std::acos(std::clamp(q.z(), -1.f, 1.f));  // from the gaze direction (+z)
  const uint32_t seed = identity_.detail_seed + 11u;
  if (angle < 0.17f) return Vec3f(0.03f, 0.03f, 0.035f);  // pupil
  if (angle < 0.43f) {
    const float azimuth = std::atan2(q.y(), q.x());
    const float fibres =
        ValueNoise(Vec3f(std::cos(azimuth) * 9.f, std::sin(azimuth) * 9.f, angle * 14.f), seed);
    Vec3f c = identity_.iris_color * (0.8f + 0.3f * fibres);
    const float limbus = SmoothStep(0.36f, 0.43f, angle);
    c *= 1.f - 0.55f * limbus;
    c *= 0.75f + 0.25f * SmoothStep(0.17f, 0.24f, angle);
    return c;
  }
  const float corner = SmoothStep(0.6f, 1.1f, angle);
  return Mix(Vec3f(0.93f, 0.91f, 0.88f), Vec3f(0.88f, 0.70f, 0.66f), corner);
}

Vec3f HeadModel::LidAlbedo(const Vec3f& p, const ExpressionState& state) const {
  const int side = p.x() < 0.f ? 0 : 1;
  const Vec3f q = p - face_.geometry().eye_c[side];
  const float elevation = std::atan2(q.y(), std::max(q.z(), 1e-4f));
  Vec3f c = SkinAlbedo(p).cwiseProduct(Vec3f(0.93f, 0.88f, 0.88f));
  // Lashes along both lid edges (the upper edge moves as the eye closes).
  const float to_upper = std::abs(elevation - state.lid_upper[side]);
  const float to_lower = std::abs(elevation - face_.geometry().lid_lower);
  const float lash =
      std::max(1.f - SmoothStep(0.04f, 0.11f, to_upper), 0.6f * (1.f - SmoothStep(0.02f, 0.06f, to_lower)));
  return Mix(c, Vec3f(0.07f, 0.05f, 0.05f), 0.85f * lash);
}

Vec3f HeadModel::CavityAlbedo(const Vec3f& x, const ExpressionState& state) const {
  const Vec3f q = (x - state.cavity_c).cwiseQuotient(state.cavity_r);
  Vec3f c = Vec3f(0.16f, 0.045f, 0.05f) * (0.45f + 0.55f * SmoothStep(-0.6f, 0.6f, q.z()));
  // Upper teeth show under the upper lip when the mouth is open enough.
  const float teeth = SmoothStep(0.35f, 0.5f, q.y()) * SmoothStep(-0.4f, 0.1f, q.z()) *
                      (1.f - SmoothStep(0.6f, 0.9f, std::abs(q.x())));
  return Mix(c, Vec3f(0.86f, 0.84f, 0.76f), teeth);
}

}  // namespace icef::synth
