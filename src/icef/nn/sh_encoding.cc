#include "icef/nn/sh_encoding.h"

namespace icef::nn {

Status ShEncodingOptions::Validate() const {
  if (degree < 1 || degree > 4) return Status::Error("sh_encoding.degree: must be in [1, 4]");
  return Status::Ok();
}

ShEncoding::ShEncoding(const ShEncodingOptions& options) : options_(options) {
  const Status st = options.Validate();
  ICEF_CHECK(st.ok(), st.message());
}

void ShEncoding::Forward(const Executor& executor, int64_t n, const float* directions, float* y) const {
  const int out = output_dims();
  ParallelFor(executor, n, [&](int64_t b, int64_t e, int) {
    ShForward<float>(options_.degree, e - b, directions + 3 * b, y + b * out);
  });
}

void ShEncoding::Backward(const Executor& executor, int64_t n, const float* directions, const float* dy,
                          float* d_directions) const {
  const int out = output_dims();
  ParallelFor(executor, n, [&](int64_t b, int64_t e, int) {
    ShBackward<float>(options_.degree, e - b, directions + 3 * b, dy + b * out, d_directions + 3 * b);
  });
}

}  // namespace icef::nn
