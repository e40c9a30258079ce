#include "icef/io/json_util.h"

#include <charconv>
#include <cmath>
#include <cstdlib>
#include <limits>

#include "icef/io/atomic_file.h"

namespace icef {

namespace {

// Python-style non-finite literals become this string (+ the literal) before parsing.
constexpr std::string_view kNonFiniteMarker = "\x01nonfinite:";

bool IsIdentChar(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }

// Replaces bare NaN / Infinity / -Infinity tokens outside strings by marker strings.
std::string ReplaceNonFiniteLiterals(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  bool in_string = false;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (in_string) {
      out += c;
      if (c == '\\' && i + 1 < text.size()) {
        out += text[++i];
      } else if (c == '"') {
        in_string = false;
      }
      continue;
    }
    if (c == '"') {
      in_string = true;
      out += c;
      continue;
    }
    bool replaced = false;
    for (std::string_view literal : {"-Infinity", "Infinity", "NaN"}) {
      if (text.substr(i, literal.size()) != literal) continue;
      const bool start_ok = i == 0 || !IsIdentChar(text[i - 1]);
      const size_t end = i + literal.size();
      const bool end_ok = end >= text.size() || !IsIdentChar(text[end]);
      if (!start_ok || !end_ok) continue;
      out += "\"\\u0001nonfinite:";
      out += literal;
      out += '"';
      i = end - 1;
      replaced = true;
      break;
    }
    if (!replaced) out += c;
  }
  return out;
}

bool IsNonFinite(const Json& value) {
  return value.is_string() && value.get_ref<const std::string&>().starts_with(kNonFiniteMarker);
}

std::string NonFiniteName(const Json& value) {
  return value.get_ref<const std::string&>().substr(kNonFiniteMarker.size());
}

bool IsScalar(const Json& value) { return value.is_primitive(); }

void Format(const Json& value, int indent, std::string& out) {
  const std::string pad(size_t(indent) * 2, ' ');
  const std::string inner_pad(size_t(indent + 1) * 2, ' ');
  if (value.is_object() && !value.empty()) {
    out += "{\n";
    size_t i = 0;
    for (auto it = value.begin(); it != value.end(); ++it, ++i) {
      out += inner_pad + Json(it.key()).dump() + ": ";
      Format(it.value(), indent + 1, out);
      out += (i + 1 < value.size()) ? ",\n" : "\n";
    }
    out += pad + "}";
  } else if (value.is_array() && !value.empty()) {
    bool all_scalar = true;
    for (const Json& v : value) all_scalar = all_scalar && IsScalar(v);
    if (all_scalar) {
      out += "[";
      for (size_t i = 0; i < value.size(); ++i) out += (i ? ", " : "") + value[i].dump();
      out += "]";
      return;
    }
    // Arrays of short scalar arrays (matrices, landmark lists) also stay compact per row.
    out += "[\n";
    for (size_t i = 0; i < value.size(); ++i) {
      out += inner_pad;
      Format(value[i], indent + 1, out);
      out += (i + 1 < value.size()) ? ",\n" : "\n";
    }
    out += pad + "]";
  } else {
    out += value.dump();
  }
}

}  // namespace

Result<Json> ParseJson(std::string_view text, const std::string& file) {
  const std::string prepared = ReplaceNonFiniteLiterals(text);
  try {
    return Json::parse(prepared);
  } catch (const Json::exception& e) {
    std::string what = e.what();
    // Drop nlohmann's "[json.exception.parse_error.101] " prefix.
    if (const size_t p = what.find("] "); what.starts_with("[json.exception") && p != std::string::npos)
      what = what.substr(p + 2);
    return Status::Error(file + ": invalid JSON: " + what);
  }
}

Result<Json> ReadJsonFile(const std::filesystem::path& path) {
  ICEF_ASSIGN_OR_RETURN(const std::string text, ReadFile(path));
  return ParseJson(text, path.string());
}

Json JsonFloat(float value) {
  if (!std::isfinite(value)) return Json(static_cast<double>(value));  // dumps as null
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  *result.ptr = '\0';
  return Json(std::strtod(buffer, nullptr));
}

