#include "icef/eval/lpips.h"

#include <cmath>
#include <cstring>
#include <map>
#include <sstream>

#include "icef/io/atomic_file.h"

namespace icef::eval {
namespace {

constexpr char kMagic[8] = {'I', 'C', 'E', 'F', 'L', 'P', 'I', 'P'};
constexpr uint32_t kVersion = 1;
constexpr int kKernel[kLpipsLayers] = {11, 5, 3, 3, 3};
constexpr int kStride[kLpipsLayers] = {4, 1, 1, 1, 1};
constexpr int kPad[kLpipsLayers] = {2, 2, 1, 1, 1};
constexpr float kShift[3] = {-0.030f, -0.088f, -0.188f};
constexpr float kScale[3] = {0.458f, 0.448f, 0.450f};

struct RawTensor {
  std::vector<uint32_t> dims;
  std::vector<float> values;
};

void PutU32(std::string& out, uint32_t v) {
  for (int i = 0; i < 4; ++i) out.push_back(char((v >> (8 * i)) & 0xff));
}

void PutTensor(std::string& out, const std::string& name, const std::vector<uint32_t>& dims,
               const std::vector<float>& values) {
  PutU32(out, uint32_t(name.size()));
  out += name;
  PutU32(out, uint32_t(dims.size()));
  for (uint32_t d : dims) PutU32(out, d);
  const size_t at = out.size();
  out.resize(at + values.size() * 4);
  std::memcpy(out.data() + at, values.data(), values.size() * 4);
}

class Reader {
 public:
  Reader(const std::string& bytes, std::string file) : bytes_(bytes), file_(std::move(file)) {}
  Result<uint32_t> U32(const std::string& what) {
    if (pos_ + 4 > bytes_.size()) return Status::Error(file_ + ": truncated while reading " + what);
    uint32_t v = 0;
    for (int i = 0; i < 4; ++i) v |= uint32_t(uint8_t(bytes_[pos_ + i])) << (8 * i);
    pos_ += 4;
    return v;
  }
  Result<std::string> Bytes(size_t n, const std::string& what) {
    if (pos_ + n > bytes_.size()) return Status::Error(file_ + ": truncated while reading " + what);
    std::string s = bytes_.substr(pos_, n);
    pos_ += n;
    return s;
  }
  bool AtEnd() const { return pos_ == bytes_.size(); }

