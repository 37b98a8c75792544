// Errors of the scene layer: an invalid scene built in code.
#pragma once

#include <string>
#include <utility>

#include "lensmith/core/errors.h"

namespace lensmith {

// A scene (built in code) is not valid: "objects[2] (sphere \"sun\"): radius_m = -1: must be > 0";
// its subject's field is the key the message starts with ("radius_m").
class SceneError : public SubjectError {
 public:
  using SubjectError::SubjectError;
};

// A scene file (docs/scene-format.md) that cannot be read throws FileError (lensmith/core/errors.h)
// at file:line:col, naming the key and what was expected ("scene.json:12:17: objects[1].radius_m:
// must be > 0, got -1").

}  // namespace lensmith
