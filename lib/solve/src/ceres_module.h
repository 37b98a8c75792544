// The command line's Ceres module (liblensmith_ceres.so): ceres_solvers.cpp and Ceres in a shared
// object of their own, which the command line loads the first time a command solves something
// (ceres_module_client.cpp, lensmith/core/module_loader.h), so that a process that solves nothing
// does not load Ceres' 17 shared libraries (ceres_solvers.h says why).
//
// Module and program are built together by the same compiler from the same sources: the table
// passes C++ types (spans, strings, std::function) as they are, and an exception a callback throws
// unwinds through Ceres in the module back to the program (the module is built with unwind tables,
// like every object of the build). kCeresModuleAbi guards against a module of another build that
// changed the table.
#pragma once

#include "lensmith/solve/ceres_solvers.h"

namespace lensmith {

// Raised whenever CeresModuleApi changes.
inline constexpr int kCeresModuleAbi = 1;

struct CeresModuleApi {
  int abi = kCeresModuleAbi;  // first: load_module checks it
  SolverReport (*solve_huber_linear)(std::span<const double>, std::span<const double>, double, const SolverLimits&,
                                     std::span<double>) = nullptr;
  SolverReport (*solve_bounded_least_squares)(const BoundedLeastSquares&, std::span<double>) = nullptr;
  SolverReport (*minimise_bfgs)(const LineSearchMinimisation&, std::span<double>) = nullptr;
};

// The module's one exported symbol.
inline constexpr const char* kCeresModuleEntry = "lensmith_ceres_module_api";
// The module's file name: beside the command line in the build tree, in <libdir>/lensmith installed.
inline constexpr const char* kCeresModuleFile = "liblensmith_ceres.so";

}  // namespace lensmith
