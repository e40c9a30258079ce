// Identity of a synthetic subject: the face model's shape parameters, the subject's own expression
// style (how strongly, where and how asymmetrically it performs each named expression) and the
// albedo parameters (skin tone, blotches, pores, freckles, moles, lips, eyes, hair, brows), all
// drawn from one identity seed.
#pragma once

#include <cstdint>
#include <string>

#include "icef/core/rng.h"
#include "icef/face/expression_style.h"
#include "icef/face/shape_params.h"
#include "icef/math/types.h"

namespace icef::synth {

struct IdentityParams {
  // Face shape: multiplicative scales of the average head (1 = average).
  face::ShapeParams shape;
  // Expression style: the ground truth's expressions, unknown to a face model fitted to the
  // subject (so the face-model prior is never the ground truth).
  face::ExpressionStyle style;

  // Albedo (linear RGB in [0, 1] as stored in the images).
  Vec3f skin_tone = Vec3f(0.80f, 0.62f, 0.52f);
  Vec3f lip_color = Vec3f(0.70f, 0.36f, 0.36f);
  Vec3f iris_color = Vec3f(0.30f, 0.45f, 0.55f);
  Vec3f hair_color = Vec3f(0.20f, 0.13f, 0.08f);
  Vec3f brow_color = Vec3f(0.13f, 0.09f, 0.055f);
  float blotch_strength = 0.5f;  // low-frequency skin variation, 0..1
  float pore_strength = 0.5f;    // high-frequency pore texture, 0..1
  float freckle_density = 0.3f;  // probability of a freckle per lattice cell (cheeks and nose)
  int num_moles = 3;             // moles on the face
  float hairline = 0.0f;         // hairline offset (head units, + = higher forehead)
  uint32_t detail_seed = 1;      // key of every noise pattern (pores, freckles, moles, strands)
  // Fine detail at the pixel scale (the `detail` scene axis; the defaults are the classic head):
  float pore_scale = 1.0f;        // pore frequency multiplier (2 = pores half the size)
  float wrinkle_strength = 0.0f;  // forehead lines and crow's feet, 0..1
  float stubble_density = 0.0f;   // beard stubble dots over the lower face, 0..1

  // The average head with the generic style and the default albedo (expression tests use it as a
  // fixed subject).
  static IdentityParams Average() { return IdentityParams(); }
  // A subject drawn from Rng(seed, "synth.identity"): every field above varies. The style comes
  // from its own stream (DrawExpressionStyle), so the shape and albedo draws do not depend on it.
  static IdentityParams FromSeed(uint64_t seed);
  std::string ToString() const;
};

// The expression style of identity `seed`, drawn from Rng(seed, "synth.expression_style"): each
// expression's gain at least 18 % away from the generic 1 (weaker or stronger at random, stronger
// capped at 1.2-1.3), one side of each paired expression weaker by up to 25 %, and jaw-hinge,
// smile-corner and brow-window offsets of a few hundredths of a head unit. The ranges and why the
// caps sit where they do are in docs/face_model.md.
face::ExpressionStyle DrawExpressionStyle(uint64_t seed);

// A value in [0, 1) for a scene axis that spreads consecutive seeds over the whole range: the
// fractional part of seed * step (an irrational step, one per axis, so axes do not move together)
// plus a small jitter from `rng`. Any six consecutive seeds (e.g. the validation identities) then
// span each axis, where independent uniform draws often leave an end out.
float SpreadUnit(uint64_t seed, double step, Rng& rng);

// The `skin` scene axis: redraws skin tone from very light to very dark (a wider palette than
// FromSeed's) with lips, brows and hair whose contrast matches the tone, from Rng(seed,
// "synth.scene.skin").
void DrawDiverseSkin(uint64_t seed, IdentityParams* identity);
// The `detail` scene axis: denser fine albedo detail (smaller and stronger pores, forehead
// wrinkles and crow's feet, stubble on some subjects), from Rng(seed, "synth.scene.detail").
void DrawFineDetail(uint64_t seed, IdentityParams* identity);

}  // namespace icef::synth
