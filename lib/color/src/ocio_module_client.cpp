// The command line's ocio_backend(): OpenColorIO's functions from its module (liblensmith_ocio.so),
// loaded the first time a command converts colour spaces (lensmith/core/module_loader.h). Linked into
// the command line as objects, so that the linker finds this definition before lensmith::color's
// ocio_backend.cpp (which would pull OpenColorIO in).
#include "lensmith/core/module_loader.h"
#include "ocio_backend.h"

namespace lensmith::color_detail {

const OcioBackend& ocio_backend() {
  return *static_cast<const OcioBackend*>(load_module(kOcioModuleFile, kOcioModuleEntry, kOcioBackendAbi, "colour management"));
}

}  // namespace lensmith::color_detail
