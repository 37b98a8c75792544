// JSON with the source position of every value, so that readers of JSON files can say
// "lens.json:12:17: surfaces[3].thickness_mm: expected a number, got a string" instead of just
// "type error". Built on nlohmann::json's SAX interface.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include <nlohmann/json.hpp>

#include "lensmith/core/errors.h"

namespace lensmith {

class LocatedJson {
 public:
  // Parses `text`; throws FileError(file:line:col) on a syntax error, on nesting deeper than
  // `max_depth` levels, or on duplicate object keys.
  static LocatedJson parse(std::string_view text, const std::string& file_name, int max_depth = 64);

  const nlohmann::json& root() const { return root_; }
  const std::string& file_name() const { return file_name_; }
  // Where the value at `pointer` (a JSON pointer, "" for the root) starts in the text.
  SourceLocation where(const std::string& pointer) const;

 private:
  nlohmann::json root_;
  std::string file_name_;
  std::unordered_map<std::string, std::pair<int, int>> positions_;  // pointer -> (line, column)
  friend class LocatedJsonBuilder;
};

// Strict reading of one JSON object: every key must be consumed by a get_* call, and
// finish() reports the first unknown key with its position and the keys that are allowed.
// Paths in messages use dotted form: surfaces[2].thickness_mm.
class JsonObjectReader {
 public:
  // Throws FileError unless the value at `pointer` is an object. `display_path` names it in
  // messages ("" for the root).
  JsonObjectReader(const LocatedJson& doc, std::string pointer, std::string display_path);

  bool has(const std::string& key) const;
  // The value of `key` if present; marks it consumed.
  const nlohmann::json* get(const std::string& key);
  // Typed getters: throw FileError at the value's position when the type is wrong or, for the
  // required forms, when the key is missing.
  double get_number(const std::string& key);
  std::optional<double> get_optional_number(const std::string& key);
  std::string get_string(const std::string& key);
  std::optional<std::string> get_optional_string(const std::string& key);
  std::optional<bool> get_optional_bool(const std::string& key);
  // Size of the array at `key` (throws when not an array); marks it consumed.
  std::size_t get_array_size(const std::string& key);

  // JSON pointer and display path of a child, for nested readers and messages.
  std::string child_pointer(const std::string& key) const;
  std::string child_path(const std::string& key) const;
  std::string pointer() const { return pointer_; }
  std::string path() const { return path_; }
  // Location of `key`'s value, or of this object when absent.
  SourceLocation where(const std::string& key = {}) const;
  // An error at `key` (or at this object) with the path prefixed: "surfaces[2].radius_mm: ...".
  [[noreturn]] void fail(const std::string& key, const std::string& message) const;

  // Throws on the first key not consumed, listing the allowed keys.
  void finish(const std::vector<std::string>& allowed_keys) const;

  const nlohmann::json& value() const { return *object_; }
  const LocatedJson& document() const { return doc_; }

 private:
  const LocatedJson& doc_;
  std::string pointer_;
  std::string path_;
  const nlohmann::json* object_;
  std::vector<std::string> consumed_;
};

// Name of a JSON value's type for messages: "a number", "a string", "an object", ...
std::string json_type_phrase(const nlohmann::json& value);
// Escapes a key for use in a JSON pointer (~ -> ~0, / -> ~1).
std::string json_pointer_escape(const std::string& key);

}  // namespace lensmith
