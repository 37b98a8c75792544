// JSON as text that is always valid UTF-8.
//
// nlohmann::json::dump throws type_error 316 on a string that is not UTF-8; lensmith's strings come
// from files it decodes to UTF-8 (text_file.h), but a path on the command line or a name from a
// foreign file must never turn a report into an internal error. Every JSON lensmith writes goes
// through here: bytes that are not UTF-8 become U+FFFD.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

namespace lensmith {

// `value` as JSON text, indented by `indent` spaces per level (-1: one line).
template <typename Json>
std::string json_text(const Json& value, int indent = -1) {
  return value.dump(indent, ' ', false, nlohmann::json::error_handler_t::replace);
}

}  // namespace lensmith
