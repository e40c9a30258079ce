// A checkpoint container: named binary sections behind a versioned header, with a checksum of the
// whole payload, written atomically. Readers refuse a file whose magic, version, sizes or checksum
// do not match, so a truncated or bit-flipped checkpoint is never loaded.
//
// Layout (little endian):
//   "ICEFCKPT" | u32 format_version | u32 num_sections
//   per section: u32 name_length | name bytes | u64 payload_length | payload bytes
//   u64 checksum (FNV-1a 64 over every byte before it)
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "icef/core/status.h"

namespace icef {

constexpr uint32_t kCheckpointFormatVersion = 1;

uint64_t Fnv1a64(std::string_view bytes, uint64_t seed = 0xcbf29ce484222325ULL);

class CheckpointWriter {
 public:
  // Sections keep insertion order; names must be unique and non-empty.
  void Add(const std::string& name, std::string bytes);
  std::string Serialize() const;
  Status WriteAtomic(const std::filesystem::path& path) const;

 private:
  std::vector<std::pair<std::string, std::string>> sections_;
};

class Checkpoint {
 public:
  // Parses and verifies a serialized checkpoint; `origin` names the source in errors.
  static Result<Checkpoint> Parse(std::string bytes, const std::string& origin);
  static Result<Checkpoint> Read(const std::filesystem::path& path);

  bool Has(const std::string& name) const { return sections_.count(name) > 0; }
  // The section's bytes, or an error naming the checkpoint and the missing section.
  Result<std::string> Section(const std::string& name) const;
  std::vector<std::string> SectionNames() const;

 private:
  std::string origin_;
  std::map<std::string, std::string> sections_;
};

}  // namespace icef
