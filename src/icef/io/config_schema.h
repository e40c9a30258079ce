// One declaration per config key, used three ways: reading a run config strictly (an unknown key
// is a typo and an error that lists the valid keys; a wrong type names the key), writing the
// resolved config back to JSON, and generating the key/default/meaning table of docs/config.md.
//
//   struct TrainConfig {
//     int steps = 3000;
//     void Bind(ConfigSchema& s) { s.Int("steps", &steps, "training steps"); }
//   };
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "icef/core/status.h"
#include "icef/io/json_util.h"

namespace icef {

class ConfigSchema {
 public:
  void Number(const std::string& key, double* value, const std::string& meaning);
  void Float(const std::string& key, float* value, const std::string& meaning);
  void Int(const std::string& key, int* value, const std::string& meaning);
  void Int64(const std::string& key, int64_t* value, const std::string& meaning);
  void Bool(const std::string& key, bool* value, const std::string& meaning);
  void String(const std::string& key, std::string* value, const std::string& meaning);
  void IntArray(const std::string& key, std::vector<int>* value, const std::string& meaning);
  // A nested block {"key": {...}} whose keys `bind` declares, e.g. one component's Options struct.
  // Reading it sets only the keys present; its keys are written and documented as "key.inner".
  void Block(const std::string& key, const std::function<void(ConfigSchema&)>& bind);
  // An earlier spelling of a key, now the dotted path `current` ("grid_levels" ->
  // "static_field.grid.num_levels"). Read() rejects it with an error naming `current`, unless told
  // to read stored configs (checkpoints written before the rename), where it is read as `current`.
  void Renamed(const std::string& old_key, const std::string& current);
  // The current path of an old spelling declared with Renamed(); "" for any other key.
  std::string RenamedTo(const std::string& old_key) const;

  enum class OldKeys { kReject, kRead };
  // Overwrites the bound values from the keys present in `object` (absent keys keep their
  // values). Unknown keys and wrong types are errors naming the file and key.
  Status Read(const JsonObjectView& object, OldKeys old_keys = OldKeys::kReject) const;
  Json Write() const;
  // Every key, blocks' keys as dotted paths ("static_field.grid.num_levels").
  std::vector<std::string> Keys() const;
  // Markdown rows "| key | default | meaning |" for the current (default) values.
  std::string MarkdownRows() const;

 private:
  struct Entry {
    std::string key;
    std::string meaning;
    std::function<Status(const JsonObjectView&)> read;
    std::function<Json()> write;
    std::shared_ptr<ConfigSchema> block;  // set for a nested block
  };
  void Add(Entry entry);
  // `object` with every old spelling moved to its current path; an error if both are given.
  Result<Json> Upgrade(const JsonObjectView& object) const;
  std::vector<Entry> entries_;
  std::vector<std::pair<std::string, std::string>> renamed_;
};

// Convenience for structs with a Bind(ConfigSchema&) member.
template <typename T>
Status ReadConfig(const JsonObjectView& object, T* config,
                  ConfigSchema::OldKeys old_keys = ConfigSchema::OldKeys::kReject) {
  ConfigSchema schema;
  config->Bind(schema);
  return schema.Read(object, old_keys);
}
template <typename T>
Json WriteConfig(const T& config) {
  T copy = config;
  ConfigSchema schema;
  copy.Bind(schema);
  return schema.Write();
}

}  // namespace icef
