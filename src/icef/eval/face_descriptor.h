// dlib's 128-D face descriptor (dlib_face_recognition_resnet_model_v1: a 29-conv ResNet trained to
// put different people more than 0.6 apart in Euclidean distance), run by our own code with the
// weights shipped in the npm package @vladmandic/face-api@1.7.15 (TF.js manifest,
// `face_recognition_model-weights_manifest.json` + `face_recognition_model.bin`).
//
// Architecture (dlib's anet_type; layer names as in the manifest):
//   input 150x150 RGB, v -> (v - [122.782, 117.001, 104.298]) / 256   (v in 0..255, dlib's scaling)
//   conv32_down: conv 7x7/2 valid + bias -> affine -> ReLU -> max-pool 3x3/2 valid   [35x35x32]
//   conv32_{1,2,3}: residual                                                         [35x35x32]
//   conv64_down, conv64_{1,2,3}                                                      [17x17x64]
//   conv128_down, conv128_{1,2}                                                      [8x8x128]
//   conv256_down, conv256_{1,2}                                                      [4x4x256]
//   conv256_down_out                                                                 [2x2x256]
//   global mean -> fc 256 -> 128 (no bias)
// residual:  relu(x + affine(conv3x3(relu(affine(conv3x3(x))))))      (3x3 'same', stride 1)
// down:      relu(avgpool2x2/2(x) (+ zero channels) + branch), branch = affine(conv3x3 s1 same(
//            relu(affine(conv3x3 s2 valid(x))))), zero-padded at the bottom/right where it comes
//            out smaller than the pooled shortcut (dlib's add_prev).
#pragma once

#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include "icef/core/status.h"
#include "icef/infer/cnn_layers.h"
#include "icef/infer/tfjs_weights.h"
#include "icef/io/image.h"

namespace icef::eval {

constexpr int kFaceChipSize = 150;
constexpr int kFaceDescriptorDim = 128;
// dlib's same-person threshold on the Euclidean distance between descriptors.
constexpr double kSamePersonThreshold = 0.6;
constexpr const char* kFaceIdManifestName = "face_recognition_model-weights_manifest.json";
// Where scripts/install-deps.sh unpacks the model.
constexpr const char* kDefaultFaceIdModelDir = "/usr/local/share/icef/face-api";

using FaceDescriptor = std::array<float, kFaceDescriptorDim>;

double DescriptorDistance(const FaceDescriptor& a, const FaceDescriptor& b);  // Euclidean
double DescriptorCosine(const FaceDescriptor& a, const FaceDescriptor& b);    // cosine similarity

// The model directory: `explicit_dir` when non-empty, else $ICEF_FACEID_MODEL when set, else
// kDefaultFaceIdModelDir.
std::filesystem::path ResolveFaceIdModelDir(const std::string& explicit_dir = "");

// conv + bias, then the per-channel affine (`scale/weights`, `scale/biases`).
struct ConvAffine {
  infer::ConvWeights conv;
  std::vector<float> scale;  // [cout]
  std::vector<float> shift;  // [cout]
};

struct ResidualBlockWeights {
  ConvAffine conv1;
  ConvAffine conv2;
};

// Applies conv + bias + affine (+ ReLU when `relu`), 3x3: stride 1 'same' or stride 2 'valid'.
infer::Tensor3 ApplyConvAffine(const infer::Tensor3& x, const ConvAffine& layer, int stride,
                               const infer::Padding& pad, bool relu);
// The residual block (down = false) and the down-sampling block (down = true) described above.
infer::Tensor3 ResidualBlock(const infer::Tensor3& x, const ResidualBlockWeights& weights, bool down);

class FaceDescriptorNet {
 public:
  // Loads `dir`/face_recognition_model-weights_manifest.json and its shard. A missing directory
  // or file gives an error that says how to install the model.
  static Result<FaceDescriptorNet> Load(const std::filesystem::path& dir);
  // From decoded tensors; every expected name must be present with the expected shape.
  static Result<FaceDescriptorNet> FromTensors(const infer::TensorMap& tensors, const std::string& source);

  // chip: kFaceChipSize x kFaceChipSize RGB (or RGBA, alpha ignored), values in [0, 1].
  FaceDescriptor Compute(const Image& chip) const;
  // The normalised input tensor [150, 150, 3] of a chip.
  static infer::Tensor3 Preprocess(const Image& chip);
  // The network on an already normalised input of any size big enough for every layer.
  std::vector<float> Forward(const infer::Tensor3& input) const;

  const std::string& source() const { return source_; }
  std::string ToString() const;

 private:
  struct Stage {
    std::string name;
    ResidualBlockWeights weights;
    bool down = false;
  };
  ConvAffine stem_;
  std::vector<Stage> stages_;
  std::vector<float> fc_;  // [256, 128]
  std::string source_;
};

}  // namespace icef::eval