std::string FormatJson(const Json& value) {
  std::string out;
  Format(value, 0, out);
  out += "\n";
  return out;
}

std::string JsonTypeDescription(const Json& value) {
  if (IsNonFinite(value)) return "a non-finite number (" + NonFiniteName(value) + ")";
  switch (value.type()) {
    case Json::value_t::null:
      return "null";
    case Json::value_t::boolean:
      return "a boolean";
    case Json::value_t::string:
      return "a string";
    case Json::value_t::array:
      return "an array of " + std::to_string(value.size());
    case Json::value_t::object:
      return "an object";
    case Json::value_t::number_integer:
    case Json::value_t::number_unsigned:
    case Json::value_t::number_float:
      return "a number";
    default:
      return value.type_name();
  }
}

Result<JsonObjectView> JsonObjectView::Make(const Json& value, std::string file, std::string path) {
  if (!value.is_object()) {
    const std::string where = path.empty() ? file : file + ": " + path;
    return Status::Error(where + ": expected an object, got " + JsonTypeDescription(value));
  }
  return JsonObjectView(&value, std::move(file), std::move(path));
}

bool JsonObjectView::Has(std::string_view key) const { return value_->contains(key); }

std::vector<std::string> JsonObjectView::UnknownKeys(const std::vector<std::string>& known) const {
  std::vector<std::string> unknown;
  for (auto it = value_->begin(); it != value_->end(); ++it) {
    bool found = false;
    for (const std::string& k : known) found = found || k == it.key();
    if (!found) unknown.push_back(it.key());
  }
  return unknown;
}

std::string JsonObjectView::Where(std::string_view key) const {
  return path_.empty() ? std::string(key) : path_ + "." + std::string(key);
}

Status JsonObjectView::Error(std::string_view key, const std::string& message) const {
  return Status::Error(file_ + ": " + Where(key) + ": " + message);
}

Status JsonObjectView::ErrorHere(const std::string& message) const {
  return Status::Error(path_.empty() ? file_ + ": " + message : file_ + ": " + path_ + ": " + message);
}

Result<const Json*> JsonObjectView::Get(std::string_view key) const {
  const auto it = value_->find(key);
  if (it == value_->end()) return Error(key, "missing required field");
  return &*it;
}

Result<double> JsonObjectView::Number(std::string_view key) const {
  ICEF_ASSIGN_OR_RETURN(const Json* v, Get(key));
  if (IsNonFinite(*v)) return Error(key, "expected a finite number, got " + NonFiniteName(*v));
  if (!v->is_number()) return Error(key, "expected a number, got " + JsonTypeDescription(*v));
  const double x = v->get<double>();
  if (!std::isfinite(x)) return Error(key, "expected a finite number");
  return x;
}

Result<int> JsonObjectView::Int(std::string_view key) const {
  ICEF_ASSIGN_OR_RETURN(const double x, Number(key));
  if (x != std::floor(x) || x < std::numeric_limits<int>::min() || x > std::numeric_limits<int>::max())
    return Error(key, "expected an integer, got " + Json(x).dump());
  return static_cast<int>(x);
}

Result<int64_t> JsonObjectView::Int64(std::string_view key, int64_t min, int64_t max) const {
  ICEF_ASSIGN_OR_RETURN(const Json* v, Get(key));
  if (IsNonFinite(*v)) return Error(key, "expected a finite number, got " + NonFiniteName(*v));
  if (!v->is_number()) return Error(key, "expected a number, got " + JsonTypeDescription(*v));
  const std::string range = "[" + std::to_string(min) + ", " + std::to_string(max) + "]";
  auto bad = [&] { return Error(key, "expected an integer in " + range + ", got " + v->dump()); };
  if (v->is_number_unsigned()) {
    const uint64_t x = v->get<uint64_t>();
    if (max < 0 || x > uint64_t(max) || (min > 0 && x < uint64_t(min))) return bad();
    return static_cast<int64_t>(x);
  }
  if (v->is_number_integer()) {
    const int64_t x = v->get<int64_t>();
    if (x < min || x > max) return bad();
    return x;
  }
  const double x = v->get<double>();
  // The double comparisons are exact for the bounds used in practice (|bound| <= 2^53).
  if (!std::isfinite(x) || x != std::floor(x) || x < double(min) || x > double(max)) return bad();
  return static_cast<int64_t>(x);
}

