#include "lensmith/core/diagnostic.h"

namespace lensmith {

std::string Diagnostic::to_string() const {
  std::string s;
  if (!where.file.empty() || where.line > 0) s = where.to_string() + ": ";
  s += severity == Severity::Warning ? "warning: " : "note: ";
  return s + message;
}

}  // namespace lensmith
