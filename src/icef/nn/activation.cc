#include "icef/nn/activation.h"

namespace icef::nn {

std::string ActivationName(Activation a) {
  switch (a) {
    case Activation::kNone: return "none";
    case Activation::kRelu: return "relu";
    case Activation::kSigmoid: return "sigmoid";
    case Activation::kExp: return "exp";
  }
  return "?";
}

Result<Activation> ParseActivation(const std::string& name) {
  for (Activation a : {Activation::kNone, Activation::kRelu, Activation::kSigmoid, Activation::kExp}) {
    if (ActivationName(a) == name) return a;
  }
  return Status::Error("unknown activation '" + name + "' (valid: none, relu, sigmoid, exp)");
}

}  // namespace icef::nn
