#include "icef/face/ict_model.h"

#include <Eigen/Core>
#include <algorithm>
#include <bit>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>
#include <mutex>
#include <sstream>

namespace icef::face {

static_assert(std::endian::native == std::endian::little, "the model file is little-endian");
static_assert(sizeof(Vec3f) == 3 * sizeof(float) && sizeof(Vec2f) == 2 * sizeof(float));

namespace {

constexpr char kMagic[8] = {'I', 'C', 'T', 'F', 'K', '1', '\0', '\0'};
constexpr uint32_t kDtypeF16 = 1, kDtypeF32 = 2;
constexpr std::string_view kSplitPairs[] = {"browInnerUp", "cheekPuff"};  // ARKit names ICT splits

// The fixed header (models/ict-facekit/README.md); 96 bytes, little-endian, no padding.
struct Header {
  char magic[8];
  uint32_t num_vertices, num_triangles, num_uvs, num_identities, num_expressions, num_parts, num_landmarks,
      num_vertex_sets, identity_dtype, expression_dtype;
  char source_commit[40];
  uint64_t file_size;
};
static_assert(sizeof(Header) == 96);

float HalfToFloat(uint16_t h) {
  const uint32_t sign = static_cast<uint32_t>(h & 0x8000u) << 16;
  const uint32_t exponent = (h >> 10) & 0x1fu, mantissa = h & 0x3ffu;
  if (exponent == 0) {  // zero or subnormal: mantissa * 2^-24
    const float magnitude = std::ldexp(static_cast<float>(mantissa), -24);
    return sign ? -magnitude : magnitude;
  }
  if (exponent == 31) return std::bit_cast<float>(sign | 0x7f800000u | (mantissa << 13));
  return std::bit_cast<float>(sign | ((exponent + 112) << 23) | (mantissa << 13));
}

bool EqualsIgnoreCase(std::string_view a, std::string_view b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return std::tolower(static_cast<unsigned char>(x)) == std::tolower(static_cast<unsigned char>(y));
         });
}

bool EndsWithIgnoreCase(std::string_view s, std::string_view suffix) {
  return s.size() > suffix.size() && EqualsIgnoreCase(s.substr(s.size() - suffix.size()), suffix);
}

std::string_view Trim(std::string_view s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front()))) s.remove_prefix(1);
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.remove_suffix(1);
  return s;
}

}  // namespace

// Reads the sections in file order from the bytes of the whole file, checking every bound.
class IctModelReader {
 public:
  IctModelReader(std::filesystem::path path, std::vector<char> bytes)
      : path_(std::move(path)), bytes_(std::move(bytes)) {}

