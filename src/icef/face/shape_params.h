// Shape parameters of the face model: 13 dimensionless multiplicative scales of the average head
// (1 = average). They set the anchor positions and radii of the face parts (FaceGeometry); see
// docs/face_model.md for what each one moves.
#pragma once

#include <array>
#include <span>
#include <string>

namespace icef::face {

struct ShapeParams {
  static constexpr int kCount = 13;

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

  // The average head (every scale 1).
  static ShapeParams Average() { return ShapeParams(); }
  // The fields in declaration order (the order of kShapeParamNames).
  std::array<float, kCount> ToArray() const;
  // Inverse of ToArray: values[i] is the field kShapeParamNames[i].
  static ShapeParams FromArray(std::span<const float, kCount> values);
  std::string ToString() const;
};

// Field names of ShapeParams in ToArray order.
inline constexpr std::array<const char*, ShapeParams::kCount> kShapeParamNames = {
    "head_width",  "head_height",    "head_depth",  "jaw_width",   "chin_length",
    "nose_length", "nose_width",     "nose_bridge", "eye_spacing", "lip_thickness",
    "brow_height", "cheek_fullness", "mouth_width"};

}  // namespace icef::face
