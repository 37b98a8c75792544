#include "lensmith/core/errors.h"

namespace lensmith {

std::string SourceLocation::to_string() const {
  std::string s = file.empty() ? std::string("<input>") : file;
  if (line > 0) {
    s += ':' + std::to_string(line);
    if (column > 0) s += ':' + std::to_string(column);
  }
  return s;
}

std::string ErrorSubject::to_string() const {
  std::string s;
  if (surface > 0) s = "surface " + std::to_string(surface);
  if (!field.empty()) {
    if (!s.empty()) s += ", ";
    s += field;
    if (index >= 0) {
      s += '[';
      s += std::to_string(index);
      s += ']';
    }
  }
  return s.empty() ? std::string("(none)") : s;
}

FileError::FileError(SourceLocation where, const std::string& what)
    : Error(where.to_string() + ": " + what), where_(std::move(where)), detail_(what) {}

}  // namespace lensmith
