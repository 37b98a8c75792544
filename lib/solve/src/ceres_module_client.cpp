// The command line's ceres_solvers.h: the same functions, forwarded to the Ceres module
// (ceres_module.h), which is loaded on the first call (lensmith/core/module_loader.h). Linked into the
// command line as objects, so that the linker finds these definitions before lensmith::solve's
// (which would pull Ceres in).
#include "ceres_module.h"
#include "lensmith/core/module_loader.h"

namespace lensmith {

namespace {

const CeresModuleApi& module() {
  return *static_cast<const CeresModuleApi*>(load_module(kCeresModuleFile, kCeresModuleEntry, kCeresModuleAbi, "its solver"));
}

}  // namespace

SolverReport solve_huber_linear(std::span<const double> design, std::span<const double> targets, double huber_scale,
                                const SolverLimits& limits, std::span<double> coefficients) {
  return module().solve_huber_linear(design, targets, huber_scale, limits, coefficients);
}

SolverReport solve_bounded_least_squares(const BoundedLeastSquares& problem, std::span<double> x) {
  return module().solve_bounded_least_squares(problem, x);
}

SolverReport minimise_bfgs(const LineSearchMinimisation& problem, std::span<double> x) {
  return module().minimise_bfgs(problem, x);
}

}  // namespace lensmith
