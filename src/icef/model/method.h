// The methods compared (DESIGN.md §2): one engine, one code path, differing only in these switches.
//
//   icef          deformation + static field + L_id + L_smooth + confidence-weighted warping
//   icef-no-id    as icef with lambda_id = lambda_smooth = 0
//   icef-no-conf  as icef with kappa = 1 always (no linearised fallback)
//   warp          deformation + static field only: no L_id, no L_smooth, no confidence
//   nerface       no deformation: beta is concatenated into the static field's density-MLP input
#pragma once

#include <string>
#include <vector>

#include "icef/core/status.h"

namespace icef {

enum class Method { kIcef, kIcefNoId, kIcefNoConf, kWarp, kNerface };

struct MethodTraits {
  bool deformation = true;       // observation -> canonical warp D_phi
  bool identity_losses = true;   // L_id and L_smooth active (their lambdas apply)
  bool confidence = true;        // kappa-weighted blend with the linearised warp at inference
  bool entangled_beta = false;   // beta fed into the static field (NerFace-style)
};

MethodTraits TraitsOf(Method method);
const char* MethodName(Method method);
// The error lists the valid names.
Result<Method> ParseMethod(const std::string& name);
const std::vector<Method>& AllMethods();

}  // namespace icef
