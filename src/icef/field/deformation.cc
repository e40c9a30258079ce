#include "icef/field/deformation.h"

#include <algorithm>
#include <sstream>

namespace icef {

namespace {
// out[i] += k * v[i] for i in [0, n), split over the executor's threads.
void AddScaled(const Executor& executor, int64_t n, float k, const float* v, float* out) {
  ParallelFor(executor, n, [&](int64_t i0, int64_t i1, int) {
    for (int64_t i = i0; i < i1; ++i) out[i] += k * v[i];
  });
}
}  // namespace

void BroadcastExpression(std::span<const float> beta, int64_t n, std::vector<float>* rows) {
  const size_t b = beta.size();
  rows->resize(static_cast<size_t>(n) * b);
  for (int64_t i = 0; i < n; ++i) std::copy(beta.begin(), beta.end(), rows->begin() + i * b);
}

Deformation::Deformation(DeformationField* residual, const DeformationPrior* prior,
                         const ExpressionConfidence* confidence, bool blend)
    : residual_(residual), prior_(prior), confidence_(confidence), blend_(blend) {
  ICEF_CHECK(confidence_ != nullptr, "the deformation needs the training expressions' confidence");
}

void Deformation::ForwardTrain(const Executor& executor, int64_t n, const float* positions,
                               const float* betas, float* offsets, float* residual_offsets,
                               DeformationContext* ctx, bool keep_for_backward) const {
  if (residual_) {
    residual_->Forward(executor, n, positions, betas, offsets, ctx, keep_for_backward);
    if (residual_offsets) std::copy(offsets, offsets + 3 * n, residual_offsets);
  } else {
    std::fill(offsets, offsets + 3 * n, 0.f);
    if (residual_offsets) std::fill(residual_offsets, residual_offsets + 3 * n, 0.f);
  }
  if (prior_) {
    std::vector<float> p(3 * n);
    prior_->Offsets(executor, n, positions, betas, p.data());
    for (int64_t i = 0; i < 3 * n; ++i) offsets[i] += p[i];
  }
}

void Deformation::Backward(const Executor& executor, int64_t n, const float* d_offsets,
                           DeformationContext* ctx) {
  if (residual_) residual_->Backward(executor, n, d_offsets, ctx);
}

double Deformation::Kappa(std::span<const float> beta) const {
  return blend_ ? confidence_->Nearest(beta).kappa : 1.0;
}

void Deformation::Offsets(const Executor& executor, int64_t n, const float* positions,
                          std::span<const float> beta, float* offsets, DeformationWorkspace* ws,
                          WarpPart part) const {
  BroadcastExpression(beta, n, &ws->betas);
  std::fill(offsets, offsets + 3 * n, 0.f);
  if (prior_) prior_->Offsets(executor, n, positions, ws->betas.data(), offsets);
  if (!residual_) return;
  const NearestExpression near = confidence_->Nearest(beta);
  double kappa = 1.0;
  if (part == WarpPart::kLinearized) kappa = 0.0;
  if (part == WarpPart::kFinal && blend_) kappa = near.kappa;
  ws->residual.resize(3 * n);
  if (kappa > 0.0) {
    residual_->Forward(executor, n, positions, ws->betas.data(), ws->residual.data(), &ws->ctx, false);
    AddScaled(executor, 3 * n, static_cast<float>(kappa), ws->residual.data(), offsets);
  }
  if (kappa < 1.0) {
    const std::vector<float>& anchor = confidence_->observed(near.index);
    BroadcastExpression(anchor, n, &ws->anchors);
    ws->tangents = ws->betas;
    AddScaled(executor, int64_t(ws->tangents.size()), -1.f, ws->anchors.data(), ws->tangents.data());
    ws->lin.resize(3 * n);
    residual_->LinearizedForward(executor, n, positions, ws->anchors.data(), ws->tangents.data(),
                                 ws->lin.data(), &ws->ctx);
    AddScaled(executor, 3 * n, static_cast<float>(1.0 - kappa), ws->lin.data(), offsets);
  }
}

void Deformation::Cavity(const Executor& executor, int64_t n, const float* positions, const float* betas,
                         uint8_t* inside) const {
  if (prior_) {
    prior_->Cavity(executor, n, positions, betas, inside);
  } else {
    std::fill(inside, inside + n, uint8_t{0});
  }
}

std::string Deformation::ToString() const {
  std::ostringstream os;
  os << "Deformation(residual=" << (residual_ ? residual_->ToString() : "none")
     << ", prior=" << (prior_ ? prior_->ToString() : "none") << ", blend=" << (blend_ ? "on" : "off") << ")";
  return os.str();
}

}  // namespace icef