  Result<IctModel> Read() {
    IctModel m;
    m.path_ = path_;
    Header h;
    if (bytes_.size() < sizeof(Header))
      return Error("truncated: " + std::to_string(bytes_.size()) + " bytes, shorter than the 96-byte header");
    std::memcpy(&h, bytes_.data(), sizeof(Header));
    pos_ = sizeof(Header);
    if (std::memcmp(h.magic, kMagic, sizeof(kMagic)) != 0)
      return Error("bad magic (not an ICT-FaceKit model written by scripts/convert_ict_facekit.py)");
    ICEF_RETURN_IF_ERROR(CheckCount("vertices", h.num_vertices, 3, 1u << 24));
    ICEF_RETURN_IF_ERROR(CheckCount("triangles", h.num_triangles, 1, 1u << 25));
    ICEF_RETURN_IF_ERROR(CheckCount("uvs", h.num_uvs, 1, 1u << 25));
    ICEF_RETURN_IF_ERROR(CheckCount("identities", h.num_identities, 0, 4096));
    ICEF_RETURN_IF_ERROR(CheckCount("expressions", h.num_expressions, 0, 1024));
    ICEF_RETURN_IF_ERROR(CheckCount("parts", h.num_parts, 1, 255));
    ICEF_RETURN_IF_ERROR(
        CheckCount("landmarks", h.num_landmarks, IctModel::kNumLandmarks, IctModel::kNumLandmarks));
    ICEF_RETURN_IF_ERROR(CheckCount("vertex sets", h.num_vertex_sets, 0, 256));
    for (const auto& [what, dtype] :
         {std::pair{"identity", h.identity_dtype}, {"expression", h.expression_dtype}})
      if (dtype != kDtypeF16 && dtype != kDtypeF32)
        return Error(std::string(what) + " dtype " + std::to_string(dtype) +
                     " is neither 1 (float16) nor 2 (float32)");
    if (h.file_size != bytes_.size())
      return Error(h.file_size > bytes_.size()
                       ? "truncated: " + std::to_string(bytes_.size()) + " of " +
                             std::to_string(h.file_size) + " bytes"
                       : std::to_string(bytes_.size()) + " bytes where the header says " +
                             std::to_string(h.file_size) + " (trailing data)");
    m.source_commit_.assign(h.source_commit, sizeof(h.source_commit));
    if (!std::all_of(m.source_commit_.begin(), m.source_commit_.end(),
                     [](char c) { return std::isxdigit(static_cast<unsigned char>(c)); }))
      return Error("source commit is not 40 hex digits");

    // The fixed-size sections must fit in the file before anything is allocated for them.
    const size_t nv = h.num_vertices;
    const auto value_bytes = [](uint32_t dtype) -> size_t { return dtype == kDtypeF16 ? 2 : 4; };
    const size_t fixed_bytes = nv * 12 + size_t{h.num_triangles} * 24 + size_t{h.num_uvs} * 8 +
                               size_t{h.num_identities} * nv * 3 * value_bytes(h.identity_dtype) +
                               size_t{h.num_expressions} * nv * 3 * value_bytes(h.expression_dtype) + nv +
                               sizeof(m.landmarks_);
    if (fixed_bytes > Remaining())
      return Error("truncated: the counts in the header need at least " + std::to_string(fixed_bytes + pos_) +
                   " bytes, the file has " + std::to_string(bytes_.size()));
    m.neutral_.resize(nv);
    ICEF_RETURN_IF_ERROR(ReadFloats("neutral vertices", nv * 3, kDtypeF32, m.neutral_.data()->data()));
    ICEF_RETURN_IF_ERROR(ReadIndices("triangles", h.num_triangles, h.num_vertices, m.triangles_));
    m.uvs_.resize(h.num_uvs);
    ICEF_RETURN_IF_ERROR(ReadFloats("uvs", size_t{h.num_uvs} * 2, kDtypeF32, m.uvs_.data()->data()));
    ICEF_RETURN_IF_ERROR(ReadIndices("triangle uvs", h.num_triangles, h.num_uvs, m.triangle_uvs_));
    m.num_identities_ = static_cast<int>(h.num_identities);
    m.identity_modes_.resize(size_t{h.num_identities} * nv);
    ICEF_RETURN_IF_ERROR(ReadFloats("identity modes", m.identity_modes_.size() * 3, h.identity_dtype,
                                    m.identity_modes_.data()->data()));
    m.expression_deltas_.resize(size_t{h.num_expressions} * nv);
    ICEF_RETURN_IF_ERROR(ReadFloats("expression deltas", m.expression_deltas_.size() * 3, h.expression_dtype,
                                    m.expression_deltas_.data()->data()));
    ICEF_RETURN_IF_ERROR(ReadNames("expression names", h.num_expressions, m.expression_names_));
    ICEF_RETURN_IF_ERROR(ReadNames("part names", h.num_parts, m.part_names_));
    m.part_labels_.resize(nv);
    ICEF_RETURN_IF_ERROR(ReadBytes("part labels", m.part_labels_.data(), nv));
    for (size_t v = 0; v < nv; ++v)
      if (m.part_labels_[v] >= h.num_parts)
        return Error("part label " + std::to_string(m.part_labels_[v]) + " of vertex " + std::to_string(v) +
                     " is not below the part count " + std::to_string(h.num_parts));
    ICEF_RETURN_IF_ERROR(ReadBytes("landmarks", m.landmarks_.data(), sizeof(m.landmarks_)));
    for (int k = 0; k < IctModel::kNumLandmarks; ++k)
      if (m.landmarks_[k] < -1 || m.landmarks_[k] >= static_cast<int32_t>(nv))
        return Error("landmark " + std::to_string(k) + " is vertex " + std::to_string(m.landmarks_[k]) +
                     ", outside [-1, " + std::to_string(nv) + ")");
    for (uint32_t s = 0; s < h.num_vertex_sets; ++s) {
      std::vector<std::string> name;
      ICEF_RETURN_IF_ERROR(ReadNames("vertex set names", 1, name));
      uint32_t count = 0;
      ICEF_RETURN_IF_ERROR(ReadBytes(("vertex set " + name[0]).c_str(), &count, sizeof(count)));
      if (size_t{count} * 4 > Remaining())
        return Error("truncated: vertex set " + name[0] + " needs " + std::to_string(size_t{count} * 4) +
                     " bytes at offset " + std::to_string(pos_) + ", the file has " +
                     std::to_string(bytes_.size()));
      std::vector<uint32_t> indices(count);
      ICEF_RETURN_IF_ERROR(ReadBytes(("vertex set " + name[0]).c_str(), indices.data(), size_t{count} * 4));
      for (uint32_t i : indices)
        if (i >= nv) return Error("vertex set " + name[0] + ": index " + std::to_string(i) + " out of range");
      m.vertex_sets_.emplace_back(std::move(name[0]), std::move(indices));
    }
    if (pos_ != bytes_.size())
      return Error(std::to_string(bytes_.size() - pos_) + " bytes left over after the last section");
    return m;
  }

