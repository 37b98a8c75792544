// The solvers of ceres_solvers.h with Ceres: built into lensmith::solve and into the command line's
// module (liblensmith_ceres.so, ceres_module.h).
#include "lensmith/solve/ceres_solvers.h"

#include <algorithm>
#include <cmath>
#include <memory>

#include <ceres/ceres.h>

namespace lensmith {

namespace {

// One residual per row: r = sum_j row[j] c[j] - target. Linear, so the Jacobian is the row.
class RowResidual final : public ceres::CostFunction {
 public:
  RowResidual(const double* row, int terms, double target) : row_(row), terms_(terms), target_(target) {
    set_num_residuals(1);
    mutable_parameter_block_sizes()->push_back(terms);
  }
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    const double* c = parameters[0];
    double s = -target_;
    for (int j = 0; j < terms_; ++j) s += row_[j] * c[j];
    residuals[0] = s;
    if (jacobians != nullptr && jacobians[0] != nullptr) std::copy(row_, row_ + terms_, jacobians[0]);
    return true;
  }

 private:
  const double* row_;
  int terms_;
  double target_;
};

// A BoundedLeastSquares' residuals as one residual block over one parameter block.
class FunctionCost final : public ceres::CostFunction {
 public:
  FunctionCost(const BoundedLeastSquares& problem, int parameters) : problem_(problem) {
    set_num_residuals(problem.residuals);
    mutable_parameter_block_sizes()->push_back(parameters);
  }
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    return problem_.evaluate(parameters[0], residuals, jacobians != nullptr ? jacobians[0] : nullptr);
  }

 private:
  const BoundedLeastSquares& problem_;
};

class FunctionOfParameters final : public ceres::FirstOrderFunction {
 public:
  FunctionOfParameters(const LineSearchMinimisation& problem, int parameters) : problem_(problem), parameters_(parameters) {}
  int NumParameters() const override { return parameters_; }
  bool Evaluate(const double* parameters, double* value, double* gradient) const override {
    return problem_.evaluate(parameters, value, gradient);
  }

 private:
  const LineSearchMinimisation& problem_;
  int parameters_;
};

class ProgressCallback final : public ceres::IterationCallback {
 public:
  explicit ProgressCallback(const SolverProgress& progress) : progress_(progress) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary& summary) override {
    if (progress_) progress_({summary.iteration, summary.cost, summary.step_norm, summary.step_is_successful});
    return ceres::SOLVER_CONTINUE;
  }

 private:
  const SolverProgress& progress_;
};

template <typename Summary>
SolverReport report_of(const Summary& summary) {
  SolverReport r;
  r.iterations = static_cast<int>(summary.iterations.size());
  r.usable = summary.IsSolutionUsable();
  r.failed = summary.termination_type == ceres::FAILURE;
  r.initial_cost = summary.initial_cost;
  r.final_cost = summary.final_cost;
  r.message = summary.message;
  r.brief = summary.BriefReport();
  return r;
}

}  // namespace

SolverReport solve_huber_linear(std::span<const double> design, std::span<const double> targets, double huber_scale,
                                const SolverLimits& limits, std::span<double> coefficients) {
  const auto terms = static_cast<int>(coefficients.size());
  ceres::HuberLoss loss(huber_scale);
  ceres::Problem::Options problem_options;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  // A robust loss acts on each residual block's squared norm: one block per row.
  for (std::size_t i = 0; i < targets.size(); ++i) {
    problem.AddResidualBlock(new RowResidual(&design[i * coefficients.size()], terms, targets[i]), &loss, coefficients.data());
  }
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;  // QR: the normal equations would square the condition number
  options.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  // The problem is linear: a vanishing LM damping makes the first step the Gauss-Newton solution.
  options.initial_trust_region_radius = 1e16;
  options.max_trust_region_radius = 1e32;
  options.function_tolerance = limits.function_tolerance;
  options.parameter_tolerance = limits.parameter_tolerance;
  options.gradient_tolerance = limits.gradient_tolerance;
  options.max_num_iterations = limits.max_iterations;
  options.logging_type = ceres::SILENT;
  // Later steps of a linear problem only move by rounding: a short run of invalid steps ends it.
  options.max_num_consecutive_invalid_steps = 2;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  return report_of(summary);
}

SolverReport solve_bounded_least_squares(const BoundedLeastSquares& problem, std::span<double> x) {
  ceres::Problem p;  // owns the cost
  p.AddResidualBlock(new FunctionCost(problem, static_cast<int>(x.size())), nullptr, x.data());
  for (std::size_t j = 0; j < x.size(); ++j) {
    if (j < problem.lower.size() && std::isfinite(problem.lower[j])) p.SetParameterLowerBound(x.data(), static_cast<int>(j), problem.lower[j]);
    if (j < problem.upper.size() && std::isfinite(problem.upper[j])) p.SetParameterUpperBound(x.data(), static_cast<int>(j), problem.upper[j]);
  }
  ceres::Solver::Options options;
  options.minimizer_type = ceres::TRUST_REGION;
  options.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  options.linear_solver_type = ceres::DENSE_QR;
  options.max_num_iterations = problem.limits.max_iterations;
  options.function_tolerance = problem.limits.function_tolerance;
  options.gradient_tolerance = problem.limits.gradient_tolerance;
  options.parameter_tolerance = problem.limits.parameter_tolerance;
  options.num_threads = 1;  // the caller's evaluate runs in parallel itself
  options.logging_type = ceres::SILENT;
  ProgressCallback callback(problem.progress);
  options.callbacks.push_back(&callback);
  ceres::Solver::Summary summary;
  ceres::Solve(options, &p, &summary);
  return report_of(summary);
}

SolverReport minimise_bfgs(const LineSearchMinimisation& problem, std::span<double> x) {
  ceres::GradientProblem p(new FunctionOfParameters(problem, static_cast<int>(x.size())));  // owns the function
  ceres::GradientProblemSolver::Options options;
  options.line_search_direction_type = ceres::BFGS;
  options.max_num_iterations = problem.limits.max_iterations;
  options.function_tolerance = problem.limits.function_tolerance;
  options.gradient_tolerance = problem.limits.gradient_tolerance;
  options.parameter_tolerance = problem.limits.parameter_tolerance;
  options.logging_type = ceres::SILENT;
  ProgressCallback callback(problem.progress);
  options.callbacks.push_back(&callback);
  ceres::GradientProblemSolver::Summary summary;
  ceres::Solve(options, p, x.data(), &summary);
  return report_of(summary);
}

}  // namespace lensmith
