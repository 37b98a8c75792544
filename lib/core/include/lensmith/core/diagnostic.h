// Warnings collected while reading or computing, returned to the caller instead of printed:
// the library never writes to a terminal; the CLI decides what to show.
#pragma once

#include <ostream>
#include <string>
#include <vector>

#include "lensmith/core/errors.h"

namespace lensmith {

struct Diagnostic {
  enum class Severity { Note, Warning };
  Severity severity = Severity::Warning;
  SourceLocation where;  // may be empty when the warning is not about a file position
  std::string message;

  std::string to_string() const;
  friend std::ostream& operator<<(std::ostream& os, const Diagnostic& d) { return os << d.to_string(); }
};

using Diagnostics = std::vector<Diagnostic>;

}  // namespace lensmith