 private:
  Status Error(const std::string& what) const { return Status::Error(path_.string() + ": " + what); }
  size_t Remaining() const { return bytes_.size() - pos_; }

  Status CheckCount(const char* what, uint32_t n, uint32_t lo, uint32_t hi) const {
    if (n >= lo && n <= hi) return Status::Ok();
    return Error("count of " + std::string(what) + " " + std::to_string(n) + " is out of range [" +
                 std::to_string(lo) + ", " + std::to_string(hi) + "]");
  }

  Status ReadBytes(const char* what, void* out, size_t n) {
    if (n > Remaining())
      return Error("truncated: " + std::string(what) + " needs " + std::to_string(n) + " bytes at offset " +
                   std::to_string(pos_) + ", the file has " + std::to_string(bytes_.size()));
    std::memcpy(out, bytes_.data() + pos_, n);
    pos_ += n;
    return Status::Ok();
  }

  // n values stored as float16 or float32, converted to float; all must be finite.
  Status ReadFloats(const char* what, size_t n, uint32_t dtype, float* out) {
    if (dtype == kDtypeF32) {
      ICEF_RETURN_IF_ERROR(ReadBytes(what, out, n * sizeof(float)));
    } else {
      std::vector<uint16_t> half(n);
      ICEF_RETURN_IF_ERROR(ReadBytes(what, half.data(), n * 2));
      std::transform(half.begin(), half.end(), out, HalfToFloat);
    }
    for (size_t i = 0; i < n; ++i)
      if (!std::isfinite(out[i]))
        return Error(std::string(what) + ": non-finite value at float " + std::to_string(i));
    return Status::Ok();
  }

  Status ReadIndices(const char* what, uint32_t rows, uint32_t bound,
                     std::vector<std::array<uint32_t, 3>>& out) {
    out.resize(rows);
    ICEF_RETURN_IF_ERROR(ReadBytes(what, out.data(), size_t{rows} * 12));
    for (size_t r = 0; r < rows; ++r)
      for (uint32_t i : out[r])
        if (i >= bound)
          return Error(std::string(what) + ": index " + std::to_string(i) + " in row " + std::to_string(r) +
                       " is not below " + std::to_string(bound));
    return Status::Ok();
  }

  // n names, each a length byte (1..255) and that many ASCII characters; unique.
  Status ReadNames(const char* what, uint32_t n, std::vector<std::string>& out) {
    for (uint32_t k = 0; k < n; ++k) {
      uint8_t len = 0;
      ICEF_RETURN_IF_ERROR(ReadBytes(what, &len, 1));
      if (len == 0) return Error(std::string(what) + ": empty name at " + std::to_string(k));
      std::string name(len, '\0');
      ICEF_RETURN_IF_ERROR(ReadBytes(what, name.data(), len));
      if (std::find(out.begin(), out.end(), name) != out.end())
        return Error(std::string(what) + ": '" + name + "' appears twice");
      out.push_back(std::move(name));
    }
    return Status::Ok();
  }

  std::filesystem::path path_;
  std::vector<char> bytes_;
  size_t pos_ = 0;
};

Result<IctModel> IctModel::Load(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in)
    return Status::Error(path.string() +
                         ": cannot open the face model (set $ICEF_FACE_MODEL or rebuild it "
                         "with scripts/convert_ict_facekit.py)");
  const std::streamsize size = in.tellg();
  if (size < 0) return Status::Error(path.string() + ": cannot read the file size");
  std::vector<char> bytes(static_cast<size_t>(size));
  in.seekg(0);
  if (!in.read(bytes.data(), size)) return Status::Error(path.string() + ": read error");
  return IctModelReader(path, std::move(bytes)).Read();
}

std::filesystem::path IctModel::DefaultPath() {
  if (const char* env = std::getenv("ICEF_FACE_MODEL"); env != nullptr && *env != '\0') return env;
  return std::filesystem::path(ICEF_SOURCE_DIR) / "models" / "ict-facekit" / "ict_facekit.bin";
}

