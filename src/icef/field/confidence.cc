#include "icef/field/confidence.h"

#include <cmath>
#include <limits>
#include <sstream>

namespace icef {

Status ConfidenceOptions::Validate() const {
  if (!(std::isfinite(lambda) && lambda > 0))
    return Status::Error("confidence.lambda must be a finite number > 0");
  return Status::Ok();
}

std::string ConfidenceOptions::ToString() const {
  std::ostringstream os;
  os << "ConfidenceOptions(lambda=" << lambda << ")";
  return os.str();
}

std::string NearestExpression::ToString() const {
  std::ostringstream os;
  os << "NearestExpression(index=" << index << ", delta=" << delta << ", kappa=" << kappa << ")";
  return os.str();
}

double ConfidenceFromDistance(double delta, double lambda) {
  ICEF_CHECK(lambda > 0, "lambda must be > 0");
  ICEF_CHECK(delta >= 0, "delta must be >= 0");
  return std::exp(-delta / lambda);
}

Result<ExpressionConfidence> ExpressionConfidence::Create(std::vector<std::vector<float>> observed,
                                                          const ConfidenceOptions& options) {
  ICEF_RETURN_IF_ERROR(options.Validate());
  if (observed.empty()) return Status::Error("confidence: no observed expressions");
  for (size_t k = 0; k < observed.size(); ++k) {
    if (observed[k].size() != observed[0].size())
      return Status::Error("confidence: observed expression " + std::to_string(k) + " has " +
                           std::to_string(observed[k].size()) + " values, expected " +
                           std::to_string(observed[0].size()));
    for (float v : observed[k])
      if (!std::isfinite(v))
        return Status::Error("confidence: observed expression " + std::to_string(k) + " is not finite");
  }
  ExpressionConfidence c;
  c.observed_ = std::move(observed);
  c.options_ = options;
  return c;
}

NearestExpression ExpressionConfidence::Nearest(std::span<const float> beta) const {
  ICEF_CHECK(int(beta.size()) == expression_dim(), "expression has " + std::to_string(beta.size()) +
                                                       " values, expected " +
                                                       std::to_string(expression_dim()));
  NearestExpression best;
  double best_sq = std::numeric_limits<double>::infinity();
  for (int k = 0; k < num_observed(); ++k) {
    double sq = 0;
    for (size_t j = 0; j < beta.size(); ++j) {
      const double d = double(beta[j]) - double(observed_[k][j]);
      sq += d * d;
    }
    if (sq < best_sq) {
      best_sq = sq;
      best.index = k;
    }
  }
  ICEF_CHECK(best.index >= 0, "expression is not finite");
  best.delta = std::sqrt(best_sq);
  best.kappa = ConfidenceFromDistance(best.delta, options_.lambda);
  return best;
}

std::string ExpressionConfidence::ToString() const {
  std::ostringstream os;
  os << "ExpressionConfidence(observed=" << num_observed() << ", dim=" << expression_dim() << ", "
     << options_.ToString() << ")";
  return os.str();
}

}  // namespace icef
