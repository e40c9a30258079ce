#include "icef/synth/identity.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "icef/core/rng.h"

namespace icef::synth {

namespace {
Vec3f Mix(const Vec3f& a, const Vec3f& b, float t) { return a + t * (b - a); }
}  // namespace

face::ExpressionStyle DrawExpressionStyle(uint64_t seed) {
  Rng rng(seed, StreamId("synth.expression_style"));
  auto u = [&](double lo, double hi) { return static_cast<float>(rng.Uniform(lo, hi)); };
  // A gain clearly off the generic 1: weaker in [0.65, 0.82] or stronger in [1.18, up_max].
  auto gain = [&](double up_max) { return rng.Below(2) == 0 ? u(0.65, 0.82) : u(1.18, up_max); };
  // A per-side pair [right, left]: a common gain, and one side (either) weaker by up to 25 %.
  auto sides = [&](double up_max) {
    const float g = gain(up_max), weaker = g * (1.f - u(0.0, 0.25));
    return rng.Below(2) == 0 ? std::array<float, 2>{weaker, g} : std::array<float, 2>{g, weaker};
  };
  // Stronger-than-generic terms stop at 1.3 (1.2 for the smile and the brows, whose generic warps
  // fold first): at the far tier's weight 1.5 no term then moves more than the generic one does
  // at weight 2, where the generic model is still valid (docs/face_model.md).
  face::ExpressionStyle st;
  st.jaw_gain = gain(1.30);
  st.jaw_hinge_dy = u(-0.03, 0.03);
  st.jaw_hinge_dz = u(-0.04, 0.04);
  st.smile_gain = sides(1.20);
  st.smile_width = gain(1.30);
  st.smile_lift = gain(1.30);
  st.smile_corner_shift = u(-0.012, 0.02);
  // The corner's motion is gain x width (x) and gain x lift (y): keep the product at most 1.3.
  const float corner = std::max(st.smile_gain[0], st.smile_gain[1]) * std::max(st.smile_width, st.smile_lift);
  if (corner > 1.3f)
    for (float& g : st.smile_gain) g *= 1.3f / corner;
  st.lip_pucker_gain = gain(1.30);
  st.lip_press_gain = gain(1.30);
  st.brow_raise_gain = sides(1.20);
  st.brow_raise_shift = u(-0.025, 0.025);
  st.brow_furrow_gain = gain(1.30);
  st.eye_close_gain = sides(1.45);
  st.cheek_puff_gain = gain(1.30);
  return st;
}

IdentityParams IdentityParams::FromSeed(uint64_t seed) {
  Rng rng(seed, StreamId("synth.identity"));
  auto u = [&](double lo, double hi) { return static_cast<float>(rng.Uniform(lo, hi)); };
  IdentityParams p;
  p.shape.head_width = u(0.90, 1.10);
  p.shape.head_height = u(0.92, 1.08);
  p.shape.head_depth = u(0.92, 1.08);
  p.shape.jaw_width = u(0.84, 1.16);
  p.shape.chin_length = u(0.80, 1.25);
  p.shape.nose_length = u(0.82, 1.22);
  p.shape.nose_width = u(0.80, 1.30);
  p.shape.nose_bridge = u(0.70, 1.35);
  p.shape.eye_spacing = u(0.91, 1.09);
  p.shape.lip_thickness = u(0.70, 1.35);
  p.shape.brow_height = u(0.75, 1.30);
  p.shape.cheek_fullness = u(0.75, 1.30);
  p.shape.mouth_width = u(0.85, 1.18);

  // Skin tones along a light-to-dark palette, with a warm/cool tint.
  const Vec3f light(0.93f, 0.76f, 0.66f), mid(0.76f, 0.55f, 0.42f), dark(0.42f, 0.28f, 0.20f);
  const float tone = u(0.0, 1.0);
  Vec3f skin = tone < 0.6f ? Mix(light, mid, tone / 0.6f) : Mix(mid, dark, (tone - 0.6f) / 0.4f);
  const float tint = u(-0.03, 0.03);
  p.skin_tone = (skin + Vec3f(tint, 0.f, -tint)).cwiseMax(0.f).cwiseMin(1.f);
  p.lip_color =
      (p.skin_tone.cwiseProduct(Vec3f(0.85f, 0.55f, 0.58f)) + Vec3f(u(0.0, 0.08), 0.f, 0.02f)).cwiseMin(1.f);
  const Vec3f irises[] = {{0.25f, 0.42f, 0.60f},
                          {0.30f, 0.48f, 0.32f},
                          {0.38f, 0.24f, 0.12f},
                          {0.22f, 0.14f, 0.08f},
                          {0.45f, 0.45f, 0.42f}};
  p.iris_color = irises[rng.Below(5)];
  const Vec3f hairs[] = {{0.08f, 0.06f, 0.05f},
                         {0.22f, 0.14f, 0.08f},
                         {0.45f, 0.30f, 0.16f},
                         {0.70f, 0.55f, 0.32f},
                         {0.50f, 0.20f, 0.08f}};
  p.hair_color = hairs[rng.Below(5)];
  p.brow_color = 0.5f * p.hair_color + Vec3f(0.03f, 0.02f, 0.015f);
  p.blotch_strength = u(0.2, 1.0);
  p.pore_strength = u(0.3, 1.0);
  p.freckle_density = rng.UniformDouble() < 0.5 ? u(0.02, 0.12) : u(0.25, 0.6);
  p.num_moles = 2 + static_cast<int>(rng.Below(5));
  p.hairline = u(-0.03, 0.05);
  p.detail_seed = static_cast<uint32_t>(Mix64(seed ^ 0x5eedULL));
  p.style = DrawExpressionStyle(seed);
  return p;
}

float SpreadUnit(uint64_t seed, double step, Rng& rng) {
  const double x = static_cast<double>(seed % 1000003) * step + rng.Uniform(-0.05, 0.05);
  return static_cast<float>(std::clamp(x - std::floor(x), 0.0, 0.999999));
}

void DrawDiverseSkin(uint64_t seed, IdentityParams* p) {
  Rng rng(seed, StreamId("synth.scene.skin"));
  auto u = [&](double lo, double hi) { return static_cast<float>(rng.Uniform(lo, hi)); };
  // Five anchors from very light to very dark; the tone is uniform along them.
  const Vec3f anchors[] = {{0.96f, 0.82f, 0.74f},
                           {0.90f, 0.72f, 0.60f},
                           {0.74f, 0.53f, 0.40f},
                           {0.46f, 0.30f, 0.21f},
                           {0.24f, 0.15f, 0.105f}};
  // The spread's ends (within 0.06 of 0 and 1) map to the palette's ends, so six seeds reach them.
  const float tone = std::clamp((SpreadUnit(seed, 0.6180339887, rng) - 0.06f) / 0.84f, 0.f, 1.f);
  const float at = tone * 4.f;
  const int i = std::min(3, static_cast<int>(at));
  const Vec3f skin = Mix(anchors[i], anchors[i + 1], at - static_cast<float>(i));
  const float tint = u(-0.025, 0.025);
  p->skin_tone = (skin + Vec3f(tint, 0.f, -tint)).cwiseMax(0.f).cwiseMin(1.f);
  // Lips: redder on light skin, darker and browner on dark skin; always darker than the skin.
  const Vec3f lip_factor = Mix(Vec3f(0.88f, 0.52f, 0.56f), Vec3f(0.78f, 0.58f, 0.62f), tone);
  p->lip_color =
      (p->skin_tone.cwiseProduct(lip_factor) + (1.f - tone) * Vec3f(u(0.02, 0.08), 0.f, 0.01f)).cwiseMin(1.f);
  // Hair and brows: any colour on light skin, dark on dark skin (brows keep a contrast of at
  // least ~2.5x the skin's luminance either way).
  const Vec3f hairs[] = {{0.05f, 0.04f, 0.035f},
                         {0.18f, 0.11f, 0.06f},
                         {0.42f, 0.28f, 0.15f},
                         {0.68f, 0.52f, 0.30f},
                         {0.48f, 0.19f, 0.07f}};
  const int hair = tone > 0.6f ? static_cast<int>(rng.Below(2)) : static_cast<int>(rng.Below(5));
  p->hair_color = hairs[hair];
  const float skin_luma = p->skin_tone.dot(Vec3f(0.2126f, 0.7152f, 0.0722f));
  const Vec3f brow = 0.5f * p->hair_color + Vec3f(0.03f, 0.02f, 0.015f);
  const float brow_luma = brow.dot(Vec3f(0.2126f, 0.7152f, 0.0722f));
  p->brow_color = brow_luma * 2.5f > skin_luma ? brow * (skin_luma / (2.5f * brow_luma)) : brow;
}

void DrawFineDetail(uint64_t seed, IdentityParams* p) {
  Rng rng(seed, StreamId("synth.scene.detail"));
  auto u = [&](double lo, double hi) { return static_cast<float>(rng.Uniform(lo, hi)); };
  p->pore_scale = u(1.2, 2.4);
  p->pore_strength = u(0.8, 1.8);
  p->wrinkle_strength = u(0.2, 1.0);
  p->stubble_density = rng.UniformDouble() < 0.5 ? 0.f : u(0.25, 0.8);
}

std::string IdentityParams::ToString() const {
  std::ostringstream os;
  const face::ShapeParams& s = shape;
  os << "IdentityParams(head=" << s.head_width << "x" << s.head_height << "x" << s.head_depth
     << ", jaw=" << s.jaw_width << ", chin=" << s.chin_length << ", nose=" << s.nose_length << "/"
     << s.nose_width << "/" << s.nose_bridge << ", eyes=" << s.eye_spacing << ", lips=" << s.lip_thickness
     << ", brows=" << s.brow_height << ", cheeks=" << s.cheek_fullness << ", mouth=" << s.mouth_width
     << ", skin=[" << skin_tone.transpose() << "], freckles=" << freckle_density << ", moles=" << num_moles
     << ", pores=" << pore_strength << "@" << pore_scale << ", wrinkles=" << wrinkle_strength
     << ", stubble=" << stubble_density << ", " << style.ToString() << ")";
  return os.str();
}

}  // namespace icef::synth
