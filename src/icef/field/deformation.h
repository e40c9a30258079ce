// The deformation of docs/design.md §2 and §2.1 as one component: an observation point x at expression
// beta maps to the canonical point x + offset with
//   training (beta a training expression, kappa = 1):  offset = (P(x, beta) - x) + R_phi(x, beta)
//   any expression (confidence-weighted warping):       offset = (P(x, beta) - x)
//                                                               + kappa R_phi(x, beta) + (1 - kappa) R_lin(x,
//                                                               beta)
// where P is the optional face-model prior (absent: P(x) = x, the paper's D_phi = x + R_phi),
// R_phi the learned field (DeformationField) and R_lin its JVP linearisation around the nearest
// training expression beta_n. kappa comes from ExpressionConfidence; methods without the blend
// (blend = false) use kappa = 1 everywhere. The blend and the broadcast of one expression to many samples
// live here only; training, rendering and the occupancy grids all call this component.
#pragma once

#include <span>
#include <vector>

#include "icef/field/confidence.h"
#include "icef/field/deformation_field.h"
#include "icef/field/deformation_prior.h"

namespace icef {

// Which part of the warp Offsets returns (tests and tools compare them).
enum class WarpPart {
  kFinal,       // (P - x) + kappa R_phi + (1 - kappa) R_lin
  kPhi,         // (P - x) + R_phi  (kappa forced to 1)
  kLinearized,  // (P - x) + R_lin  (kappa forced to 0)
};

// Reusable buffers of one caller (not shared between threads).
struct DeformationWorkspace {
  std::vector<float> betas, anchors, tangents, lin, residual;
  DeformationContext ctx;
};

// rows [n, B] = n copies of beta: the one place an expression is broadcast to samples.
void BroadcastExpression(std::span<const float> beta, int64_t n, std::vector<float>* rows);

class Deformation {
 public:
  // residual and prior may each be null; confidence (the training expressions and kappa's length
  // scale) must be given. blend = false: kappa = 1 for every expression. The pointees must outlive
  // this object.
  Deformation(DeformationField* residual, const DeformationPrior* prior,
              const ExpressionConfidence* confidence, bool blend);

  bool has_prior() const { return prior_ != nullptr; }
  DeformationField* residual() { return residual_; }
  const DeformationField* residual() const { return residual_; }
  const DeformationPrior* prior() const { return prior_; }

  // Training: betas [n, B] per sample (training expressions). offsets = (P - x) + R_phi; when
  // residual_offsets is non-null it receives R_phi alone (what L_id regularises).
  void ForwardTrain(const Executor& executor, int64_t n, const float* positions, const float* betas,
                    float* offsets, float* residual_offsets, DeformationContext* ctx,
                    bool keep_for_backward) const;
  // After ForwardTrain(keep_for_backward): d loss / d offsets [n, 3] into R_phi's parameters (P has none).
  void Backward(const Executor& executor, int64_t n, const float* d_offsets, DeformationContext* ctx);

  // One expression for all n samples, confidence-weighted (see WarpPart).
  void Offsets(const Executor& executor, int64_t n, const float* positions, std::span<const float> beta,
               float* offsets, DeformationWorkspace* ws, WarpPart part = WarpPart::kFinal) const;

  // inside [n] (see DeformationPrior::Cavity); all 0 without a prior.
  void Cavity(const Executor& executor, int64_t n, const float* positions, const float* betas,
              uint8_t* inside) const;

  // The prior's surface normals (DeformationPrior::Normals); false without a prior that has them.
  bool Normals(const Executor& executor, int64_t n, const float* positions, const float* betas,
               float* observed, float* canonical) const {
    return prior_ && prior_->Normals(executor, n, positions, betas, observed, canonical);
  }

  // kappa of the blend at beta (1 without the blend).
  double Kappa(std::span<const float> beta) const;
  std::string ToString() const;

 private:
  DeformationField* residual_;
  const DeformationPrior* prior_;
  const ExpressionConfidence* confidence_;
  bool blend_;
};

}  // namespace icef
