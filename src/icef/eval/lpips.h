// LPIPS v0.1 (Zhang et al. 2018), AlexNet variant: the learned perceptual distance between two
// images. No package we can reach ships the weights, so they come from a file the user provides
// (scripts/convert_lpips_weights.py converts the official PyTorch weights); without one LPIPS is
// unavailable (std::nullopt / JSON null), never invented.
//
// Network: x in [0, 1] -> 2x - 1 -> (x - shift) / scale with shift = [-0.030, -0.088, -0.188],
// scale = [0.458, 0.448, 0.450]; AlexNet features (torchvision layout):
//   conv1 11x11 /4 pad 2 -> ReLU [tap 1] -> max-pool 3x3/2 -> conv2 5x5 pad 2 -> ReLU [tap 2]
//   -> max-pool 3x3/2 -> conv3 3x3 pad 1 -> ReLU [tap 3] -> conv4 3x3 pad 1 -> ReLU [tap 4]
//   -> conv5 3x3 pad 1 -> ReLU [tap 5]
// For each tap: unit-normalise both feature maps over channels (f / (||f|| + 1e-10)), square the
// difference, weight channels by the non-negative linear head lin{i} (1x1 conv, no bias), average
// over pixels; LPIPS is the sum over the five taps. Inputs must be at least 31x31 pixels.
//
// Weights file (docs/evaluation.md), little-endian:
//   8 bytes magic "ICEFLPIP", uint32 version (1), uint32 tensor count, then per tensor:
//   uint32 name length, name bytes, uint32 rank, rank x uint32 dims, float32 values (row-major).
// Tensors, PyTorch layouts: conv{1..5}.weight [out, in, kh, kw], conv{1..5}.bias [out],
// lin{0..4}.weight [1, C_i, 1, 1] where C_i is conv{i+1}'s out. Kernel sizes must be AlexNet's
// (11, 5, 3, 3, 3); channel widths are read from the file (official: 64, 192, 384, 256, 256).
#pragma once

#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "icef/core/status.h"
#include "icef/infer/cnn_layers.h"
#include "icef/io/image.h"

namespace icef::eval {

constexpr int kLpipsLayers = 5;
constexpr int kLpipsMinSize = 31;
// Where scripts/convert_lpips_weights.py writes by default; never installed by us.
constexpr const char* kLpipsWeightsFileName = "lpips_alex_v0.1.bin";

struct LpipsWeights {
  std::array<infer::ConvWeights, kLpipsLayers> conv;  // HWIO filters + bias, AlexNet conv1..conv5
  std::array<std::vector<float>, kLpipsLayers> lin;   // [C_i] linear-head weights
  std::string ToString() const;
};

// Reads / writes the file format above. Errors name the file and the tensor.
Result<LpipsWeights> ReadLpipsWeights(const std::filesystem::path& path);
Status WriteLpipsWeights(const std::filesystem::path& path, const LpipsWeights& weights);
// Checks kernel sizes, chained channel counts and head sizes; `source` prefixes errors.
Status ValidateLpipsWeights(const LpipsWeights& weights, const std::string& source);

class LpipsNet {
 public:
  static Result<LpipsNet> Load(const std::filesystem::path& path);
  static Result<LpipsNet> FromWeights(LpipsWeights weights, const std::string& source);

  // LPIPS between two images of equal size (RGB; alpha ignored), values in [0, 1].
  Result<double> Distance(const Image& a, const Image& b) const;
  // The five tapped feature maps of one image (after the scaling layer).
  std::array<infer::Tensor3, kLpipsLayers> Features(const Image& image) const;

  const std::string& source() const { return source_; }
  std::string ToString() const;

 private:
  LpipsWeights weights_;
  std::string source_;
};

// `path` empty -> std::nullopt (LPIPS unavailable); otherwise the loaded network or its error.
Result<std::optional<LpipsNet>> LoadLpipsIfConfigured(const std::string& path);

}  // namespace icef::eval
