// Confidence of the learned deformation at an expression (docs/design.md §2):
//   beta_n = argmin_k ||beta - beta_k||_2 over the observed (training) expressions,
//   delta  = ||beta - beta_n||_2,   kappa = exp(-delta / lambda)
// so kappa = 1 at a training expression and tends to 0 as beta moves away from all of them.
// Ties go to the lowest training index (deterministic).
#pragma once

#include <span>
#include <string>
#include <vector>

#include "icef/core/status.h"

namespace icef {

struct ConfidenceOptions {
  double lambda = 0.5;  // length scale of kappa = exp(-delta / lambda), in expression-coefficient units (> 0)

  bool operator==(const ConfidenceOptions&) const = default;
  Status Validate() const;
  std::string ToString() const;
};

// The nearest observed expression and the confidence there.
struct NearestExpression {
  int index = -1;    // training frame index k of beta_n
  double delta = 0;  // ||beta - beta_n||_2
  double kappa = 1;  // exp(-delta / lambda)
  std::string ToString() const;
};

// kappa(delta) = exp(-delta / lambda).
double ConfidenceFromDistance(double delta, double lambda);

class ExpressionConfidence {
 public:
  // Errors: no expressions, expressions of different lengths, non-finite values, bad options.
  static Result<ExpressionConfidence> Create(std::vector<std::vector<float>> observed,
                                             const ConfidenceOptions& options);

  // beta must have expression_dim() values (checked: a programming error otherwise).
  NearestExpression Nearest(std::span<const float> beta) const;

  const std::vector<float>& observed(int k) const { return observed_[k]; }
  int num_observed() const { return int(observed_.size()); }
  int expression_dim() const { return observed_.empty() ? 0 : int(observed_[0].size()); }
  const ConfidenceOptions& options() const { return options_; }
  std::string ToString() const;

 private:
  ExpressionConfidence() = default;
  std::vector<std::vector<float>> observed_;  // [K][B]
  ConfidenceOptions options_;
};

}  // namespace icef