 private:
  const std::string& bytes_;
  std::string file_;
  size_t pos_ = 0;
};

std::string ConvName(int i, const char* part) { return "conv" + std::to_string(i + 1) + "." + part; }
std::string LinName(int i) { return "lin" + std::to_string(i) + ".weight"; }

}  // namespace

std::string LpipsWeights::ToString() const {
  std::ostringstream s;
  s << "LpipsWeights(alex, channels";
  for (const infer::ConvWeights& c : conv) s << " " << c.cout;
  s << ")";
  return s.str();
}

Status ValidateLpipsWeights(const LpipsWeights& w, const std::string& source) {
  int cin = 3;
  for (int i = 0; i < kLpipsLayers; ++i) {
    const infer::ConvWeights& c = w.conv[i];
    const std::string name = source + ": conv" + std::to_string(i + 1);
    if (c.kh != kKernel[i] || c.kw != kKernel[i])
      return Status::Error(name + ".weight: kernel " + std::to_string(c.kh) + "x" + std::to_string(c.kw) +
                           ", AlexNet needs " + std::to_string(kKernel[i]) + "x" +
                           std::to_string(kKernel[i]));
    if (c.cin != cin)
      return Status::Error(name + ".weight: " + std::to_string(c.cin) + " input channels, expected " +
                           std::to_string(cin));
    if (c.cout < 1) return Status::Error(name + ".weight: no output channels");
    if (c.filters.size() != size_t(c.kh) * c.kw * c.cin * c.cout || c.bias.size() != size_t(c.cout))
      return Status::Error(name + ": filter/bias sizes do not match the shape");
    if (w.lin[i].size() != size_t(c.cout))
      return Status::Error(source + ": " + LinName(i) + ": " + std::to_string(w.lin[i].size()) +
                           " channels, conv" + std::to_string(i + 1) + " has " + std::to_string(c.cout));
    cin = c.cout;
  }
  return Status::Ok();
}

Status WriteLpipsWeights(const std::filesystem::path& path, const LpipsWeights& w) {
  ICEF_RETURN_IF_ERROR(ValidateLpipsWeights(w, path.string()));
  std::string out(kMagic, sizeof(kMagic));
  PutU32(out, kVersion);
  PutU32(out, 3 * kLpipsLayers);
  for (int i = 0; i < kLpipsLayers; ++i) {
    const infer::ConvWeights& c = w.conv[i];
    std::vector<float> oihw(c.filters.size());  // HWIO -> OIHW (PyTorch)
    for (int y = 0; y < c.kh; ++y)
      for (int x = 0; x < c.kw; ++x)
        for (int ci = 0; ci < c.cin; ++ci)
          for (int co = 0; co < c.cout; ++co)
            oihw[((size_t(co) * c.cin + ci) * c.kh + y) * c.kw + x] =
                c.filters[((size_t(y) * c.kw + x) * c.cin + ci) * c.cout + co];
    PutTensor(out, ConvName(i, "weight"), {uint32_t(c.cout), uint32_t(c.cin), uint32_t(c.kh), uint32_t(c.kw)},
              oihw);
    PutTensor(out, ConvName(i, "bias"), {uint32_t(c.cout)}, c.bias);
  }
  for (int i = 0; i < kLpipsLayers; ++i)
    PutTensor(out, LinName(i), {1u, uint32_t(w.lin[i].size()), 1u, 1u}, w.lin[i]);
  return WriteFileAtomic(path, out);
}

Result<LpipsWeights> ReadLpipsWeights(const std::filesystem::path& path) {
  const std::string file = path.string();
  ICEF_ASSIGN_OR_RETURN(const std::string bytes, ReadFile(path));
  Reader reader(bytes, file);
  ICEF_ASSIGN_OR_RETURN(const std::string magic, reader.Bytes(sizeof(kMagic), "magic"));
  if (std::memcmp(magic.data(), kMagic, sizeof(kMagic)) != 0)
    return Status::Error(file +
                         ": not an ICEF LPIPS weights file (bad magic; convert the official weights with "
                         "scripts/convert_lpips_weights.py)");
  ICEF_ASSIGN_OR_RETURN(const uint32_t version, reader.U32("version"));
  if (version != kVersion) return Status::Error(file + ": unsupported version " + std::to_string(version));
  ICEF_ASSIGN_OR_RETURN(const uint32_t count, reader.U32("tensor count"));
  std::map<std::string, RawTensor> tensors;
  for (uint32_t t = 0; t < count; ++t) {
    const std::string where = "tensor " + std::to_string(t);
    ICEF_ASSIGN_OR_RETURN(const uint32_t name_len, reader.U32(where + " name length"));
    if (name_len > 256)
      return Status::Error(file + ": " + where + ": name length " + std::to_string(name_len));
    ICEF_ASSIGN_OR_RETURN(const std::string name, reader.Bytes(name_len, where + " name"));
    ICEF_ASSIGN_OR_RETURN(const uint32_t rank, reader.U32(name + " rank"));
    if (rank > 4) return Status::Error(file + ": " + name + ": rank " + std::to_string(rank));
    RawTensor tensor;
    size_t n = 1;
    for (uint32_t r = 0; r < rank; ++r) {
      ICEF_ASSIGN_OR_RETURN(const uint32_t d, reader.U32(name + " dims"));
      tensor.dims.push_back(d);
      n *= d;
    }
    if (n > (size_t(1) << 28)) return Status::Error(file + ": " + name + ": implausibly large");
    ICEF_ASSIGN_OR_RETURN(const std::string data, reader.Bytes(n * 4, name + " values"));
    tensor.values.resize(n);
    std::memcpy(tensor.values.data(), data.data(), n * 4);
    for (float v : tensor.values)
      if (!std::isfinite(v)) return Status::Error(file + ": " + name + ": non-finite value");
    if (!tensors.emplace(name, std::move(tensor)).second)
      return Status::Error(file + ": duplicate tensor " + name);
  }
  if (!reader.AtEnd()) return Status::Error(file + ": trailing bytes after the last tensor");

  auto get = [&](const std::string& name, size_t rank) -> Result<const RawTensor*> {
    const auto it = tensors.find(name);
    if (it == tensors.end()) return Status::Error(file + ": missing tensor " + name);
    if (it->second.dims.size() != rank)
      return Status::Error(file + ": " + name + ": rank " + std::to_string(it->second.dims.size()) +
                           ", expected " + std::to_string(rank));
    return &it->second;
  };
  LpipsWeights w;
  for (int i = 0; i < kLpipsLayers; ++i) {
    ICEF_ASSIGN_OR_RETURN(const RawTensor* weight, get(ConvName(i, "weight"), 4));
    ICEF_ASSIGN_OR_RETURN(const RawTensor* bias, get(ConvName(i, "bias"), 1));
    ICEF_ASSIGN_OR_RETURN(const RawTensor* lin, get(LinName(i), 4));
    infer::ConvWeights& c = w.conv[i];
    c.cout = int(weight->dims[0]);
    c.cin = int(weight->dims[1]);
    c.kh = int(weight->dims[2]);
    c.kw = int(weight->dims[3]);
    if (bias->dims[0] != weight->dims[0])
      return Status::Error(file + ": " + ConvName(i, "bias") + ": " + std::to_string(bias->dims[0]) +
                           " values for " + std::to_string(c.cout) + " filters");
    if (lin->dims[0] != 1 || lin->dims[2] != 1 || lin->dims[3] != 1)
      return Status::Error(file + ": " + LinName(i) + ": expected shape [1, C, 1, 1]");
    c.filters.resize(weight->values.size());  // OIHW -> HWIO
    for (int co = 0; co < c.cout; ++co)
      for (int ci = 0; ci < c.cin; ++ci)
        for (int y = 0; y < c.kh; ++y)
          for (int x = 0; x < c.kw; ++x)
            c.filters[((size_t(y) * c.kw + x) * c.cin + ci) * c.cout + co] =
                weight->values[((size_t(co) * c.cin + ci) * c.kh + y) * c.kw + x];
    c.bias = bias->values;
    w.lin[i] = lin->values;
  }
  ICEF_RETURN_IF_ERROR(ValidateLpipsWeights(w, file));
  return w;
}

Result<LpipsNet> LpipsNet::FromWeights(LpipsWeights weights, const std::string& source) {
  ICEF_RETURN_IF_ERROR(ValidateLpipsWeights(weights, source));
  LpipsNet net;
  net.weights_ = std::move(weights);
  net.source_ = source;
  return net;
}

Result<LpipsNet> LpipsNet::Load(const std::filesystem::path& path) {
  ICEF_ASSIGN_OR_RETURN(LpipsWeights weights, ReadLpipsWeights(path));
  return FromWeights(std::move(weights), path.string());
}

std::array<infer::Tensor3, kLpipsLayers> LpipsNet::Features(const Image& image) const {
  infer::Tensor3 x(image.height, image.width, 3);
  for (int y = 0; y < image.height; ++y)
    for (int i = 0; i < image.width; ++i) {
      const Vec3f rgb = image.Rgb(i, y);
      for (int c = 0; c < 3; ++c) x.At(y, i, c) = (2.f * rgb[c] - 1.f - kShift[c]) / kScale[c];
    }
  std::array<infer::Tensor3, kLpipsLayers> taps;
  for (int l = 0; l < kLpipsLayers; ++l) {
    if (l == 1 || l == 2) x = infer::MaxPool(x, 3, 2);
    x = infer::Conv2d(x, weights_.conv[l], kStride[l], infer::Padding::Uniform(kPad[l]));
    infer::Relu(x);
    taps[l] = x;
  }
  return taps;
}

Result<double> LpipsNet::Distance(const Image& a, const Image& b) const {
  if (a.width != b.width || a.height != b.height)
    return Status::Error("LPIPS: images differ in size: " + a.ToString() + " vs " + b.ToString());
  if (a.width < kLpipsMinSize || a.height < kLpipsMinSize)
    return Status::Error("LPIPS: image " + a.ToString() + " smaller than " + std::to_string(kLpipsMinSize) +
                         " pixels");
  const auto fa = Features(a), fb = Features(b);
  double total = 0.0;
  for (int l = 0; l < kLpipsLayers; ++l) {
    const infer::Tensor3 &x = fa[l], &y = fb[l];
    const size_t pixels = size_t(x.h) * x.w;
    double layer = 0.0;
    for (size_t p = 0; p < pixels; ++p) {
      const float* u = &x.data[p * x.c];
      const float* v = &y.data[p * y.c];
      double nu = 0.0, nv = 0.0;
      for (int c = 0; c < x.c; ++c) {
        nu += double(u[c]) * u[c];
        nv += double(v[c]) * v[c];
      }
      nu = std::sqrt(nu) + 1e-10;
      nv = std::sqrt(nv) + 1e-10;
      double s = 0.0;
      for (int c = 0; c < x.c; ++c) {
        const double d = u[c] / nu - v[c] / nv;
        s += weights_.lin[l][c] * d * d;
      }
      layer += s;
    }
    total += layer / double(pixels);
  }
  return total;
}

std::string LpipsNet::ToString() const { return "LpipsNet(" + weights_.ToString() + ", " + source_ + ")"; }

Result<std::optional<LpipsNet>> LoadLpipsIfConfigured(const std::string& path) {
  if (path.empty()) return std::optional<LpipsNet>();
  ICEF_ASSIGN_OR_RETURN(LpipsNet net, LpipsNet::Load(path));
  return std::optional<LpipsNet>(std::move(net));
}

}  // namespace icef::eval
