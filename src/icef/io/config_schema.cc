#include "icef/io/config_schema.h"

#include <limits>

namespace icef {

void ConfigSchema::Add(Entry entry) {
  for (const auto& e : entries_) ICEF_CHECK(e.key != entry.key, "duplicate config key " + entry.key);
  entries_.push_back(std::move(entry));
}

void ConfigSchema::Number(const std::string& key, double* value, const std::string& meaning) {
  Add({key, meaning,
       [=](const JsonObjectView& o) -> Status {
         ICEF_ASSIGN_OR_RETURN(*value, o.Number(key));
         return Status::Ok();
       },
       [=]() { return Json(*value); }});
}

void ConfigSchema::Float(const std::string& key, float* value, const std::string& meaning) {
  Add({key, meaning,
       [=](const JsonObjectView& o) -> Status {
         ICEF_ASSIGN_OR_RETURN(const double v, o.Number(key));
         if (std::abs(v) > std::numeric_limits<float>::max()) return o.Error(key, "out of float range");
         *value = static_cast<float>(v);
         return Status::Ok();
       },
       [=]() { return JsonFloat(*value); }});
}

void ConfigSchema::Int(const std::string& key, int* value, const std::string& meaning) {
  Add({key, meaning,
       [=](const JsonObjectView& o) -> Status {
         ICEF_ASSIGN_OR_RETURN(*value, o.Int(key));
         return Status::Ok();
       },
       [=]() { return Json(*value); }});
}

void ConfigSchema::Int64(const std::string& key, int64_t* value, const std::string& meaning) {
  Add({key, meaning,
       [=](const JsonObjectView& o) -> Status {
         ICEF_ASSIGN_OR_RETURN(const double v, o.Number(key));
         if (v != std::floor(v) || std::abs(v) > 9.0e15) return o.Error(key, "expected an integer");
         *value = static_cast<int64_t>(v);
         return Status::Ok();
       },
       [=]() { return Json(*value); }});
}

void ConfigSchema::Bool(const std::string& key, bool* value, const std::string& meaning) {
  Add({key, meaning,
       [=](const JsonObjectView& o) -> Status {
         ICEF_ASSIGN_OR_RETURN(*value, o.Bool(key));
         return Status::Ok();
       },
       [=]() { return Json(*value); }});
}

void ConfigSchema::String(const std::string& key, std::string* value, const std::string& meaning) {
  Add({key, meaning,
       [=](const JsonObjectView& o) -> Status {
         ICEF_ASSIGN_OR_RETURN(*value, o.String(key));
         return Status::Ok();
       },
       [=]() { return Json(*value); }});
}

void ConfigSchema::IntArray(const std::string& key, std::vector<int>* value, const std::string& meaning) {
  Add({key, meaning,
       [=](const JsonObjectView& o) -> Status {
         ICEF_ASSIGN_OR_RETURN(const std::vector<double> v, o.NumberArray(key));
         std::vector<int> out;
         for (double d : v) {
           if (d != std::floor(d) || std::abs(d) > 1e9) return o.Error(key, "expected an array of integers");
           out.push_back(static_cast<int>(d));
         }
         *value = std::move(out);
         return Status::Ok();
       },
       [=]() { return Json(*value); }});
}

Status ConfigSchema::Read(const JsonObjectView& object) const {
  const std::vector<std::string> keys = Keys();
  const std::vector<std::string> unknown = object.UnknownKeys(keys);
  if (!unknown.empty()) {
    std::string valid;
    for (const auto& k : keys) valid += (valid.empty() ? "" : ", ") + k;
    return object.Error(unknown.front(), "unknown key (valid keys: " + valid + ")");
  }
  for (const auto& e : entries_) {
    if (object.Has(e.key)) ICEF_RETURN_IF_ERROR(e.read(object));
  }
  return Status::Ok();
}

Json ConfigSchema::Write() const {
  Json out = Json::object();
  for (const auto& e : entries_) out[e.key] = e.write();
  return out;
}

std::vector<std::string> ConfigSchema::Keys() const {
  std::vector<std::string> keys;
  for (const auto& e : entries_) keys.push_back(e.key);
  return keys;
}

std::string ConfigSchema::MarkdownRows() const {
  std::string out;
  for (const auto& e : entries_) out += "| `" + e.key + "` | `" + e.write().dump() + "` | " + e.meaning + " |\n";
  return out;
}

}  // namespace icef
