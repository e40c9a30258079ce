// Test-only helpers (header, not part of the library): central finite differences in double.
#pragma once

#include <algorithm>
#include <cmath>
#include <functional>
#include <vector>

#include "icef/core/rng.h"

namespace icef::nn::testing {

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

}  // namespace icef::nn::testing
