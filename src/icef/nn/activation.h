// Output activations of an Mlp (hidden layers are always ReLU, as in tiny-cuda-nn). Each
// activation's derivative is computed from its OUTPUT value y, so a backward pass needs only the
// stored outputs: relu' = [y > 0], sigmoid' = y (1 - y), exp' = y, none' = 1.
#pragma once

#include <cmath>
#include <string>

#include "icef/core/status.h"

namespace icef::nn {

enum class Activation { kNone, kRelu, kSigmoid, kExp };

// "none", "relu", "sigmoid", "exp".
std::string ActivationName(Activation a);
// Inverse of ActivationName; the error lists the valid names.
Result<Activation> ParseActivation(const std::string& name);

template <typename T>
inline T ApplyActivation(Activation a, T x) {
  switch (a) {
    case Activation::kNone:
      return x;
    case Activation::kRelu:
      return x > T(0) ? x : T(0);
    case Activation::kSigmoid:
      return T(1) / (T(1) + std::exp(-x));
    case Activation::kExp:
      return std::exp(x);
  }
  return x;
}

// d activation / d pre-activation, as a function of the activation's output y.
template <typename T>
inline T ActivationDerivativeFromOutput(Activation a, T y) {
  switch (a) {
    case Activation::kNone:
      return T(1);
    case Activation::kRelu:
      return y > T(0) ? T(1) : T(0);
    case Activation::kSigmoid:
      return y * (T(1) - y);
    case Activation::kExp:
      return y;
  }
  return T(1);
}

}  // namespace icef::nn
