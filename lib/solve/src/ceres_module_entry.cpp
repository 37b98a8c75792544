// The Ceres module's entry point (ceres_module.h): the table of ceres_solvers.cpp's functions. The
// module is built with hidden visibility and -Bsymbolic, so that these addresses are the module's own
// functions and not the command line's stand-ins of the same names (ceres_module_client.cpp).
#include "ceres_module.h"

extern "C" __attribute__((visibility("default"))) const void* lensmith_ceres_module_api() {
  static const lensmith::CeresModuleApi api{lensmith::kCeresModuleAbi, &lensmith::solve_huber_linear,
                                            &lensmith::solve_bounded_least_squares, &lensmith::minimise_bfgs};
  return &api;
}
