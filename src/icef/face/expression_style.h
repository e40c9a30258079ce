// How one subject performs the named expressions: the strength, centre and asymmetry of each
// expression's warp. The in-class defaults are the generic style (ExpressionStyle::Generic()),
// the face model's own expressions; synthetic subjects draw their own style from the identity
// seed (synth::IdentityParams), which a face model fitted to their landmarks (shape + pose) does
// not know. Paired arrays are indexed like FaceGeometry: 0 = the subject's right (x < 0), 1 = the
// left (x > 0). See docs/face_model.md for the table of fields and the ranges synth draws.
#pragma once

#include <array>
#include <string>
#include <utility>
#include <vector>

#include "icef/core/status.h"

namespace icef::face {

struct ExpressionStyle {
  // Multiplies the jaw angle per unit jaw_open (0.20 rad).
  float jaw_gain = 1.f;
  // Jaw hinge offset along y and z (head units; + = higher, + = towards the face).
  float jaw_hinge_dy = 0.f;
  float jaw_hinge_dz = 0.f;
  // Multiplies smile_right / smile_left: [right, left].
  std::array<float, 2> smile_gain{1.f, 1.f};
  // Multiplies the mouth corner's outward motion (0.018).
  float smile_width = 1.f;
  // Multiplies the corner's (0.022) and the cheek's (0.012) upward motion.
  float smile_lift = 1.f;
  // Moves the corner window outwards (head units; + = wider).
  float smile_corner_shift = 0.f;
  // Multiplies lip_pucker (the lips' motion and the open mouth's narrowing).
  float lip_pucker_gain = 1.f;
  // Multiplies lip_press.
  float lip_press_gain = 1.f;
  // Multiplies brow_raise_right / brow_raise_left: [right, left].
  std::array<float, 2> brow_raise_gain{1.f, 1.f};
  // Moves both brow-raise windows laterally (head units; + = the outer brow rises more).
  float brow_raise_shift = 0.f;
  // Multiplies brow_furrow.
  float brow_furrow_gain = 1.f;
  // Lid closure per unit eye_close_right / eye_close_left, [right, left]; still clamped at closed.
  std::array<float, 2> eye_close_gain{1.f, 1.f};
  // Multiplies cheek_puff.
  float cheek_puff_gain = 1.f;

  // The face model's own expressions (every default above).
  static ExpressionStyle Generic() { return ExpressionStyle(); }
  bool IsGeneric() const { return *this == Generic(); }
  // The factor the style applies to the weight of expression `e` (ExpressionIndex) before the
  // warp: jaw_gain, smile_gain[side], ... (1 for every expression in the generic style).
  float WeightGain(int e) const;
  // OK when every gain is in [kMinGain, kMaxGain] and every offset within kMaxOffset; the message
  // names the field.
  Status Validate() const;
  std::string ToString() const;

  // Every field by name, the 13 gains first (declaration order; paired fields as name[0], name[1]),
  // then the 4 offsets: the flat form a fit's parameter vector and a model's setup JSON use.
  static constexpr int kNumGains = 13, kNumOffsets = 4, kNumFields = kNumGains + kNumOffsets;
  std::vector<std::pair<std::string, float>> Fields() const;
  // Sets the field called `name` (as Fields() names it); false when there is none.
  bool SetField(const std::string& name, float value);

  bool operator==(const ExpressionStyle&) const = default;

  static constexpr float kMinGain = 0.25f, kMaxGain = 2.5f;
  static constexpr float kMaxOffset = 0.08f;  // head units
};

}  // namespace icef::face
