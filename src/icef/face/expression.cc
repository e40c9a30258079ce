#include "icef/face/expression.h"

#include <cmath>

namespace icef::face {

std::vector<std::string> ExpressionNames() { return {kExpressionNames.begin(), kExpressionNames.end()}; }

Status ValidateExpression(std::span<const float> expression) {
  if (expression.size() != kNumExpressions)
    return Status::Error("expression: expected " + std::to_string(kNumExpressions) + " values, got " +
                         std::to_string(expression.size()));
  for (size_t i = 0; i < expression.size(); ++i)
    if (!std::isfinite(expression[i]) || expression[i] < 0.f)
      return Status::Error("expression[" + std::to_string(i) + "] (" + kExpressionNames[i] +
                           "): expected a finite value >= 0, got " + std::to_string(expression[i]));
  return Status::Ok();
}

std::vector<int> ExpressionRegionLandmarks(int e) {
  auto range = [](int a, int b, std::vector<int> v = {}) {
    for (int i = a; i <= b; ++i) v.push_back(i);
    return v;
  };
  switch (e) {
    case kJawOpen:
      return range(48, 67, range(3, 13));
    case kSmileLeft:
    case kSmileRight:
    case kLipPucker:
    case kLipPress:
      return range(48, 67);
    case kCheekPuff:
      return range(48, 67, range(3, 13));
    case kBrowRaiseLeft:
      return range(22, 26);
    case kBrowRaiseRight:
      return range(17, 21);
    case kBrowFurrow:
      return range(17, 26);
    case kEyeCloseLeft:
      return range(42, 47);
    case kEyeCloseRight:
      return range(36, 41);
    default:
      return {};
  }
}

}  // namespace icef::face
