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

void ConfigSchema::Block(const std::string& key, const std::function<void(ConfigSchema&)>& bind) {
  auto block = std::make_shared<ConfigSchema>();
  bind(*block);
  Add({key, "",
       [=](const JsonObjectView& o) -> Status {
         ICEF_ASSIGN_OR_RETURN(const JsonObjectView inner, o.Object(key));
         return block->Read(inner);
       },
       [=]() { return block->Write(); }, block});
}

void ConfigSchema::Renamed(const std::string& old_key, const std::string& current) {
  renamed_.emplace_back(old_key, current);
}

std::string ConfigSchema::RenamedTo(const std::string& old_key) const {
  for (const auto& [old_name, current] : renamed_)
    if (old_name == old_key) return current;
  return "";
}

namespace {
std::vector<std::string> SplitPath(const std::string& dotted) {
  std::vector<std::string> parts;
  size_t start = 0;
  for (size_t dot; (dot = dotted.find('.', start)) != std::string::npos; start = dot + 1)
    parts.push_back(dotted.substr(start, dot - start));
  parts.push_back(dotted.substr(start));
  return parts;
}
}  // namespace

Result<Json> ConfigSchema::Upgrade(const JsonObjectView& object) const {
  Json out = object.json();
  for (const auto& [old_key, current] : renamed_) {
    if (!out.contains(old_key) || out[old_key].is_object()) continue;  // a block of that name is current
    Json value = std::move(out[old_key]);
    out.erase(old_key);  // first: a block may take the old key's name ("visual_hull")
    Json* at = &out;
    for (const std::string& part : SplitPath(current)) {
      if (!at->is_object() && !at->is_null())
        return object.Error(old_key, "renamed to " + current + ", which is not an object here");
      at = &(*at)[part];
    }
    if (!at->is_null()) return object.Error(old_key, "given twice: under this old name and as " + current);
    *at = std::move(value);
  }
  return out;
}

Status ConfigSchema::Read(const JsonObjectView& object, OldKeys old_keys) const {
  for (const auto& [old_key, current] : renamed_) {
    if (old_keys == OldKeys::kReject && object.Has(old_key) && !object.json()[old_key].is_object())
      return object.Error(old_key, "renamed to " + (object.path().empty() ? "" : object.path() + ".") +
                                       current + " (docs/config.md lists every key)");
  }
  Json upgraded;
  JsonObjectView view = object;
  if (!renamed_.empty()) {
    ICEF_ASSIGN_OR_RETURN(upgraded, Upgrade(object));
    ICEF_ASSIGN_OR_RETURN(view, JsonObjectView::Make(upgraded, object.file(), object.path()));
  }
  std::vector<std::string> top;
  for (const auto& e : entries_) top.push_back(e.key);
  const std::vector<std::string> unknown = view.UnknownKeys(top);
  if (!unknown.empty()) {
    std::string valid;
    for (const auto& k : top) valid += (valid.empty() ? "" : ", ") + k;
    return view.Error(unknown.front(), "unknown key (valid keys: " + valid + ")");
  }
  for (const auto& e : entries_) {
    if (view.Has(e.key)) ICEF_RETURN_IF_ERROR(e.read(view));
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
  for (const auto& e : entries_) {
    if (!e.block) {
      keys.push_back(e.key);
      continue;
    }
    for (const std::string& inner : e.block->Keys()) keys.push_back(e.key + "." + inner);
  }
  return keys;
}

std::string ConfigSchema::MarkdownRows() const {
  std::string out;
  for (const auto& e : entries_) {
    if (!e.block) {
      out += "| `" + e.key + "` | `" + e.write().dump() + "` | " + e.meaning + " |\n";
      continue;
    }
    // A block's rows, each key prefixed with the block's name.
    const std::string rows = e.block->MarkdownRows();
    for (size_t start = 0; start < rows.size();) {
      const size_t end = rows.find('\n', start);
      out += "| `" + e.key + "." + rows.substr(start + 3, end - start - 3) + "\n";
      start = end + 1;
    }
  }
  return out;
}

}  // namespace icef
