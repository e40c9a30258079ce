#include "icef/eval/face_descriptor.h"

#include <cmath>
#include <cstdlib>
#include <sstream>

namespace icef::eval {
namespace {

constexpr float kMeanRgb[3] = {122.782f, 117.001f, 104.298f};
constexpr float kInputScale = 1.f / 256.f;  // dlib's input_rgb_image divides by 256

Status Take(const infer::TensorMap& tensors, const std::string& source, const std::string& name,
            const std::vector<int>& shape, std::vector<float>& out) {
  const auto it = tensors.find(name);
  if (it == tensors.end()) return Status::Error(source + ": missing tensor '" + name + "'");
  if (it->second.shape != shape) {
    infer::NamedTensor expected{shape, {}};
    return Status::Error(source + ": tensor '" + name + "' has shape " + it->second.ToString() +
                         ", expected " + expected.ToString());
  }
  out = it->second.values;
  return Status::Ok();
}

Status TakeConvAffine(const infer::TensorMap& tensors, const std::string& source, const std::string& prefix,
                      int k, int cin, int cout, ConvAffine& layer) {
  layer.conv.kh = layer.conv.kw = k;
  layer.conv.cin = cin;
  layer.conv.cout = cout;
  ICEF_RETURN_IF_ERROR(
      Take(tensors, source, prefix + "/conv/filters", {k, k, cin, cout}, layer.conv.filters));
  ICEF_RETURN_IF_ERROR(Take(tensors, source, prefix + "/conv/bias", {cout}, layer.conv.bias));
  ICEF_RETURN_IF_ERROR(Take(tensors, source, prefix + "/scale/weights", {cout}, layer.scale));
  ICEF_RETURN_IF_ERROR(Take(tensors, source, prefix + "/scale/biases", {cout}, layer.shift));
  return Status::Ok();
}

}  // namespace

double DescriptorDistance(const FaceDescriptor& a, const FaceDescriptor& b) {
  double s = 0.0;
  for (int i = 0; i < kFaceDescriptorDim; ++i) s += double(a[i] - b[i]) * double(a[i] - b[i]);
  return std::sqrt(s);
}

double DescriptorCosine(const FaceDescriptor& a, const FaceDescriptor& b) {
  double ab = 0.0, aa = 0.0, bb = 0.0;
  for (int i = 0; i < kFaceDescriptorDim; ++i) {
    ab += double(a[i]) * b[i];
    aa += double(a[i]) * a[i];
    bb += double(b[i]) * b[i];
  }
  return (aa > 0.0 && bb > 0.0) ? ab / std::sqrt(aa * bb) : 0.0;
}

std::filesystem::path ResolveFaceIdModelDir(const std::string& explicit_dir) {
  if (!explicit_dir.empty()) return explicit_dir;
  if (const char* env = std::getenv("ICEF_FACEID_MODEL"); env != nullptr && *env != '\0') return env;
  return kDefaultFaceIdModelDir;
}

infer::Tensor3 ApplyConvAffine(const infer::Tensor3& x, const ConvAffine& layer, int stride,
                               const infer::Padding& pad, bool relu) {
  infer::Tensor3 out = infer::Conv2d(x, layer.conv, stride, pad);
  infer::ChannelAffine(out, layer.scale, layer.shift);
  if (relu) infer::Relu(out);
  return out;
}

infer::Tensor3 ResidualBlock(const infer::Tensor3& x, const ResidualBlockWeights& weights, bool down) {
  if (!down) {
    infer::Tensor3 out = ApplyConvAffine(x, weights.conv1, 1, infer::Padding::Uniform(1), true);
    out = ApplyConvAffine(out, weights.conv2, 1, infer::Padding::Uniform(1), false);
    infer::AddInPlace(out, x);
    infer::Relu(out);
    return out;
  }
  infer::Tensor3 branch = ApplyConvAffine(x, weights.conv1, 2, infer::Padding::Valid(), true);
  branch = ApplyConvAffine(branch, weights.conv2, 1, infer::Padding::Uniform(1), false);
  infer::Tensor3 out = infer::AddZeroExtended(infer::AvgPool(x, 2, 2), branch);
  infer::Relu(out);
  return out;
}

Result<FaceDescriptorNet> FaceDescriptorNet::FromTensors(const infer::TensorMap& tensors,
                                                         const std::string& source) {
  FaceDescriptorNet net;
  net.source_ = source;
  ICEF_RETURN_IF_ERROR(TakeConvAffine(tensors, source, "conv32_down", 7, 3, 32, net.stem_));
  struct StageSpec {
    const char* name;
    int cin;
    int cout;
    bool down;
  };
  const StageSpec specs[] = {
      {"conv32_1", 32, 32, false},    {"conv32_2", 32, 32, false},          {"conv32_3", 32, 32, false},
      {"conv64_down", 32, 64, true},  {"conv64_1", 64, 64, false},          {"conv64_2", 64, 64, false},
      {"conv64_3", 64, 64, false},    {"conv128_down", 64, 128, true},      {"conv128_1", 128, 128, false},
      {"conv128_2", 128, 128, false}, {"conv256_down", 128, 256, true},     {"conv256_1", 256, 256, false},
      {"conv256_2", 256, 256, false}, {"conv256_down_out", 256, 256, true},
  };
  for (const StageSpec& spec : specs) {
    Stage stage;
    stage.name = spec.name;
    stage.down = spec.down;
    ICEF_RETURN_IF_ERROR(
        TakeConvAffine(tensors, source, stage.name + "/conv1", 3, spec.cin, spec.cout, stage.weights.conv1));
    ICEF_RETURN_IF_ERROR(
        TakeConvAffine(tensors, source, stage.name + "/conv2", 3, spec.cout, spec.cout, stage.weights.conv2));
    net.stages_.push_back(std::move(stage));
  }
  ICEF_RETURN_IF_ERROR(Take(tensors, source, "fc", {256, kFaceDescriptorDim}, net.fc_));
  return net;
}

Result<FaceDescriptorNet> FaceDescriptorNet::Load(const std::filesystem::path& dir) {
  const std::filesystem::path manifest = dir / kFaceIdManifestName;
  std::error_code ec;
  if (!std::filesystem::exists(manifest, ec))
    return Status::Error(manifest.string() +
                         ": face-identity model not found (install it with scripts/install-deps.sh, or point "
                         "--faceid-model / ICEF_FACEID_MODEL at a directory holding " +
                         kFaceIdManifestName +
                         " and face_recognition_model.bin from @vladmandic/face-api@1.7.15)");
  ICEF_ASSIGN_OR_RETURN(const infer::TensorMap tensors, infer::ReadTfjsWeights(manifest));
  return FromTensors(tensors, manifest.string());
}

infer::Tensor3 FaceDescriptorNet::Preprocess(const Image& chip) {
  ICEF_CHECK(chip.channels >= 3, "face chip must be RGB");
  infer::Tensor3 input(chip.height, chip.width, 3);
  for (int y = 0; y < chip.height; ++y)
    for (int x = 0; x < chip.width; ++x)
      for (int c = 0; c < 3; ++c) input.At(y, x, c) = (chip.At(x, y, c) * 255.f - kMeanRgb[c]) * kInputScale;
  return input;
}

std::vector<float> FaceDescriptorNet::Forward(const infer::Tensor3& input) const {
  infer::Tensor3 x = ApplyConvAffine(input, stem_, 2, infer::Padding::Valid(), true);
  x = infer::MaxPool(x, 3, 2);
  for (const Stage& stage : stages_) x = ResidualBlock(x, stage.weights, stage.down);
  return infer::FullyConnected(infer::GlobalMean(x), fc_, kFaceDescriptorDim);
}

FaceDescriptor FaceDescriptorNet::Compute(const Image& chip) const {
  ICEF_CHECK(chip.width == kFaceChipSize && chip.height == kFaceChipSize,
             "face chip must be 150x150, got " + chip.ToString());
  const std::vector<float> out = Forward(Preprocess(chip));
  FaceDescriptor d;
  std::copy(out.begin(), out.end(), d.begin());
  return d;
}

std::string FaceDescriptorNet::ToString() const {
  std::ostringstream s;
  s << "FaceDescriptorNet(dlib ResNet-29, " << stages_.size() << " residual stages, 128-D; weights "
    << source_ << ")";
  return s.str();
}

}  // namespace icef::eval
