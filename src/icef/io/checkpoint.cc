#include "icef/io/checkpoint.h"

#include <cstring>

#include "icef/io/atomic_file.h"

namespace icef {

namespace {
constexpr char kMagic[8] = {'I', 'C', 'E', 'F', 'C', 'K', 'P', 'T'};
constexpr uint64_t kMaxSectionName = 256;

template <typename T>
void Put(std::string& out, T v) {
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  out.append(b, sizeof(T));
}

class Cursor {
 public:
  explicit Cursor(std::string_view bytes) : bytes_(bytes) {}
  template <typename T>
  bool Get(T* v) {
    if (bytes_.size() - pos_ < sizeof(T)) return false;
    std::memcpy(v, bytes_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return true;
  }
  bool GetBytes(uint64_t n, std::string* out) {
    if (bytes_.size() - pos_ < n) return false;
    out->assign(bytes_.data() + pos_, n);
    pos_ += n;
    return true;
  }
  size_t pos() const { return pos_; }

 private:
  std::string_view bytes_;
  size_t pos_ = 0;
};
}  // namespace

uint64_t Fnv1a64(std::string_view bytes, uint64_t h) {
  // Four interleaved lanes keep this fast on large payloads; combined at the end.
  uint64_t lanes[4] = {h, h ^ 0x9e3779b97f4a7c15ULL, h ^ 0xbf58476d1ce4e5b9ULL, h ^ 0x94d049bb133111ebULL};
  const size_t n = bytes.size();
  const auto* p = reinterpret_cast<const unsigned char*>(bytes.data());
  size_t i = 0;
  for (; i + 4 <= n; i += 4)
    for (int k = 0; k < 4; ++k) lanes[k] = (lanes[k] ^ p[i + k]) * 0x100000001b3ULL;
  for (; i < n; ++i) lanes[0] = (lanes[0] ^ p[i]) * 0x100000001b3ULL;
  uint64_t out = h;
  for (uint64_t lane : lanes)
    for (int s = 0; s < 64; s += 8) out = (out ^ ((lane >> s) & 0xff)) * 0x100000001b3ULL;
  return out;
}

void CheckpointWriter::Add(const std::string& name, std::string bytes) {
  ICEF_CHECK(!name.empty() && name.size() <= kMaxSectionName, "bad section name");
  for (const auto& s : sections_) ICEF_CHECK(s.first != name, "duplicate checkpoint section " + name);
  sections_.emplace_back(name, std::move(bytes));
}

std::string CheckpointWriter::Serialize() const {
  std::string out(kMagic, sizeof kMagic);
  Put<uint32_t>(out, kCheckpointFormatVersion);
  Put<uint32_t>(out, static_cast<uint32_t>(sections_.size()));
  for (const auto& [name, bytes] : sections_) {
    Put<uint32_t>(out, static_cast<uint32_t>(name.size()));
    out += name;
    Put<uint64_t>(out, bytes.size());
    out += bytes;
  }
  Put<uint64_t>(out, Fnv1a64(out));
  return out;
}

Status CheckpointWriter::WriteAtomic(const std::filesystem::path& path) const {
  return WriteFileAtomic(path, Serialize());
}

Result<Checkpoint> Checkpoint::Parse(std::string bytes, const std::string& origin) {
  auto fail = [&](const std::string& why) {
    return Status::Error(origin + ": not a valid ICEF checkpoint: " + why);
  };
  if (bytes.size() < sizeof kMagic + 16)
    return fail("file too short (" + std::to_string(bytes.size()) + " bytes)");
  if (std::memcmp(bytes.data(), kMagic, sizeof kMagic) != 0) return fail("bad magic");
  uint64_t stored = 0;
  std::memcpy(&stored, bytes.data() + bytes.size() - 8, 8);
  const std::string_view body(bytes.data(), bytes.size() - 8);
  if (Fnv1a64(body) != stored) return fail("checksum mismatch (truncated or corrupted file)");
  Cursor cur(body);
  std::string magic;
  uint32_t version = 0, count = 0;
  cur.GetBytes(sizeof kMagic, &magic);
  if (!cur.Get(&version) || !cur.Get(&count)) return fail("truncated header");
  if (version != kCheckpointFormatVersion)
    return fail("format version " + std::to_string(version) + ", this build reads version " +
                std::to_string(kCheckpointFormatVersion));
  Checkpoint ckpt;
  ckpt.origin_ = origin;
  for (uint32_t i = 0; i < count; ++i) {
    uint32_t name_len = 0;
    std::string name, payload;
    uint64_t len = 0;
    if (!cur.Get(&name_len) || name_len == 0 || name_len > kMaxSectionName || !cur.GetBytes(name_len, &name))
      return fail("bad section name at section " + std::to_string(i));
    if (!cur.Get(&len) || !cur.GetBytes(len, &payload)) return fail("section '" + name + "' is truncated");
    if (ckpt.sections_.count(name)) return fail("duplicate section '" + name + "'");
    ckpt.sections_.emplace(std::move(name), std::move(payload));
  }
  if (cur.pos() != body.size()) return fail("trailing bytes after the last section");
  return ckpt;
}

Result<Checkpoint> Checkpoint::Read(const std::filesystem::path& path) {
  ICEF_ASSIGN_OR_RETURN(std::string bytes, ReadFile(path));
  return Parse(std::move(bytes), path.string());
}

Result<std::string> Checkpoint::Section(const std::string& name) const {
  auto it = sections_.find(name);
  if (it == sections_.end()) return Status::Error(origin_ + ": checkpoint has no section '" + name + "'");
  return it->second;
}

std::vector<std::string> Checkpoint::SectionNames() const {
  std::vector<std::string> names;
  for (const auto& s : sections_) names.push_back(s.first);
  return names;
}

}  // namespace icef