Result<std::shared_ptr<const IctModel>> IctModel::LoadDefault() {
  static std::mutex mutex;
  static std::map<std::filesystem::path, std::shared_ptr<const IctModel>> loaded;
  const std::filesystem::path path = DefaultPath();
  const std::lock_guard<std::mutex> lock(mutex);
  if (const auto it = loaded.find(path); it != loaded.end()) return it->second;
  ICEF_ASSIGN_OR_RETURN(IctModel model, Load(path));
  auto shared = std::make_shared<const IctModel>(std::move(model));
  loaded[path] = shared;
  return std::shared_ptr<const IctModel>(shared);
}

int IctModel::ExpressionIndex(std::string_view name) const {
  const auto find = [&](std::string_view stem, std::string_view suffix) {
    for (size_t e = 0; e < expression_names_.size(); ++e) {
      const std::string_view n = expression_names_[e];
      if (n.size() == stem.size() + suffix.size() && EqualsIgnoreCase(n.substr(0, stem.size()), stem) &&
          EqualsIgnoreCase(n.substr(stem.size()), suffix))
        return static_cast<int>(e);
    }
    return -1;
  };
  if (const int e = find(name, ""); e >= 0) return e;  // ICT spelling (and ARKit's unsided names)
  if (EndsWithIgnoreCase(name, "Left")) return find(name.substr(0, name.size() - 4), "_L");
  if (EndsWithIgnoreCase(name, "Right")) return find(name.substr(0, name.size() - 5), "_R");
  return -1;
}

std::vector<int> IctModel::ExpressionTargets(std::string_view name) const {
  if (const int e = ExpressionIndex(name); e >= 0) return {e};
  for (std::string_view pair : kSplitPairs) {
    if (!EqualsIgnoreCase(name, pair)) continue;
    const int l = ExpressionIndex(std::string(pair) + "_L"), r = ExpressionIndex(std::string(pair) + "_R");
    if (l >= 0 && r >= 0) return {l, r};
  }
  return {};
}

std::vector<std::string> IctModel::ArkitNames() const {
  std::vector<std::string> names;
  for (const std::string& n : expression_names_) {
    std::string arkit = n;
    const bool left = n.ends_with("_L"), right = n.ends_with("_R");
    if (left || right) {
      const std::string stem = n.substr(0, n.size() - 2);
      const bool split = std::any_of(std::begin(kSplitPairs), std::end(kSplitPairs),
                                     [&](std::string_view pair) { return EqualsIgnoreCase(stem, pair); });
      arkit = split ? stem : stem + (left ? "Left" : "Right");
    }
    if (std::find(names.begin(), names.end(), arkit) == names.end()) names.push_back(arkit);
  }
  return names;
}

std::vector<Vec3f> IctModel::Mesh(std::span<const float> identity, std::span<const float> expression) const {
  ICEF_CHECK(identity.size() <= static_cast<size_t>(num_identities_),
             std::to_string(identity.size()) + " identity coefficients for " +
                 std::to_string(num_identities_) + " modes");
  ICEF_CHECK(expression.size() <= expression_names_.size(),
             std::to_string(expression.size()) + " expression weights for " +
                 std::to_string(num_expressions()) + " blendshapes");
  const Eigen::Index n = 3 * static_cast<Eigen::Index>(neutral_.size());
  // Displacements summed from zero first, then added to the neutral once: fewer roundings at the
  // neutral's magnitude, and a mesh with all coefficients 0 is the neutral exactly.
  Eigen::VectorXf offset;
  const auto accumulate = [&](std::span<const float> coefficients, const std::vector<Vec3f>& modes) {
    for (size_t k = 0; k < coefficients.size(); ++k) {
      if (coefficients[k] == 0.f) continue;
      if (offset.size() == 0) offset = Eigen::VectorXf::Zero(n);
      offset += coefficients[k] * Eigen::Map<const Eigen::VectorXf>(modes[k * neutral_.size()].data(), n);
    }
  };
  accumulate(identity, identity_modes_);
  accumulate(expression, expression_deltas_);
  std::vector<Vec3f> mesh = neutral_;
  if (offset.size() != 0) Eigen::Map<Eigen::VectorXf>(mesh.data()->data(), n) += offset;
  return mesh;
}

