// Ceres Solver (ceres-solver.org) behind plain types: the three of its solvers lensmith uses, robust
// linear least squares (lib/polyfit's Huber fits), damped least squares within bounds and BFGS line
// search (lib/design's optimiser).
//
// Why behind plain types: Ceres, statically linked, brings 17 shared libraries (glog, gflags,
// SuiteSparse, LAPACK, BLAS, ATLAS, gfortran) that cost every process about 5 ms to load on this
// project's 2-core test machine (docs/performance.md), and most commands (bokeh, info, trace) never
// solve anything. Programs that link lensmith's libraries get these functions from lensmith::solve,
// with Ceres linked in as before; the command line instead defines them over a module it loads the
// first time a command solves something (liblensmith_ceres.so, ceres_module.h).
#pragma once

#include <functional>
#include <span>
#include <string>
#include <vector>

namespace lensmith {

// One iteration, as Ceres' IterationSummary reports it.
struct SolverIteration {
  int iteration = 0;
  // Ceres' cost: half the sum of squared residuals (least squares), the function's value (line search).
  double cost = 0.0;
  double step_norm = 0.0;
  bool step_accepted = false;
};
using SolverProgress = std::function<void(const SolverIteration&)>;

// What a solve reports (Ceres' Solver::Summary).
struct SolverReport {
  int iterations = 0;       // summary.iterations.size(): the starting point counts as one
  bool usable = false;      // IsSolutionUsable()
  bool failed = false;      // terminated with FAILURE (Ceres keeps the best parameters it found)
  double initial_cost = 0.0;
  double final_cost = 0.0;
  std::string message;      // summary.message
  std::string brief;        // BriefReport()
};

// Convergence limits shared by the solvers below (Ceres' options of the same names).
struct SolverLimits {
  int max_iterations = 50;
  double function_tolerance = 1e-6;
  double gradient_tolerance = 1e-10;
  double parameter_tolerance = 1e-8;
};

// design * c ~ targets (design row-major, targets.size() rows x coefficients.size() columns) under
// Huber's loss of scale `huber_scale` on each row's residual, by Levenberg-Marquardt with dense QR,
// from `coefficients` (in place). The problem is linear, so the first step is the Gauss-Newton
// solution (no damping to start with); `limits` stop the steps that then only move by rounding.
SolverReport solve_huber_linear(std::span<const double> design, std::span<const double> targets, double huber_scale,
                                const SolverLimits& limits, std::span<double> coefficients);

// Least squares with bounds: Levenberg-Marquardt (dense QR, one thread) over x.
struct BoundedLeastSquares {
  int residuals = 0;
  // The residuals at x (`residuals` of them) and, where `jacobian` is not null, their Jacobian
  // (residuals x x.size(), row-major); false where they cannot be computed at x.
  std::function<bool(const double* x, double* residuals, double* jacobian)> evaluate;
  std::vector<double> lower, upper;  // per parameter, empty or x.size(); +-infinity: unbounded
  SolverLimits limits;
  SolverProgress progress;  // after each iteration; may be empty
};
SolverReport solve_bounded_least_squares(const BoundedLeastSquares& problem, std::span<double> x);

// Minimisation of a smooth function by BFGS line search over x.
struct LineSearchMinimisation {
  // The function's value at x and, where `gradient` is not null, its gradient; false where it cannot
  // be computed at x (the line search then shortens its step).
  std::function<bool(const double* x, double* value, double* gradient)> evaluate;
  SolverLimits limits;
  SolverProgress progress;
};
SolverReport minimise_bfgs(const LineSearchMinimisation& problem, std::span<double> x);

}  // namespace lensmith
