// Identity of a synthetic subject: face-shape parameters (dimensionless scales around 1) and the
// albedo parameters (skin tone, blotches, pores, freckles, moles, lips, eyes, hair, brows), all
// drawn from one identity seed.
#pragma once

#include <cstdint>
#include <string>

#include "icef/math/types.h"

namespace icef::synth {

struct IdentityParams {
  // Shape: multiplicative scales of the average head (1 = average) unless stated.
  float head_width = 1.f;      // cranium width
  float head_height = 1.f;     // cranium height
  float head_depth = 1.f;      // cranium front-to-back depth
  float jaw_width = 1.f;       // lower-face width
  float chin_length = 1.f;     // chin drop below the mouth
  float nose_length = 1.f;     // bridge-to-tip length (also moves the mouth down)
  float nose_width = 1.f;      // tip and nostril-wing width
  float nose_bridge = 1.f;     // bridge protrusion
  float eye_spacing = 1.f;     // distance between the eye centres
  float lip_thickness = 1.f;   // lip height and protrusion
  float brow_height = 1.f;     // brow distance above the eyes
  float cheek_fullness = 1.f;  // cheek volume
  float mouth_width = 1.f;     // distance between the mouth corners

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

  // The average head with the default albedo (expression tests use it as a fixed subject).
  static IdentityParams Average() { return IdentityParams(); }
  // A subject drawn from Rng(seed, "synth.identity"): every field above varies.
  static IdentityParams FromSeed(uint64_t seed);
  std::string ToString() const;
};

}  // namespace icef::synth
