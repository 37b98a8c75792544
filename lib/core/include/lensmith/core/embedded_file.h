// A data file compiled into the library (glass catalogues, shipped lenses), named by its path
// relative to the folder it came from. See cmake/EmbedFiles.cmake.
#pragma once

#include <span>
#include <string_view>

namespace lensmith {

struct EmbeddedFile {
  std::string_view path;
  std::string_view text;
};

}  // namespace lensmith
