#include "icef/model/method.h"

namespace icef {

MethodTraits TraitsOf(Method method) {
  MethodTraits t;
  switch (method) {
    case Method::kIcef: break;
    case Method::kIcefNoId: t.identity_losses = false; break;
    case Method::kIcefNoConf: t.confidence = false; break;
    case Method::kIcefUniform: t.uniform_mask = true; break;
    case Method::kWarp: t.identity_losses = false, t.confidence = false; break;
    case Method::kNerface:
      t.deformation = false, t.identity_losses = false, t.confidence = false, t.entangled_beta = true;
      break;
    case Method::kIcefPrior: t.prior = true; break;
    case Method::kWarpPrior: t.prior = true, t.identity_losses = false, t.confidence = false; break;
  }
  return t;
}

const char* MethodName(Method method) {
  switch (method) {
    case Method::kIcef: return "icef";
    case Method::kIcefNoId: return "icef-no-id";
    case Method::kIcefNoConf: return "icef-no-conf";
    case Method::kIcefUniform: return "icef-uniform";
    case Method::kWarp: return "warp";
    case Method::kNerface: return "nerface";
    case Method::kIcefPrior: return "icef-prior";
    case Method::kWarpPrior: return "warp-prior";
  }
  return "?";
}

const std::vector<Method>& AllMethods() {
  static const std::vector<Method> kAll = {Method::kIcef, Method::kIcefNoId, Method::kIcefNoConf, Method::kIcefUniform,
                                           Method::kWarp, Method::kNerface, Method::kIcefPrior, Method::kWarpPrior};
  return kAll;
}

Result<Method> ParseMethod(const std::string& name) {
  std::string valid;
  for (Method m : AllMethods()) {
    if (name == MethodName(m)) return m;
    valid += (valid.empty() ? "" : ", ") + std::string(MethodName(m));
  }
  return Status::Error("unknown method '" + name + "' (valid: " + valid + ")");
}

}  // namespace icef
