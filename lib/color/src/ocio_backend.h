// OpenColorIO's part of colour management (color_management.h) behind plain types, so that the
// command line can load it from a module (liblensmith_ocio.so, lensmith/core/module_loader.h) the
// first time a command converts colour spaces: OpenColorIO and the 3 libraries it brings (yaml-cpp,
// expat, pystring) cost every process about 3 ms to load otherwise. Programs that link lensmith::color
// get ocio_backend.cpp linked in. No exception crosses the table: failures come back as OcioFailure.
#pragma once

#include <array>
#include <string>

#include "lensmith/color/color_management.h"

namespace lensmith::color_detail {

// The two conversions (OpenColorIO CPU processors) of one ColorManagement.
struct OcioConversions;

// Why the conversions could not be made: an OptionsError (a colour space the config lacks) or an
// IoError (the config cannot be read).
struct OcioFailure {
  bool options_error = false;
  std::string message;
};

// Raised whenever OcioBackend changes.
inline constexpr int kOcioBackendAbi = 1;

struct OcioBackend {
  int abi = kOcioBackendAbi;  // first: load_module checks it
  // Both conversions `options` asks for, with the config at `config_path` (an existing file); where
  // the config's aces_interchange role is the way to the working space, `ap0_to_rec709` (row-major)
  // follows it. Null on failure, with `failure` said; else `working_route` says how the working
  // space was reached (ColorManagement::working_route).
  OcioConversions* (*open)(const ColorManagementOptions& options, const std::string& config_path,
                           const std::array<double, 9>& ap0_to_rec709, std::string& working_route, OcioFailure& failure) = nullptr;
  void (*close)(OcioConversions* conversions) = nullptr;
  // `count` pixels of `channels` floats (R, G, B first, the rest left as they are) converted in place:
  // input -> working (to_working) or working -> output; nothing where that conversion was not asked for.
  void (*apply)(const OcioConversions& conversions, bool to_working, float* pixels, long count, int channels) = nullptr;
};

// OpenColorIO's functions: ocio_backend.cpp's in lensmith::color, the module's in the command line.
const OcioBackend& ocio_backend();

// The module's file and its one exported symbol (ocio_module_entry.cpp).
inline constexpr const char* kOcioModuleFile = "liblensmith_ocio.so";
inline constexpr const char* kOcioModuleEntry = "lensmith_ocio_module_api";

}  // namespace lensmith::color_detail