std::span<const Vec3f> IctModel::IdentityMode(int i) const {
  ICEF_CHECK(i >= 0 && i < num_identities_, "identity mode " + std::to_string(i));
  return std::span<const Vec3f>(identity_modes_).subspan(i * neutral_.size(), neutral_.size());
}

std::span<const Vec3f> IctModel::ExpressionDelta(int e) const {
  ICEF_CHECK(e >= 0 && e < num_expressions(), "expression " + std::to_string(e));
  return std::span<const Vec3f>(expression_deltas_).subspan(e * neutral_.size(), neutral_.size());
}

std::vector<Vec3f> IctModel::Landmarks(const std::vector<Vec3f>& mesh) const {
  ICEF_CHECK(mesh.size() == neutral_.size(), "a mesh of " + std::to_string(mesh.size()) +
                                                 " vertices for a model of " +
                                                 std::to_string(neutral_.size()));
  std::vector<Vec3f> out(kNumLandmarks, Vec3f::Constant(std::numeric_limits<float>::quiet_NaN()));
  for (int k = 0; k < kNumLandmarks; ++k)
    if (landmarks_[k] >= 0) out[k] = mesh[landmarks_[k]];
  return out;
}

int IctModel::PartIndex(std::string_view name) const {
  const auto it = std::find(part_names_.begin(), part_names_.end(), name);
  return it == part_names_.end() ? -1 : static_cast<int>(it - part_names_.begin());
}

std::vector<std::string> IctModel::VertexSetNames() const {
  std::vector<std::string> names;
  for (const auto& [name, indices] : vertex_sets_) names.push_back(name);
  return names;
}

std::span<const uint32_t> IctModel::VertexSet(std::string_view name) const {
  for (const auto& [n, indices] : vertex_sets_)
    if (n == name) return indices;
  return {};
}

std::string IctModel::ToString() const {
  const int known =
      static_cast<int>(std::count_if(landmarks_.begin(), landmarks_.end(), [](int32_t i) { return i >= 0; }));
  std::ostringstream s;
  s << "IctModel{file=" << path_.string() << ", source=ICT-VGL/ICT-FaceKit@" << source_commit_.substr(0, 12)
    << ", vertices=" << neutral_.size() << ", triangles=" << triangles_.size() << ", uvs=" << uvs_.size()
    << ", identities=" << num_identities_ << ", expressions=" << expression_names_.size()
    << ", parts=" << part_names_.size() << ", landmarks=" << known << "/" << kNumLandmarks
    << ", vertex_sets=" << vertex_sets_.size() << "}";
  return s.str();
}

Result<std::vector<float>> ParseArkitExpression(const IctModel& model, std::string_view text) {
  std::vector<float> weights(model.num_expressions(), 0.f);
  std::vector<bool> set(model.num_expressions(), false);
  const auto error = [&](const std::string& what) {
    return Status::Error("expression \"" + std::string(text) + "\": " + what);
  };
  if (Trim(text).empty()) return weights;
  size_t start = 0;
  while (start <= text.size()) {
    const size_t comma = std::min(text.find(',', start), text.size());
    const std::string_view item = Trim(text.substr(start, comma - start));
    start = comma + 1;
    const size_t eq = item.find('=');
    if (eq == std::string_view::npos) return error("item '" + std::string(item) + "' is not NAME=VALUE");
    const std::string_view name = Trim(item.substr(0, eq)), value_text = Trim(item.substr(eq + 1));
    float value = 0;
    const auto [end, ec] = std::from_chars(value_text.data(), value_text.data() + value_text.size(), value);
    if (ec != std::errc() || end != value_text.data() + value_text.size() || !std::isfinite(value))
      return error("the value of '" + std::string(name) + "' is not a finite number: '" +
                   std::string(value_text) + "'");
    const std::vector<int> targets = model.ExpressionTargets(name);
    if (targets.empty()) {
      std::string names;
      for (const auto& n : model.expression_names()) names += (names.empty() ? "" : ", ") + n;
      const std::string why = EqualsIgnoreCase(name, "tongueOut")
                                  ? "ARKit's tongueOut has no ICT blendshape"
                                  : "unknown expression '" + std::string(name) + "'";
      return error(why +
                   "; the names are ICT's (mouthSmile_L) or ARKit's (mouthSmileLeft; browInnerUp and "
                   "cheekPuff set both sides): " +
                   names);
    }
    for (int e : targets) {
      if (set[e])
        return error("'" + std::string(name) + "' sets " + model.expression_names()[e] +
                     ", which is already set");
      set[e] = true;
      weights[e] = value;
    }
  }
  return weights;
}

}  // namespace icef::face
