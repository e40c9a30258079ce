// Identity of a synthetic subject: the face model's shape parameters, the subject's own expression
// style (how strongly, where and how asymmetrically it performs each named expression) and the
// albedo parameters (skin tone, blotches, pores, freckles, moles, lips, eyes, hair, brows), all
// drawn from one identity seed.
#pragma once

#include <cstdint>
#include <string>

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

}  // namespace icef::synth
