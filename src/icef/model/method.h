// The methods compared (docs/design.md §2): one engine, one code path, differing only in these switches.
//
//   icef          deformation + static field + L_id + L_smooth + confidence-weighted warping
//   icef-no-id    as icef with lambda_id = lambda_smooth = 0
//   icef-no-conf  as icef with kappa = 1 always (no linearised fallback)
//   icef-uniform  as icef with the region mask M = 0 everywhere in L_id (deformation damped
//                 everywhere; isolates the landmark mask from plain damping; L_smooth, which acts
//                 on the mask's boundary, has nothing to act on)
//   warp          deformation + static field only: no L_id, no L_smooth, no confidence
//   nerface       no deformation: beta is concatenated into the static field's density-MLP input
//                 (no canonical space, so the left-right symmetry prior does not apply to it)
//   icef-prior    icef on the face-model prior (docs/design.md §2.1): D = P + R_phi, L_id / L_smooth on
//                 R_phi, confidence blends R_phi with its linearisation R_lin
//   warp-prior    the face-model prior plus an unregularised residual (no L_id, no L_smooth, no
//                 confidence)
//
// `warp` and `icef-no-id` train the same model (confidence acts only at render time); the bench
// runs `warp` as the baseline and leaves `icef-no-id` out by default.
#pragma once

#include <string>
#include <vector>

#include "icef/core/status.h"

namespace icef {

enum class Method { kIcef, kIcefNoId, kIcefNoConf, kIcefUniform, kWarp, kNerface, kIcefPrior, kWarpPrior };

struct MethodTraits {
  bool deformation = true;      // observation -> canonical warp D_phi
  bool identity_losses = true;  // L_id and L_smooth active (their lambdas apply)
  bool confidence = true;       // kappa-weighted blend with the linearised warp at inference
  bool entangled_beta = false;  // beta fed into the static field (NerFace-style)
  bool uniform_mask = false;    // L_id with M = 0 everywhere instead of the landmark mask
  bool prior = false;           // the fitted face model's warp P under the learned residual
};

MethodTraits TraitsOf(Method method);
const char* MethodName(Method method);
// The error lists the valid names.
Result<Method> ParseMethod(const std::string& name);
const std::vector<Method>& AllMethods();
// True for the methods that need the face-model fit (ModelSetup::face_fit).
inline bool UsesFacePrior(Method method) {
  return method == Method::kIcefPrior || method == Method::kWarpPrior;
}

}  // namespace icef
