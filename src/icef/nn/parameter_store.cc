#include "icef/nn/parameter_store.h"

#include <algorithm>
#include <cstring>
#include <istream>
#include <ostream>
#include <sstream>

namespace icef::nn {

namespace {
constexpr char kMagic[8] = {'I', 'C', 'E', 'F', 'P', 'R', 'M', '\0'};
constexpr uint32_t kVersion = 1;

template <typename T>
void Put(std::ostream& out, const T& v) {
  out.write(reinterpret_cast<const char*>(&v), sizeof(T));
}
template <typename T>
bool Get(std::istream& in, T* v) {
  in.read(reinterpret_cast<char*>(v), sizeof(T));
  return static_cast<bool>(in);
}
}  // namespace

std::string ParamBlock::ToString() const {
  std::ostringstream s;
  s << "ParamBlock(" << name << ", offset=" << offset << ", size=" << size << ", group=" << group << ")";
  return s.str();
}

int ParameterStore::Register(const std::string& name, int64_t size, int group) {
  ICEF_CHECK(size >= 0, "negative block size for " + name);
  ICEF_CHECK(FindBlock(name) < 0, "duplicate parameter block name " + name);
  ParamBlock b;
  b.name = name;
  b.offset = this->size();
  b.size = size;
  b.group = group;
  blocks_.push_back(b);
  const int64_t new_size = b.offset + RoundUpToLine(size);
  params_.resize(new_size, 0.0f);
  grads_.resize(new_size, 0.0f);
  return num_blocks() - 1;
}

int ParameterStore::FindBlock(const std::string& name) const {
  for (int i = 0; i < num_blocks(); ++i) {
    if (blocks_[i].name == name) return i;
  }
  return -1;
}

std::span<float> ParameterStore::params(int i) {
  return {params_.data() + block(i).offset, static_cast<size_t>(block(i).size)};
}
std::span<const float> ParameterStore::params(int i) const {
  return {params_.data() + block(i).offset, static_cast<size_t>(block(i).size)};
}
std::span<float> ParameterStore::grads(int i) {
  return {grads_.data() + block(i).offset, static_cast<size_t>(block(i).size)};
}
std::span<const float> ParameterStore::grads(int i) const {
  return {grads_.data() + block(i).offset, static_cast<size_t>(block(i).size)};
}

void ParameterStore::ZeroGrads() { std::fill(grads_.begin(), grads_.end(), 0.0f); }

Status ParameterStore::Write(std::ostream& out) const {
  out.write(kMagic, sizeof(kMagic));
  Put(out, kVersion);
  Put(out, static_cast<uint32_t>(blocks_.size()));
  int64_t total = 0;
  for (const ParamBlock& b : blocks_) {
    Put(out, static_cast<uint32_t>(b.name.size()));
    out.write(b.name.data(), static_cast<std::streamsize>(b.name.size()));
    Put(out, b.size);
    Put(out, static_cast<int32_t>(b.group));
    total += b.size;
  }
  Put(out, total);
  for (const ParamBlock& b : blocks_) {
    out.write(reinterpret_cast<const char*>(params_.data() + b.offset),
              static_cast<std::streamsize>(b.size * sizeof(float)));
  }
  if (!out) return Status::Error("parameters: write failed");
  return Status::Ok();
}

Status ParameterStore::Read(std::istream& in) {
  char magic[8];
  in.read(magic, sizeof(magic));
  if (!in || std::memcmp(magic, kMagic, sizeof(kMagic)) != 0) {
    return Status::Error("parameters: bad magic (not an ICEF parameter section)");
  }
  uint32_t version = 0, count = 0;
  if (!Get(in, &version)) return Status::Error("parameters: truncated header (version)");
  if (version != kVersion) {
    return Status::Error("parameters: unsupported version " + std::to_string(version) + " (expected " +
                         std::to_string(kVersion) + ")");
  }
  if (!Get(in, &count)) return Status::Error("parameters: truncated header (block count)");
  if (count > (1u << 16))
    return Status::Error("parameters: implausible block count " + std::to_string(count));
  // The file's block headers first, so that a mismatch names the block that differs.
  struct FileBlock {
    std::string name;
    int64_t size = 0;
  };
  std::vector<FileBlock> file(count);
  for (uint32_t k = 0; k < count; ++k) {
    uint32_t len = 0;
    if (!Get(in, &len) || len > (1u << 16)) return Status::Error("parameters: truncated block name");
    file[k].name.assign(len, '\0');
    in.read(file[k].name.data(), len);
    int32_t group = 0;
    if (!in || !Get(in, &file[k].size) || !Get(in, &group)) {
      return Status::Error("parameters: truncated header of block " + std::to_string(k));
    }
  }
  const std::string counts = " (the file has " + std::to_string(count) + " blocks, the model " +
                             std::to_string(blocks_.size()) +
                             ": written by another version or for another method?)";
  for (size_t k = 0; k < std::max<size_t>(file.size(), blocks_.size()); ++k) {
    if (k >= file.size())
      return Status::Error("parameters: the model's block '" + blocks_[k].name + "' is not in the file" +
                           counts);
    if (k >= blocks_.size())
      return Status::Error("parameters: block '" + file[k].name + "' in file is not in the model" + counts);
    const ParamBlock& b = blocks_[k];
    if (file[k].name != b.name) {
      return Status::Error("parameters: block '" + file[k].name + "' in file where model expects '" + b.name +
                           "'");
    }
    if (file[k].size != b.size) {
      return Status::Error("parameters: block '" + b.name + "' has " + std::to_string(file[k].size) +
                           " floats in file, model expects " + std::to_string(b.size));
    }
  }
  int64_t total = 0;
  if (!Get(in, &total)) return Status::Error("parameters: truncated header (total)");
  for (const ParamBlock& b : blocks_) {
    in.read(reinterpret_cast<char*>(params_.data() + b.offset),
            static_cast<std::streamsize>(b.size * sizeof(float)));
    if (!in) return Status::Error("parameters: truncated data of block '" + b.name + "'");
  }
  return Status::Ok();
}

std::string ParameterStore::ToString() const {
  std::ostringstream s;
  s << "ParameterStore(" << blocks_.size() << " blocks, " << size() << " floats";
  for (const ParamBlock& b : blocks_) s << "; " << b.name << ":" << b.size << "@g" << b.group;
  s << ")";
  return s.str();
}

}  // namespace icef::nn
