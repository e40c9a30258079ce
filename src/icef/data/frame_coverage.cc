#include "icef/data/frame_coverage.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "icef/core/status.h"
#include "icef/data/dataset.h"

namespace icef {

namespace {

double Distance(const CoverageCandidate& a, const CoverageCandidate& b, double view_scale) {
  double s = (view_scale * (a.view_direction - b.view_direction)).squaredNorm();
  for (size_t i = 0; i < a.expression.size(); ++i) {
    const double d = a.expression[i] - b.expression[i];
    s += d * d;
  }
  return std::sqrt(s);
}

// An expression name that closes an eye (this face model's or ARKit's).
bool IsBlinkName(const std::string& name) {
  return name.find("eye_close") != std::string::npos || name.find("eyeBlink") != std::string::npos;
}

}  // namespace

std::vector<int> ChooseCoverageFrames(const std::vector<CoverageCandidate>& candidates, int k,
                                      const CoverageOptions& options) {
  const int n = static_cast<int>(candidates.size());
  ICEF_CHECK(k >= 0 && k <= n, "ChooseCoverageFrames: k must be in [0, candidates]");
  // A chord of the unit sphere is about the angle in radians: scale it to expression units.
  const double view_scale = 180.0 / std::numbers::pi / options.degrees_per_unit;
  std::vector<bool> preferred(n);
  int num_preferred = 0;
  for (int i = 0; i < n; ++i) {
    preferred[i] =
        candidates[i].sharpness >= options.min_sharpness && (options.allow_blink || !candidates[i].blink);
    num_preferred += preferred[i];
  }
  std::vector<int> chosen;
  std::vector<bool> taken(n, false);
  std::vector<double> nearest(n, std::numeric_limits<double>::infinity());
  while (static_cast<int>(chosen.size()) < k) {
    // Only preferred frames while any are left, then the rest.
    const bool use_preferred = static_cast<int>(chosen.size()) < num_preferred;
    int best = -1;
    double best_score = -std::numeric_limits<double>::infinity();
    for (int i = 0; i < n; ++i) {
      if (taken[i] || (use_preferred && !preferred[i])) continue;
      const CoverageCandidate& c = candidates[i];
      double score;
      if (chosen.empty()) {
        // The most frontal and neutral frame: the canonical space's anchor.
        CoverageCandidate frontal;
        frontal.expression.assign(c.expression.size(), 0.f);
        score = -Distance(c, frontal, view_scale);
      } else {
        score = nearest[i] * (0.5 + 0.5 * std::min(1.0, std::max(0.0, c.sharpness)));
      }
      if (score > best_score) {
        best_score = score;
        best = i;
      }
    }
    ICEF_CHECK(best >= 0, "ChooseCoverageFrames: no candidate left");
    taken[best] = true;
    chosen.push_back(best);
    for (int i = 0; i < n; ++i)
      nearest[i] = std::min(nearest[i], Distance(candidates[i], candidates[best], view_scale));
  }
  return chosen;
}

CoverageCandidate CandidateOfFrame(const Frame& frame, const std::vector<std::string>& expression_names) {
  CoverageCandidate c;
  const Vec3d centre = frame.camera.Center();
  if (centre.norm() > 0) c.view_direction = centre.normalized();
  c.expression = frame.expression;
  for (size_t i = 0; i < expression_names.size() && i < frame.expression.size(); ++i)
    if (IsBlinkName(expression_names[i]) && frame.expression[i] > 0.5f) c.blink = true;
  return c;
}

}  // namespace icef
