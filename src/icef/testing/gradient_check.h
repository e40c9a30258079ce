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
    const double err =
        std::abs(analytic[i] - numeric) / std::max({std::abs(analytic[i]), std::abs(numeric), floor});
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
// max(min_step, rel_step |p|). The hash grid is trilinear and the MLPs are ReLU, so derivatives
// jump at cell faces and activation boundaries. With skip_kinks, a parameter whose stencil
// straddles such a kink (neither difference is then a derivative) is skipped, and at least
// min_checked must remain. A kink at distance d inside a stencil of half-width h shows as
//   - central differences at h and h/2 that disagree: by |jump| d / 2h, which catches kinks
//     towards the stencil's ends but vanishes as d -> 0 (both then average the two slopes);
//   - one-sided slopes (f(p+h) - f(p)) / h and (f(p) - f(p-h)) / h that differ by nearly the whole
//     jump, |jump| (1 - d/h), at h and at h/2 alike, which catches kinks near the parameter.
//     Smooth curvature also parts them, by h |f''|, but halves with the step: the second rule
//     fires only when the parting at h/2 is over 3/4 of that at h.
// Between them every kink whose jump exceeds a few kink_tol of the gradient is skipped.
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
    // Central difference and the one-sided slopes' parting (f(p+h) - 2 f(p) + f(p-h)) / h at step h.
    struct Differences {
      double central = 0, parting = 0;
    };
    const double at_params = loss();
    auto differences = [&](int64_t i, float h) {
      const float saved = params[i];
      params[i] = saved + h;
      const double lp = loss();
      params[i] = saved - h;
      const double lm = loss();
      params[i] = saved;
      const double up = double(saved + h) - double(saved),
                   down = double(saved) - double(saved - h);  // as float holds them
      return Differences{(lp - lm) / (up + down), (lp - at_params) / up - (at_params - lm) / down};
    };
    Report report;
    std::ostringstream failures;
    for (int64_t j = 0; j < k; ++j) {
      const int64_t i = order[j];
      const float h = std::max(min_step, rel_step * std::abs(params[i]));
      const Differences full = differences(i, h);
      double fd = full.central;
      if (skip_kinks) {
        const Differences half = differences(i, 0.5f * h);
        const double tol = kink_tol * std::abs(half.central) + 1e-3 * largest;
        if (std::abs(full.central - half.central) > tol) continue;  // a kink towards the stencil's ends
        if (std::abs(half.parting) > tol && std::abs(half.parting) > 0.75 * std::abs(full.parting))
          continue;  // a kink near the parameter
        fd = half.central;
      }
      ++report.checked;
      const double tol = rel_tol * std::abs(fd) + abs_tol_frac * largest + abs_tol;
      if (!(std::abs(analytic[i] - fd) <= tol))
        failures << "parameter " << i << ": analytic " << analytic[i] << ", numeric " << fd << " (tolerance "
                 << tol << ")\n";
    }
    if (report.checked < std::min<int64_t>(min_checked, k))
      failures << "only " << report.checked << " of " << k
               << " parameters checked (the rest straddle kinks)\n";
    if (largest == 0.0) failures << "every analytic gradient is zero\n";
    report.failures = failures.str();
    return report;
  }
};

}  // namespace icef::testing
