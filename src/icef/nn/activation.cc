#include "icef/nn/activation.h"

#include "icef/core/enum_table.h"

namespace icef::nn {

namespace {

constexpr std::array<EnumEntry<Activation>, 4> kActivationNames = {{{Activation::kNone, "none"},
                                                                    {Activation::kRelu, "relu"},
                                                                    {Activation::kSigmoid, "sigmoid"},
                                                                    {Activation::kExp, "exp"}}};

}  // namespace

std::string ActivationName(Activation a) { return EnumName(kActivationNames, a); }

Result<Activation> ParseActivation(const std::string& name) {
  if (const std::optional<Activation> a = ParseEnum(kActivationNames, name)) return *a;
  return Status::Error("unknown activation '" + name + "' (valid: " + EnumNames(kActivationNames) + ")");
}

}  // namespace icef::nn
