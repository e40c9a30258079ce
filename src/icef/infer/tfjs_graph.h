// A TensorFlow.js graph model (`model.json` with a `modelTopology` of TF nodes and its weights),
// run forward on one image. Supports the ops of the small mobile CNNs shipped as TF.js graphs
// (MediaPipe's face mesh and selfie segmentation among them): Placeholder, Const, Identity, Conv2D
// and _FusedConv2D (BiasAdd, then optionally Relu / Relu6 / Prelu), DepthwiseConv2dNative,
// Conv2DBackpropInput (transposed convolution), AddV2 / Add / Mul / AddN (a tensor of one pixel, or
// a constant of one value or one per channel, broadcasts), Prelu, Relu, Relu6, Sigmoid, MaxPool and
// AvgPool ('VALID'), ResizeBilinear, Pad (zeros) and Reshape. Tensors are NHWC with a batch of one,
// held as Tensor3 [h, w, c]; a rank-2 result [1, n] is a Tensor3 [1, 1, n].
// Loading checks every node (op, inputs, attributes, weight shapes) so that a bad or unsupported
// model fails at load, naming the file and the node, never at run time.
#pragma once

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "icef/core/status.h"
#include "icef/infer/cnn_layers.h"
#include "icef/infer/tfjs_weights.h"

namespace icef::infer {

class TfjsGraph {
 public:
  static Result<TfjsGraph> Load(const std::filesystem::path& model_json);

  // Runs the graph on `input` (fed to its one Placeholder) and returns the requested outputs,
  // each named as a node ("Identity_2") or a tensor ("Identity_2:0"), or by its signature name
  // ("output_mesh"). Errors name the node whose shapes do not fit. flops: if given, receives the
  // floating-point operations of the convolutions run (2 per multiply-add).
  Result<std::map<std::string, Tensor3>> Run(const Tensor3& input, const std::vector<std::string>& outputs,
                                             double* flops = nullptr) const;

  // The input's [h, w, c] as the signature gives it (−1 where unknown).
  const std::vector<int>& input_shape() const { return input_shape_; }
  std::string ToString() const;

 private:
  struct Node {
    std::string name;
    std::string op;
    std::vector<std::string> inputs;  // node names (":0" and control inputs removed)
    std::vector<std::string> fused;   // _FusedConv2D's fused ops
    int stride = 1;
    int window = 0;  // MaxPool, AvgPool
    bool same_padding = false;
    bool align_corners = false;       // ResizeBilinear
    bool half_pixel_centers = false;  // ResizeBilinear
  };

  Result<Tensor3> Evaluate(const std::string& name, const Tensor3& input,
                           std::map<std::string, Tensor3>& cache, double& flops) const;
  Result<Tensor3> Apply(const Node& node, const std::vector<const Tensor3*>& args, double& flops) const;
  const NamedTensor* Weight(const std::string& name) const;

  std::string file_;
  std::map<std::string, Node> nodes_;
  std::map<std::string, std::string> signature_outputs_;  // signature name -> node name
  TensorMap weights_;
  std::string placeholder_;
  std::vector<int> input_shape_;
};

// A graph that scripts/install-deps.sh unpacks: `file` in `dir` (empty: the environment variable
// `env_var` when set, else `default_dir`), whose input must be `input_shape` ([h, w, c]). Errors
// name the file; a missing one says what installs it (`what`: "face-mesh model", ...; `hint`:
// anything to add, such as an option that does without it).
Result<TfjsGraph> LoadInstalledGraph(const std::filesystem::path& dir, const char* env_var,
                                     const char* default_dir, const std::string& file,
                                     const std::vector<int>& input_shape, const std::string& what,
                                     const std::string& hint = "");

}  // namespace icef::infer
