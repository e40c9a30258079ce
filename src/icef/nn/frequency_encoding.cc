#include "icef/nn/frequency_encoding.h"

#include <algorithm>
#include <sstream>

namespace icef::nn {

Status FrequencyEncodingOptions::Validate() const {
  if (input_dims < 1) return Status::Error("frequency_encoding.input_dims: must be >= 1");
  if (num_frequencies < 0 || num_frequencies > 24) {
    return Status::Error("frequency_encoding.num_frequencies: must be in [0, 24]");
  }
  if (output_dims() < 1) return Status::Error("frequency_encoding: empty output (no input, no frequencies)");
  return Status::Ok();
}

std::string FrequencyEncodingOptions::ToString() const {
  std::ostringstream s;
  s << "FrequencyEncodingOptions(d=" << input_dims << ", N=" << num_frequencies
    << ", include_input=" << (include_input ? "true" : "false") << ", out=" << output_dims() << ")";
  return s.str();
}

double AnnealingWeight(double alpha, int k) {
  const double t = std::clamp(alpha - k, 0.0, 1.0);
  return 0.5 * (1.0 - std::cos(3.14159265358979323846 * t));
}

FrequencyEncoding::FrequencyEncoding(const FrequencyEncodingOptions& options) : options_(options) {
  const Status st = options.Validate();
  ICEF_CHECK(st.ok(), st.message());
  SetAlpha(options.num_frequencies);
}

void FrequencyEncoding::SetAlpha(double alpha) {
  alpha_ = std::clamp(alpha, 0.0, static_cast<double>(options_.num_frequencies));
  weights_.resize(options_.num_frequencies);
  weights_double_.resize(options_.num_frequencies);
  for (int k = 0; k < options_.num_frequencies; ++k) {
    weights_double_[k] = AnnealingWeight(alpha_, k);
    weights_[k] = static_cast<float>(weights_double_[k]);
  }
}

void FrequencyEncoding::Forward(const Executor& executor, int64_t n, const float* x, float* y) const {
  const int d = input_dims(), out = output_dims();
  ParallelFor(executor, n, [&](int64_t b, int64_t e, int) {
    FrequencyForward<float>(options_, weights_.data(), e - b, x + b * d, y + b * out);
  });
}

void FrequencyEncoding::Backward(const Executor& executor, int64_t n, const float* x, const float* dy,
                                 float* dx) const {
  const int d = input_dims(), out = output_dims();
  ParallelFor(executor, n, [&](int64_t b, int64_t e, int) {
    FrequencyBackward<float>(options_, weights_.data(), e - b, x + b * d, dy + b * out, dx + b * d);
  });
}

void FrequencyEncoding::Jvp(const Executor& executor, int64_t n, const float* x, const float* v, float* y,
                            float* jy) const {
  const int d = input_dims(), out = output_dims();
  ParallelFor(executor, n, [&](int64_t b, int64_t e, int) {
    FrequencyJvp<float>(options_, weights_.data(), e - b, x + b * d, v + b * d, y + b * out, jy + b * out);
  });
}

std::string FrequencyEncoding::ToString() const {
  return "FrequencyEncoding(" + options_.ToString() + ", alpha=" + std::to_string(alpha_) + ")";
}

}  // namespace icef::nn
