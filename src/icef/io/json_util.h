// Strict JSON helpers (nlohmann::json underneath). Typed getters whose errors name the file and
// the field, e.g. "data/transforms_train.json: frames[3].expression: expected an array of 12
// numbers, got 11 values". Whether unknown keys are an error is the caller's policy: datasets
// ignore them (other tools add their own), run configs reject them (UnknownKeys()).
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "icef/core/status.h"

namespace icef {

using Json = nlohmann::ordered_json;  // keeps keys in document order

// Parses JSON text. Python's json.dump writes NaN, Infinity and -Infinity as bare literals; they
// are accepted here as marker values that every numeric getter rejects as "non-finite", so the
// error names the field that holds them. `file` prefixes error messages.
Result<Json> ParseJson(std::string_view text, const std::string& file);
// Reads and parses a JSON file; errors name the file.
Result<Json> ReadJsonFile(const std::filesystem::path& path);

// A number for JSON output that prints as the shortest decimal reproducing the float exactly
// (0.1f is written as 0.1, not 0.10000000149011612).
Json JsonFloat(float value);

// Pretty-prints with a 2-space indent, but writes arrays of scalars (numbers, strings, bools) on
// one line, so matrices and landmark lists stay readable. Ends with a newline.
std::string FormatJson(const Json& value);

// One JSON object inside a file, with its location for error messages. The viewed Json must
// outlive the view.
class JsonObjectView {
 public:
  // Fails unless `value` is an object. `path` is the object's location: "" for the document
  // root, "frames[3]" for a frame.
  static Result<JsonObjectView> Make(const Json& value, std::string file, std::string path);

  const std::string& file() const { return file_; }
  const std::string& path() const { return path_; }
  const Json& json() const { return *value_; }
  // Present under this key (whatever its type, null included).
  bool Has(std::string_view key) const;
  // Keys present here that are not in `known`, in document order.
  std::vector<std::string> UnknownKeys(const std::vector<std::string>& known) const;

  // "frames[3].expression" (just "expression" at the root).
  std::string Where(std::string_view key) const;
  // "<file>: <where>: <message>".
  Status Error(std::string_view key, const std::string& message) const;
  // "<file>: <path>: <message>" (or "<file>: <message>" at the root).
  Status ErrorHere(const std::string& message) const;

  // Required typed getters: a missing key is "missing required field", a wrong type or a
  // non-finite number an error naming the field.
  Result<double> Number(std::string_view key) const;
  Result<int> Int(std::string_view key) const;  // an integer-valued number within int range
  // An integer-valued number in [min, max]; JSON integers are read exactly over the whole int64
  // range, numbers written with a fraction or exponent must be whole.
  Result<int64_t> Int64(std::string_view key, int64_t min, int64_t max) const;
  // A non-negative JSON integer, read exactly over the whole uint64 range (hashes).
  Result<uint64_t> Uint64(std::string_view key) const;
  Result<bool> Bool(std::string_view key) const;
  Result<std::string> String(std::string_view key) const;
  // Arrays; expected_size < 0 accepts any length.
  Result<std::vector<double>> NumberArray(std::string_view key, int expected_size = -1) const;
  Result<std::vector<std::string>> StringArray(std::string_view key, int expected_size = -1) const;
  Result<std::vector<bool>> BoolArray(std::string_view key, int expected_size = -1) const;
  // rows x cols numbers, e.g. a 4x4 matrix or 68 [x, y] landmarks (rows < 0: any count).
  Result<std::vector<std::vector<double>>> NumberMatrix(std::string_view key, int rows, int cols) const;
  Result<JsonObjectView> Object(std::string_view key) const;
  Result<std::vector<JsonObjectView>> ObjectArray(std::string_view key) const;

 private:
  JsonObjectView(const Json* value, std::string file, std::string path)
      : value_(value), file_(std::move(file)), path_(std::move(path)) {}
  Result<const Json*> Get(std::string_view key) const;

  const Json* value_;
  std::string file_;
  std::string path_;
};

// Dotted paths ("train.lambda_id") of the values that differ between two JSON objects: nested
// objects are compared key by key, anything else as a whole; keys present on one side only count
// as differences. In the order of `a`'s keys, then those only in `b`.
std::vector<std::string> JsonDifferences(const Json& a, const Json& b);

// Describes a JSON value's type for error messages ("a string", "null", "a non-finite number").
std::string JsonTypeDescription(const Json& value);

}  // namespace icef
