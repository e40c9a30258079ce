// How far a subject's expression style is from the generic one, measured on landmarks: for each
// named expression e at weight w (1 by default),
//   gap_e = mean_i ||L_style(e)_i - L_generic(e)_i|| / mean_i ||L_generic(e)_i - L_neutral_i||
// over the landmarks the expression moves (both means over the same landmarks, so this is the
// ratio of the sums over all 68: a landmark that neither model moves adds 0 to both): the styled
// expression's deviation from the generic one as a fraction of the generic expression's own
// motion. This is what a face-model prior that knows the subject's shape but not its style gets
// wrong. An expression whose generic motion moves no landmark by kMinMotion is not measured
// (cheek_puff, whose window lies between the landmarks, on most shapes).
#pragma once

#include <array>
#include <string>

#include "icef/face/expression.h"
#include "icef/face/expression_style.h"
#include "icef/face/shape_params.h"

namespace icef::face {

struct StyleGap {
  static constexpr double kMinMotion = 1e-3;  // head units (~0.13 px in a 128x128 synth frame)

  std::array<double, kNumExpressions> per_expression{};  // gap_e in kExpressionNames order; NaN: not measured
  double mean = 0;                                       // mean over the measured expressions
  int num_measured = 0;                                  // expressions that move a landmark by kMinMotion

  std::string ToString() const;
};

// Builds the generic and the styled face model of `shape` and compares their landmarks at each
// single expression of weight `weight` (> 0). 0 for every measured expression of the generic style.
StyleGap MeasureStyleGap(const ShapeParams& shape, const ExpressionStyle& style, float weight = 1.f);

}  // namespace icef::face
