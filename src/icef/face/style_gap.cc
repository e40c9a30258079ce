#include "icef/face/style_gap.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "icef/core/status.h"
#include "icef/face/face_model.h"

namespace icef::face {

StyleGap MeasureStyleGap(const ShapeParams& shape, const ExpressionStyle& style, float weight) {
  ICEF_CHECK(weight > 0.f, "style gap: the weight must be > 0");
  const FaceModel generic(shape), styled(shape, style);
  const std::array<Vec3f, 68>& neutral = generic.NeutralLandmarks();
  StyleGap gap;
  double sum = 0.0;
  for (int e = 0; e < kNumExpressions; ++e) {
    std::vector<float> beta(kNumExpressions, 0.f);
    beta[e] = weight;
    const std::array<Vec3f, 68> a = generic.Landmarks(generic.Prepare(beta));
    const std::array<Vec3f, 68> b = styled.Landmarks(styled.Prepare(beta));
    double deviation = 0.0, motion = 0.0, max_motion = 0.0;
    for (int i = 0; i < 68; ++i) {
      const double m = (a[i] - neutral[i]).cast<double>().norm();
      deviation += (b[i] - a[i]).cast<double>().norm();
      motion += m;
      max_motion = std::max(max_motion, m);
    }
    if (max_motion < StyleGap::kMinMotion) {
      gap.per_expression[e] = std::numeric_limits<double>::quiet_NaN();
      continue;
    }
    gap.per_expression[e] = deviation / motion;
    sum += gap.per_expression[e];
    ++gap.num_measured;
  }
  gap.mean = gap.num_measured > 0 ? sum / gap.num_measured : 0.0;
  return gap;
}

std::string StyleGap::ToString() const {
  std::string out;
  char buf[64];
  std::snprintf(buf, sizeof buf, "StyleGap(mean=%.3f over %d:", mean, num_measured);
  out = buf;
  for (int e = 0; e < kNumExpressions; ++e) {
    if (std::isnan(per_expression[e]))
      std::snprintf(buf, sizeof buf, "%s %s=n/a", e ? "," : "", kExpressionNames[e]);
    else
      std::snprintf(buf, sizeof buf, "%s %s=%.3f", e ? "," : "", kExpressionNames[e], per_expression[e]);
    out += buf;
  }
  return out + ")";
}

}  // namespace icef::face
