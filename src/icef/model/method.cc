#include "icef/model/method.h"

#include "icef/core/enum_table.h"

namespace icef {

MethodTraits TraitsOf(Method method) {
  MethodTraits t;
  switch (method) {
    case Method::kIcef:
      break;
    case Method::kIcefNoId:
      t.identity_losses = false;
      break;
    case Method::kIcefNoConf:
      t.confidence = false;
      break;
    case Method::kIcefUniform:
      t.uniform_mask = true;
      break;
    case Method::kWarp:
      t.identity_losses = false, t.confidence = false;
      break;
    case Method::kNerface:
      t.deformation = false, t.identity_losses = false, t.confidence = false, t.entangled_beta = true;
      break;
    case Method::kIcefPrior:
      t.prior = true;
      break;
    case Method::kWarpPrior:
      t.prior = true, t.identity_losses = false, t.confidence = false;
      break;
  }
  return t;
}

namespace {

constexpr std::array<EnumEntry<Method>, 8> kMethodNames = {{{Method::kIcef, "icef"},
                                                            {Method::kIcefNoId, "icef-no-id"},
                                                            {Method::kIcefNoConf, "icef-no-conf"},
                                                            {Method::kIcefUniform, "icef-uniform"},
                                                            {Method::kWarp, "warp"},
                                                            {Method::kNerface, "nerface"},
                                                            {Method::kIcefPrior, "icef-prior"},
                                                            {Method::kWarpPrior, "warp-prior"}}};

}  // namespace

const char* MethodName(Method method) { return EnumName(kMethodNames, method); }

const std::vector<Method>& AllMethods() {
  static const std::vector<Method> kAll = [] {
    std::vector<Method> all;
    for (const EnumEntry<Method>& e : kMethodNames) all.push_back(e.value);
    return all;
  }();
  return kAll;
}

Result<Method> ParseMethod(const std::string& name) {
  if (const std::optional<Method> m = ParseEnum(kMethodNames, name)) return *m;
  return Status::Error("unknown method '" + name + "' (valid: " + EnumNames(kMethodNames) + ")");
}

}  // namespace icef
