// Helpers for the lens-file readers' tests: where a snippet sits in a test file's text, and whether
// a reader reported a diagnostic.
#pragma once

#include <stdexcept>
#include <string>

#include "lensmith/core/diagnostic.h"

namespace lensmith::testing {

// 1-based line of the first occurrence of `needle` in `text`; throws std::logic_error when absent,
// so a test whose text lost the snippet fails loudly instead of checking line 0.
inline int line_of(const std::string& text, const std::string& needle) {
  const auto pos = text.find(needle);
  if (pos == std::string::npos) throw std::logic_error("test text lacks " + needle);
  int line = 1;
  for (std::size_t i = 0; i < pos; ++i) line += text[i] == '\n' ? 1 : 0;
  return line;
}

// Whether `diagnostics` holds one of `severity` at `line` whose message contains `text`.
inline bool has_diagnostic(const Diagnostics& diagnostics, Diagnostic::Severity severity, int line, const std::string& text) {
  for (const Diagnostic& d : diagnostics) {
    if (d.severity == severity && d.where.line == line && d.message.find(text) != std::string::npos) return true;
  }
  return false;
}

}  // namespace lensmith::testing
