// The named expression parameters of the face model. Each is a weight >= 0 (0 = neutral, 1 = the
// full expression); values above 1 extrapolate and still give a valid surface. "left" and "right"
// are the subject's own: the subject's left side is +x and appears on the image's right in a
// frontal view.
#pragma once

#include <array>
#include <span>
#include <string>
#include <vector>

#include "icef/core/status.h"

namespace icef::face {

enum ExpressionIndex : int {
  kJawOpen = 0,
  kSmileLeft,
  kSmileRight,
  kLipPucker,
  kLipPress,
  kBrowRaiseLeft,
  kBrowRaiseRight,
  kBrowFurrow,
  kEyeCloseLeft,
  kEyeCloseRight,
  kCheekPuff,
  kNumExpressions
};

inline constexpr std::array<const char*, kNumExpressions> kExpressionNames = {
    "jaw_open",         "smile_left",  "smile_right",    "lip_pucker",      "lip_press", "brow_raise_left",
    "brow_raise_right", "brow_furrow", "eye_close_left", "eye_close_right", "cheek_puff"};

std::vector<std::string> ExpressionNames();

// OK when `expression` has kNumExpressions finite values >= 0; the message names the entry.
Status ValidateExpression(std::span<const float> expression);

// The iBUG-68 landmark indices whose neighbourhood an expression parameter moves (used by the
// locality tests and documentation): mouth, jaw, brows or eyes.
std::vector<int> ExpressionRegionLandmarks(int expression_index);

}  // namespace icef::face
