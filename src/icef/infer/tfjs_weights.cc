#include "icef/infer/tfjs_weights.h"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <nlohmann/json.hpp>
#include <sstream>

#include "icef/io/atomic_file.h"

namespace icef::infer {

std::string NamedTensor::ToString() const {
  std::ostringstream s;
  s << "[";
  for (size_t i = 0; i < shape.size(); ++i) s << (i ? ", " : "") << shape[i];
  s << "]";
  return s.str();
}

namespace {

float HalfToFloat(uint16_t h) {
  const int sign = (h >> 15) & 1;
  const int exponent = (h >> 10) & 0x1f;
  const int mantissa = h & 0x3ff;
  double v;
  if (exponent == 0)
    v = std::ldexp(double(mantissa), -24);  // subnormal (or zero)
  else if (exponent == 31)
    v = mantissa ? std::nan("") : HUGE_VAL;
  else
    v = std::ldexp(double(mantissa | 0x400), exponent - 25);
  return float(sign ? -v : v);
}

// Decodes `count` values of `dtype` (optionally quantised) from `bytes` at `offset`.
Status Decode(const nlohmann::json& entry, const std::string& where, const std::string& bytes, size_t& offset,
              size_t count, std::vector<float>& out) {
  const std::string dtype = entry.value("dtype", "");
  if (dtype != "float32" && dtype != "int32")
    return Status::Error(where + ".dtype: unsupported '" + dtype + "'");
  out.resize(count);
  const std::string qtype = entry.contains("quantization") ? entry["quantization"].value("dtype", "") : "";
  if (qtype == "float16") {  // IEEE half precision, no scale / min
    if (offset + count * 2 > bytes.size())
      return Status::Error(where + ": weights file too short (needs " + std::to_string(offset + count * 2) +
                           " bytes, has " + std::to_string(bytes.size()) + ")");
    const auto* p = reinterpret_cast<const unsigned char*>(bytes.data() + offset);
    for (size_t i = 0; i < count; ++i) out[i] = HalfToFloat(uint16_t(p[2 * i] | (p[2 * i + 1] << 8)));
    offset += count * 2;
  } else if (entry.contains("quantization")) {
    const auto& q = entry["quantization"];
    const std::string qtype = q.value("dtype", "");
    if (!q.contains("scale") || !q.contains("min") || !q["scale"].is_number() || !q["min"].is_number())
      return Status::Error(where + ".quantization: needs numeric 'scale' and 'min'");
    const double scale = q["scale"].get<double>();
    const double min = q["min"].get<double>();
    size_t width = 0;
    if (qtype == "uint8")
      width = 1;
    else if (qtype == "uint16")
      width = 2;
    else
      return Status::Error(where + ".quantization.dtype: unsupported '" + qtype + "'");
    if (offset + count * width > bytes.size())
      return Status::Error(where + ": weights file too short (needs " +
                           std::to_string(offset + count * width) + " bytes, has " +
                           std::to_string(bytes.size()) + ")");
    const auto* p = reinterpret_cast<const unsigned char*>(bytes.data() + offset);
    for (size_t i = 0; i < count; ++i) {
      const unsigned v = width == 1 ? p[i] : unsigned(p[2 * i]) | (unsigned(p[2 * i + 1]) << 8);
      out[i] = float(double(v) * scale + min);
    }
    offset += count * width;
  } else {
    if (offset + count * 4 > bytes.size())
      return Status::Error(where + ": weights file too short (needs " + std::to_string(offset + count * 4) +
                           " bytes, has " + std::to_string(bytes.size()) + ")");
    if (dtype == "int32") {  // shapes and paddings: small integers, exact in float
      for (size_t i = 0; i < count; ++i) {
        int32_t v;
        std::memcpy(&v, bytes.data() + offset + 4 * i, 4);
        out[i] = float(v);
      }
    } else {
      std::memcpy(out.data(), bytes.data() + offset, count * 4);  // little-endian float32
    }
    offset += count * 4;
  }
  return Status::Ok();
}

}  // namespace

Result<TensorMap> ReadTfjsWeights(const std::filesystem::path& manifest_path) {
  const std::string file = manifest_path.string();
  ICEF_ASSIGN_OR_RETURN(const std::string text, ReadFile(manifest_path));
  nlohmann::json manifest;
  try {
    manifest = nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    return Status::Error(file + ": invalid JSON: " + e.what());
  }
  // A graph model's model.json carries its manifest in 'weightsManifest'.
  if (manifest.is_object() && manifest.contains("weightsManifest")) manifest = manifest["weightsManifest"];
  if (!manifest.is_array()) return Status::Error(file + ": expected an array of weight groups");
  TensorMap tensors;
  for (size_t g = 0; g < manifest.size(); ++g) {
    const std::string group_where = file + ": [" + std::to_string(g) + "]";
    const auto& group = manifest[g];
    if (!group.is_object() || !group.contains("paths") || !group["paths"].is_array() ||
        !group.contains("weights") || !group["weights"].is_array())
      return Status::Error(group_where + ": expected 'paths' and 'weights' arrays");
    std::string bytes;
    for (const auto& p : group["paths"]) {
      if (!p.is_string()) return Status::Error(group_where + ".paths: expected strings");
      ICEF_ASSIGN_OR_RETURN(const std::string shard,
                            ReadFile(manifest_path.parent_path() / p.get<std::string>()));
      bytes += shard;
    }
    size_t offset = 0;
    for (size_t w = 0; w < group["weights"].size(); ++w) {
      const auto& entry = group["weights"][w];
      const std::string where = group_where + ".weights[" + std::to_string(w) + "]";
      if (!entry.is_object() || !entry.contains("name") || !entry["name"].is_string() ||
          !entry.contains("shape") || !entry["shape"].is_array())
        return Status::Error(where + ": expected 'name' and 'shape'");
      NamedTensor tensor;
      size_t count = 1;
      for (const auto& d : entry["shape"]) {
        if (!d.is_number_integer() || d.get<int>() < 0)
          return Status::Error(where + ".shape: expected non-negative integers");
        tensor.shape.push_back(d.get<int>());
        count *= size_t(d.get<int>());
      }
      ICEF_RETURN_IF_ERROR(Decode(entry, where, bytes, offset, count, tensor.values));
      const std::string name = entry["name"].get<std::string>();
      if (!tensors.emplace(name, std::move(tensor)).second)
        return Status::Error(where + ".name: duplicate tensor '" + name + "'");
    }
    if (offset != bytes.size())
      return Status::Error(group_where + ": weights use " + std::to_string(offset) +
                           " bytes but the shards hold " + std::to_string(bytes.size()));
  }
  return tensors;
}

}  // namespace icef::infer
