#include "icef/face/shape_params.h"

#include <sstream>

namespace icef::face {

namespace {
// Pointers to the fields in kShapeParamNames order.
constexpr std::array<float ShapeParams::*, ShapeParams::kCount> kFields = {
    &ShapeParams::head_width,    &ShapeParams::head_height, &ShapeParams::head_depth,
    &ShapeParams::jaw_width,     &ShapeParams::chin_length, &ShapeParams::nose_length,
    &ShapeParams::nose_width,    &ShapeParams::nose_bridge, &ShapeParams::eye_spacing,
    &ShapeParams::lip_thickness, &ShapeParams::brow_height, &ShapeParams::cheek_fullness,
    &ShapeParams::mouth_width};
}  // namespace

std::array<float, ShapeParams::kCount> ShapeParams::ToArray() const {
  std::array<float, kCount> out;
  for (int i = 0; i < kCount; ++i) out[i] = this->*kFields[i];
  return out;
}

ShapeParams ShapeParams::FromArray(std::span<const float, kCount> values) {
  ShapeParams p;
  for (int i = 0; i < kCount; ++i) p.*kFields[i] = values[i];
  return p;
}

std::string ShapeParams::ToString() const {
  std::ostringstream os;
  os << "ShapeParams(";
  const std::array<float, kCount> values = ToArray();
  for (int i = 0; i < kCount; ++i) os << (i ? ", " : "") << kShapeParamNames[i] << "=" << values[i];
  os << ")";
  return os.str();
}

}  // namespace icef::face
