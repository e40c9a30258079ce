#include "icef/face/expression_style.h"

#include <array>
#include <cmath>
#include <sstream>
#include <utility>
#include <vector>

#include "icef/face/expression.h"

namespace icef::face {

namespace {

// (name, address) of every gain, then every offset, in declaration order.
template <typename Style, typename Float>
std::array<std::pair<const char*, Float*>, ExpressionStyle::kNumFields> FieldAddresses(Style& s) {
  return {{{"jaw_gain", &s.jaw_gain},
           {"smile_gain[0]", &s.smile_gain[0]},
           {"smile_gain[1]", &s.smile_gain[1]},
           {"smile_width", &s.smile_width},
           {"smile_lift", &s.smile_lift},
           {"lip_pucker_gain", &s.lip_pucker_gain},
           {"lip_press_gain", &s.lip_press_gain},
           {"brow_raise_gain[0]", &s.brow_raise_gain[0]},
           {"brow_raise_gain[1]", &s.brow_raise_gain[1]},
           {"brow_furrow_gain", &s.brow_furrow_gain},
           {"eye_close_gain[0]", &s.eye_close_gain[0]},
           {"eye_close_gain[1]", &s.eye_close_gain[1]},
           {"cheek_puff_gain", &s.cheek_puff_gain},
           {"jaw_hinge_dy", &s.jaw_hinge_dy},
           {"jaw_hinge_dz", &s.jaw_hinge_dz},
           {"smile_corner_shift", &s.smile_corner_shift},
           {"brow_raise_shift", &s.brow_raise_shift}}};
}

std::vector<std::pair<std::string, float>> Gains(const ExpressionStyle& s) {
  const std::vector<std::pair<std::string, float>> all = s.Fields();
  return {all.begin(), all.begin() + ExpressionStyle::kNumGains};
}
std::vector<std::pair<std::string, float>> Offsets(const ExpressionStyle& s) {
  const std::vector<std::pair<std::string, float>> all = s.Fields();
  return {all.begin() + ExpressionStyle::kNumGains, all.end()};
}

}  // namespace

float ExpressionStyle::WeightGain(int e) const {
  switch (e) {
    case kJawOpen:
      return jaw_gain;
    case kSmileLeft:
      return smile_gain[1];
    case kSmileRight:
      return smile_gain[0];
    case kLipPucker:
      return lip_pucker_gain;
    case kLipPress:
      return lip_press_gain;
    case kBrowRaiseLeft:
      return brow_raise_gain[1];
    case kBrowRaiseRight:
      return brow_raise_gain[0];
    case kBrowFurrow:
      return brow_furrow_gain;
    case kEyeCloseLeft:
      return eye_close_gain[1];
    case kEyeCloseRight:
      return eye_close_gain[0];
    case kCheekPuff:
      return cheek_puff_gain;
    default:
      return 1.f;
  }
}

Status ExpressionStyle::Validate() const {
  for (const auto& [name, value] : Gains(*this))
    if (!std::isfinite(value) || value < kMinGain || value > kMaxGain)
      return Status::Error("expression style: " + name + ": expected a gain in [" + std::to_string(kMinGain) +
                           ", " + std::to_string(kMaxGain) + "], got " + std::to_string(value));
  for (const auto& [name, value] : Offsets(*this))
    if (!std::isfinite(value) || std::abs(value) > kMaxOffset)
      return Status::Error("expression style: " + name + ": expected an offset within +-" +
                           std::to_string(kMaxOffset) + " head units, got " + std::to_string(value));
  return Status::Ok();
}

std::vector<std::pair<std::string, float>> ExpressionStyle::Fields() const {
  std::vector<std::pair<std::string, float>> out;
  for (const auto& [name, address] : FieldAddresses<const ExpressionStyle, const float>(*this))
    out.emplace_back(name, *address);
  return out;
}

bool ExpressionStyle::SetField(const std::string& name, float value) {
  for (const auto& [field, address] : FieldAddresses<ExpressionStyle, float>(*this))
    if (name == field) {
      *address = value;
      return true;
    }
  return false;
}

std::string ExpressionStyle::ToString() const {
  if (IsGeneric()) return "ExpressionStyle(generic)";
  std::ostringstream os;
  os << "ExpressionStyle(";
  bool first = true;
  for (const auto& [name, value] : Gains(*this))
    os << (first ? "" : ", ") << name << "=" << value, first = false;
  for (const auto& [name, value] : Offsets(*this)) os << ", " << name << "=" << value;
  os << ")";
  return os.str();
}

}  // namespace icef::face
