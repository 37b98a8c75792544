// The command line's ceres_solvers.h: the same functions, forwarded to the Ceres module
// (ceres_module.h), which is loaded on the first call. Linked into the command line as objects, so
// that the linker finds these definitions before lensmith::solve's (which would pull Ceres in).
//
// Where the module is looked for: in $LENSMITH_MODULE_DIR alone where that is set; else beside the
// program (the build tree) and in LENSMITH_MODULE_RELATIVE_DIR relative to the program's folder (an
// install: bin/ -> lib/lensmith).
#include <dlfcn.h>

#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <string>
#include <system_error>
#include <vector>

#include "ceres_module.h"
#include "lensmith/core/errors.h"

namespace lensmith {

namespace {

namespace fs = std::filesystem;

std::vector<fs::path> module_folders() {
  if (const char* dir = std::getenv("LENSMITH_MODULE_DIR"); dir != nullptr && *dir != '\0') return {fs::path(dir)};
  std::error_code ec;
  const fs::path program = fs::read_symlink("/proc/self/exe", ec);
  if (ec) return {};
  const fs::path folder = program.parent_path();
  return {folder, (folder / LENSMITH_MODULE_RELATIVE_DIR).lexically_normal()};
}

const CeresModuleApi& load_module() {
  static const CeresModuleApi* api = nullptr;
  static std::string failure;
  static std::once_flag once;
  std::call_once(once, [] {
    std::string tried;
    for (const fs::path& folder : module_folders()) {
      const fs::path file = folder / kCeresModuleFile;
      tried += "\n  " + file.string();
      std::error_code ec;
      if (!fs::exists(file, ec)) continue;
      void* handle = dlopen(file.c_str(), RTLD_NOW | RTLD_LOCAL);
      if (handle == nullptr) {
        const char* why = dlerror();
        tried += std::string(": ") + (why != nullptr ? why : "dlopen failed");
        continue;
      }
      using Entry = const CeresModuleApi* (*)();
      const auto entry = reinterpret_cast<Entry>(dlsym(handle, kCeresModuleEntry));
      const CeresModuleApi* found = entry != nullptr ? entry() : nullptr;
      if (found == nullptr || found->abi != kCeresModuleAbi) {
        tried += ": not a lensmith Ceres module of this build (ABI " + std::to_string(found != nullptr ? found->abi : -1) +
                 ", expected " + std::to_string(kCeresModuleAbi) + ")";
        dlclose(handle);
        continue;
      }
      api = found;  // kept loaded for the process's life
      return;
    }
    failure = std::string("lensmith's Ceres module (") + kCeresModuleFile +
              "), which this command needs for its solver, was not found or not usable; looked for:" + tried +
              "\nReinstall lensmith, or set LENSMITH_MODULE_DIR to the folder that holds it";
  });
  if (api == nullptr) throw IoError(failure);
  return *api;
}

}  // namespace

SolverReport solve_huber_linear(std::span<const double> design, std::span<const double> targets, double huber_scale,
                                const SolverLimits& limits, std::span<double> coefficients) {
  return load_module().solve_huber_linear(design, targets, huber_scale, limits, coefficients);
}

SolverReport solve_bounded_least_squares(const BoundedLeastSquares& problem, std::span<double> x) {
  return load_module().solve_bounded_least_squares(problem, x);
}

SolverReport minimise_bfgs(const LineSearchMinimisation& problem, std::span<double> x) {
  return load_module().minimise_bfgs(problem, x);
}

}  // namespace lensmith