Result<uint64_t> JsonObjectView::Uint64(std::string_view key) const {
  ICEF_ASSIGN_OR_RETURN(const Json* v, Get(key));
  if (v->is_number_unsigned()) return v->get<uint64_t>();
  if (v->is_number_integer() && v->get<int64_t>() >= 0) return static_cast<uint64_t>(v->get<int64_t>());
  return Error(
      key, "expected a non-negative integer, got " + (v->is_number() ? v->dump() : JsonTypeDescription(*v)));
}

Result<bool> JsonObjectView::Bool(std::string_view key) const {
  ICEF_ASSIGN_OR_RETURN(const Json* v, Get(key));
  if (!v->is_boolean()) return Error(key, "expected true or false, got " + JsonTypeDescription(*v));
  return v->get<bool>();
}

Result<std::string> JsonObjectView::String(std::string_view key) const {
  ICEF_ASSIGN_OR_RETURN(const Json* v, Get(key));
  if (!v->is_string() || IsNonFinite(*v))
    return Error(key, "expected a string, got " + JsonTypeDescription(*v));
  return v->get<std::string>();
}

namespace {

std::string ArrayOf(int size, const std::string& what) {
  return size < 0 ? "an array of " + what : "an array of " + std::to_string(size) + " " + what;
}

}  // namespace

Result<std::vector<double>> JsonObjectView::NumberArray(std::string_view key, int expected_size) const {
  ICEF_ASSIGN_OR_RETURN(const Json* v, Get(key));
  const std::string expected = "expected " + ArrayOf(expected_size, "numbers");
  if (!v->is_array()) return Error(key, expected + ", got " + JsonTypeDescription(*v));
  if (expected_size >= 0 && v->size() != size_t(expected_size))
    return Error(key, expected + ", got " + std::to_string(v->size()) + " values");
  std::vector<double> out;
  out.reserve(v->size());
  for (size_t i = 0; i < v->size(); ++i) {
    const Json& e = (*v)[i];
    if (IsNonFinite(e))
      return Error(key, "non-finite value " + NonFiniteName(e) + " at [" + std::to_string(i) + "]");
    if (!e.is_number())
      return Error(key, expected + ", got " + JsonTypeDescription(e) + " at [" + std::to_string(i) + "]");
    out.push_back(e.get<double>());
  }
  return out;
}

Result<std::vector<std::string>> JsonObjectView::StringArray(std::string_view key, int expected_size) const {
  ICEF_ASSIGN_OR_RETURN(const Json* v, Get(key));
  const std::string expected = "expected " + ArrayOf(expected_size, "strings");
  if (!v->is_array()) return Error(key, expected + ", got " + JsonTypeDescription(*v));
  if (expected_size >= 0 && v->size() != size_t(expected_size))
    return Error(key, expected + ", got " + std::to_string(v->size()) + " values");
  std::vector<std::string> out;
  for (size_t i = 0; i < v->size(); ++i) {
    const Json& e = (*v)[i];
    if (!e.is_string() || IsNonFinite(e))
      return Error(key, expected + ", got " + JsonTypeDescription(e) + " at [" + std::to_string(i) + "]");
    out.push_back(e.get<std::string>());
  }
  return out;
}

