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

LensFileError::LensFileError(SourceLocation where, const std::string& what)
    : Error(where.to_string() + ": " + what), where_(std::move(where)), detail_(what) {}

}  // namespace lensmith
