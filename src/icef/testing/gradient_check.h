// The gradient-check harness (test-only, header): central finite differences in double for the
// kernels' hand-written backward passes and JVPs, and a check of a whole model's parameter
// gradients against differences of its loss.
#pragma once

#include <algorithm>
#include <cmath>
#include <functional>
#include <span>
#include <sstream>
#include <string>
#include <vector>

#include "icef/core/rng.h"

namespace icef::testing {

inline std::vector<double> RandomVector(size_t n, uint64_t seed, uint64_t purpose, double lo, double hi) {
  Rng rng(seed, purpose);
  std::vector<double> v(n);
  for (double& x : v) x = rng.Uniform(lo, hi);
  return v;
}

// Largest |analytic_i - numeric_i| / max(|analytic_i|, |numeric_i|, floor) over the indices (all
// when empty), numeric_i by central differences (step h) of loss() w.r.t. (*values)[i]. The floor,
// 1e-4 of the largest analytic gradient, keeps round-off on (near-)zero entries from dominating;
// every entry above it is checked relatively, so a wrong index fails.
inline double MaxRelativeError(std::vector<double>* values, const std::vector<double>& analytic,
                               const std::function<double()>& loss, const std::vector<size_t>& indices = {},
                               double h = 1e-5) {
  double largest = 0.0;
  for (double a : analytic) largest = std::max(largest, std::abs(a));
  const double floor = std::max(1e-4 * largest, 1e-12);
  double worst = 0.0;
  auto check = [&](size_t i) {
    const double saved = (*values)[i];
    (*values)[i] = saved + h;
    const double lp = loss();
    (*values)[i] = saved - h;
    const double lm = loss();
    (*values)[i] = saved;
    const double numeric = (lp - lm) / (2.0 * h);
    const double err = std::abs(analytic[i] - numeric) / std::max({std::abs(analytic[i]), std::abs(numeric), floor});
    worst = std::max(worst, err);
  };
  if (indices.empty()) {
    for (size_t i = 0; i < values->size(); ++i) check(i);
  } else {
    for (size_t i : indices) check(i);
  }
  return worst;
}

inline double Dot(const std::vector<double>& a, const std::vector<double>& b) {
  double s = 0.0;
  for (size_t i = 0; i < a.size(); ++i) s += a[i] * b[i];
  return s;
}

// A model's parameter gradients (float parameters, as trained) against central differences of its
// loss, on the `top_k` parameters with the largest analytic gradient. The step is
// max(min_step, rel_step |p|). The hash grid is trilinear, so its position derivative jumps at cell
// faces: with skip_kinks, a parameter whose differences at h and h/2 disagree (its stencil
// straddles a face, so neither is a derivative) is skipped, and at least min_checked must remain.
struct ParameterGradientCheck {
  int top_k = 12;
  float rel_step = 1e-3f;
  float min_step = 1e-3f;
  bool skip_kinks = true;
  double kink_tol = 0.01;  // relative disagreement of the two differences that marks a kink
  double rel_tol = 3e-2;   // |analytic - numeric| <= rel_tol |numeric| + abs_tol_frac max|analytic| + abs_tol
  double abs_tol_frac = 2e-3;
  double abs_tol = 0.0;
  int min_checked = 6;

  struct Report {
    int checked = 0;
    std::string failures;  // one line per mismatch, or too few checked; empty when the check passed
    bool ok() const { return failures.empty(); }
  };
  // params [n] are perturbed in place (and restored); analytic [n]; loss() evaluates at params.
  Report Run(float* params, std::span<const double> analytic, const std::function<double()>& loss) const {
    const int64_t n = static_cast<int64_t>(analytic.size());
    std::vector<int64_t> order(n);
    for (int64_t i = 0; i < n; ++i) order[i] = i;
    const int64_t k = std::min<int64_t>(top_k, n);
    std::partial_sort(order.begin(), order.begin() + k, order.end(),
                      [&](int64_t a, int64_t b) { return std::abs(analytic[a]) > std::abs(analytic[b]); });
    const double largest = k > 0 ? std::abs(analytic[order[0]]) : 0.0;
    auto numeric = [&](int64_t i, float h) {
      const float saved = params[i];
      params[i] = saved + h;
      const double lp = loss();
      params[i] = saved - h;
      const double lm = loss();
      params[i] = saved;
      return (lp - lm) / (2.0 * (double(saved + h) - double(saved)));  // the step as float represents it
    };
    Report report;
    std::ostringstream failures;
    for (int64_t j = 0; j < k; ++j) {
      const int64_t i = order[j];
      const float h = std::max(min_step, rel_step * std::abs(params[i]));
      double fd = numeric(i, h);
      if (skip_kinks) {
        const double fd_half = numeric(i, 0.5f * h);
        if (std::abs(fd - fd_half) > kink_tol * std::abs(fd_half) + 1e-3 * largest) continue;
        fd = fd_half;
      }
      ++report.checked;
      const double tol = rel_tol * std::abs(fd) + abs_tol_frac * largest + abs_tol;
      if (!(std::abs(analytic[i] - fd) <= tol))
        failures << "parameter " << i << ": analytic " << analytic[i] << ", numeric " << fd << " (tolerance " << tol
                 << ")\n";
    }
    if (report.checked < std::min<int64_t>(min_checked, k))
      failures << "only " << report.checked << " of " << k << " parameters checked (the rest straddle kinks)\n";
    if (largest == 0.0) failures << "every analytic gradient is zero\n";
    report.failures = failures.str();
    return report;
  }
};

}  // namespace icef::testing
