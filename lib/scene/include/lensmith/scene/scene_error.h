// Errors of the scene layer: an invalid scene built in code, and a scene file that cannot be read.
#pragma once

#include <string>
#include <utility>

#include "lensmith/core/errors.h"

namespace lensmith {

// A scene (built in code) is not valid: "objects[2] (sphere \"sun\"): radius_m = -1: must be > 0".
class SceneError : public Error {
 public:
  using Error::Error;
};

// A scene file (docs/scene-format.md) could not be read: the message starts with file:line:col and
// names the key and what was expected ("scene.json:12:17: objects[1].radius_m: must be > 0, got -1").
class SceneFileError : public Error {
 public:
  SceneFileError(SourceLocation where, const std::string& what)
      : Error(where.to_string() + ": " + what), where_(std::move(where)), detail_(what) {}
  const SourceLocation& where() const { return where_; }
  const std::string& what_without_location() const { return detail_; }

 private:
  SourceLocation where_;
  std::string detail_;
};

}  // namespace lensmith
