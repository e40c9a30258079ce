// Reader for TensorFlow.js weights: a `*-weights_manifest.json` naming tensors (name, shape,
// dtype, optional quantization) whose bytes lie back to back, in manifest order, in the group's
// binary shard files. Quantised tensors (uint8 / uint16) decode as value = q * scale + min,
// float16 ones as IEEE half precision; int32 tensors (a graph's shapes, paddings) become floats.
#pragma once

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "icef/core/status.h"

namespace icef::infer {

struct NamedTensor {
  std::vector<int> shape;     // as in the manifest (filters: [kh, kw, cin, cout])
  std::vector<float> values;  // [prod(shape)], row-major
  size_t size() const { return values.size(); }
  std::string ToString() const;
};

using TensorMap = std::map<std::string, NamedTensor>;

// Reads the manifest (or a graph model's model.json, whose 'weightsManifest' it is) and its shard files
// (paths relative to the manifest's directory). Errors name the file and the field, e.g. "m.json:
// [0].weights[3].quantization.dtype: unsupported 'float16'".
Result<TensorMap> ReadTfjsWeights(const std::filesystem::path& manifest_path);

}  // namespace icef::infer
