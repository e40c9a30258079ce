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

  // Overwrites the bound values from the keys present in `object` (absent keys keep their
  // values). Unknown keys and wrong types are errors naming the file and key.
  Status Read(const JsonObjectView& object) const;
  Json Write() const;
  std::vector<std::string> Keys() const;
  // Markdown rows "| key | default | meaning |" for the current (default) values.
  std::string MarkdownRows() const;

 private:
  struct Entry {
    std::string key;
    std::string meaning;
    std::function<Status(const JsonObjectView&)> read;
    std::function<Json()> write;
  };
  void Add(Entry entry);
  std::vector<Entry> entries_;
};

// Convenience for structs with a Bind(ConfigSchema&) member.
template <typename T>
Status ReadConfig(const JsonObjectView& object, T* config) {
  ConfigSchema schema;
  config->Bind(schema);
  return schema.Read(object);
}
template <typename T>
Json WriteConfig(const T& config) {
  T copy = config;
  ConfigSchema schema;
  copy.Bind(schema);
  return schema.Write();
}

}  // namespace icef
