// A fixed, known part of the deformation (docs/design.md §2.1): P(x, beta), an observation point's
// canonical point as a face model predicts it. It has no parameters, so it is only evaluated,
// never differentiated. The learned residual R_phi (DeformationField) is added on top of it.
#pragma once

#include <cstdint>
#include <string>

#include "icef/core/parallel.h"

namespace icef {

class DeformationPrior {
 public:
  virtual ~DeformationPrior() = default;

  // Cavity's labels.
  enum PriorMaterial : uint8_t { kField = 0, kMouthCavity = 1, kTeeth = 2, kAir = 3 };

  // positions [n, 3] world frame, betas [n, B] (each sample's expression) -> offsets [n, 3] world
  // frame: P(x_i, beta_i) - x_i.
  virtual void Offsets(const Executor& executor, int64_t n, const float* positions, const float* betas,
                       float* offsets) const = 0;

  // What the face model puts at x_i at beta_i that no canonical point stands for, per sample
  // (PriorMaterial): kMouthCavity in an open mouth's interior, kTeeth inside teeth an open mouth
  // shows (priors whose model has teeth: has_teeth()), kAir where the warp would carry the air
  // between parted lips into the closed lips at rest, else kField (the warped static field).
  virtual void Cavity(const Executor& executor, int64_t n, const float* positions, const float* betas,
                      uint8_t* inside) const = 0;
  virtual bool has_teeth() const { return false; }

  // Surface normals of the face model, world frame: canonical [n, 3] of the neutral surface at
  // P(x_i, beta_i); observed [n, 3] that normal carried back through the warp (J^T n normalised,
  // J = dP/dx at x_i): the normal at x_i of the surface P makes of the neutral one. The two are
  // equal where P(., beta_i) is a translation. False: the prior has none.
  virtual bool Normals(const Executor& executor, int64_t n, const float* positions, const float* betas,
                       float* observed, float* canonical) const {
    (void)executor, (void)n, (void)positions, (void)betas, (void)observed, (void)canonical;
    return false;
  }

  virtual int expression_dims() const = 0;
  virtual std::string ToString() const = 0;
};

}  // namespace icef