Result<std::vector<bool>> JsonObjectView::BoolArray(std::string_view key, int expected_size) const {
  ICEF_ASSIGN_OR_RETURN(const Json* v, Get(key));
  const std::string expected = "expected " + ArrayOf(expected_size, "booleans");
  if (!v->is_array()) return Error(key, expected + ", got " + JsonTypeDescription(*v));
  if (expected_size >= 0 && v->size() != size_t(expected_size))
    return Error(key, expected + ", got " + std::to_string(v->size()) + " values");
  std::vector<bool> out;
  for (size_t i = 0; i < v->size(); ++i) {
    const Json& e = (*v)[i];
    if (!e.is_boolean())
      return Error(key, expected + ", got " + JsonTypeDescription(e) + " at [" + std::to_string(i) + "]");
    out.push_back(e.get<bool>());
  }
  return out;
}

Result<std::vector<std::vector<double>>> JsonObjectView::NumberMatrix(std::string_view key, int rows,
                                                                      int cols) const {
  ICEF_ASSIGN_OR_RETURN(const Json* v, Get(key));
  const std::string expected = "expected " + ArrayOf(rows, "arrays of " + std::to_string(cols) + " numbers");
  if (!v->is_array()) return Error(key, expected + ", got " + JsonTypeDescription(*v));
  if (rows >= 0 && v->size() != size_t(rows))
    return Error(key, expected + ", got " + std::to_string(v->size()) + " entries");
  std::vector<std::vector<double>> out;
  out.reserve(v->size());
  for (size_t r = 0; r < v->size(); ++r) {
    const Json& row = (*v)[r];
    const std::string at = " at [" + std::to_string(r) + "]";
    if (!row.is_array() || row.size() != size_t(cols))
      return Error(key, expected + ", got " + JsonTypeDescription(row) + at);
    std::vector<double> values;
    values.reserve(cols);
    for (size_t c = 0; c < row.size(); ++c) {
      const Json& e = row[c];
      const std::string at_rc = " at [" + std::to_string(r) + "][" + std::to_string(c) + "]";
      if (IsNonFinite(e)) return Error(key, "non-finite value " + NonFiniteName(e) + at_rc);
      if (!e.is_number()) return Error(key, expected + ", got " + JsonTypeDescription(e) + at_rc);
      values.push_back(e.get<double>());
    }
    out.push_back(std::move(values));
  }
  return out;
}

Result<JsonObjectView> JsonObjectView::Object(std::string_view key) const {
  ICEF_ASSIGN_OR_RETURN(const Json* v, Get(key));
  if (!v->is_object()) return Error(key, "expected an object, got " + JsonTypeDescription(*v));
  return JsonObjectView(v, file_, Where(key));
}

Result<std::vector<JsonObjectView>> JsonObjectView::ObjectArray(std::string_view key) const {
  ICEF_ASSIGN_OR_RETURN(const Json* v, Get(key));
  if (!v->is_array()) return Error(key, "expected an array of objects, got " + JsonTypeDescription(*v));
  std::vector<JsonObjectView> out;
  out.reserve(v->size());
  for (size_t i = 0; i < v->size(); ++i) {
    const std::string element = Where(key) + "[" + std::to_string(i) + "]";
    if (!(*v)[i].is_object())
      return Status::Error(file_ + ": " + element + ": expected an object, got " +
                           JsonTypeDescription((*v)[i]));
    out.push_back(JsonObjectView(&(*v)[i], file_, element));
  }
  return out;
}

namespace {
void CollectDifferences(const Json& a, const Json& b, const std::string& prefix,
                        std::vector<std::string>* out) {
  if (!a.is_object() || !b.is_object()) {
    if (a != b) out->push_back(prefix);
    return;
  }
  auto path = [&](const std::string& key) { return prefix.empty() ? key : prefix + "." + key; };
  for (auto it = a.begin(); it != a.end(); ++it) {
    const auto other = b.find(it.key());
    if (other == b.end()) {
      out->push_back(path(it.key()));
    } else {
      CollectDifferences(it.value(), *other, path(it.key()), out);
    }
  }
  for (auto it = b.begin(); it != b.end(); ++it)
    if (!a.contains(it.key())) out->push_back(path(it.key()));
}
}  // namespace

std::vector<std::string> JsonDifferences(const Json& a, const Json& b) {
  std::vector<std::string> out;
  CollectDifferences(a, b, "", &out);
  return out;
}

}  // namespace icef
