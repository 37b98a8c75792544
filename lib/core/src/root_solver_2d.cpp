#include "lensmith/core/root_solver_2d.h"

#include <sstream>

#include "lensmith/core/errors.h"
#include "lensmith/core/number_parsing.h"

namespace lensmith {

namespace {

std::string_view jacobian_name(JacobianSource j) {
  switch (j) {
    case JacobianSource::Analytic: return "analytic";
    case JacobianSource::ForwardDifference: return "forward differences";
    case JacobianSource::Broyden: return "Broyden";
    case JacobianSource::Fixed: return "fixed";
  }
  return "?";
}

}  // namespace

void RootSolver2dOptions::validate() const {
  auto fail = [](const std::string& what) { throw OptionsError("RootSolver2dOptions::" + what); };
  if (!(std::isfinite(tolerance) && tolerance > 0.0)) fail("tolerance = " + format_number(tolerance) + ": must be finite and > 0");
  if (max_iterations < 0) fail("max_iterations = " + std::to_string(max_iterations) + ": must be >= 0");
  if (!(std::isfinite(difference_step) && difference_step > 0.0)) {
    fail("difference_step = " + format_number(difference_step) + ": must be finite and > 0");
  }
  if (!(max_step > 0.0)) fail("max_step = " + format_number(max_step) + ": must be > 0 (infinity: no trust region)");
  if (!(armijo >= 0.0 && armijo < 1.0)) fail("armijo = " + format_number(armijo) + ": must be in [0, 1)");
  if (max_halvings < 0) fail("max_halvings = " + std::to_string(max_halvings) + ": must be >= 0");
}

std::string RootSolver2dOptions::to_string() const {
  std::ostringstream os;
  os << "RootSolver2dOptions(" << jacobian_name(jacobian) << ", tolerance " << tolerance << ", " << max_iterations
     << " iterations";
  if (jacobian == JacobianSource::ForwardDifference) os << ", difference step " << difference_step;
  if (std::isfinite(max_step)) os << ", max step " << max_step;
  if (line_search) {
    os << ", line search (Armijo " << armijo << ", " << max_halvings << " halvings)";
  } else {
    os << ", full steps";
  }
  os << ")";
  return os.str();
}

std::string_view to_string(RootSolver2dStatus status) {
  switch (status) {
    case RootSolver2dStatus::Converged: return "converged";
    case RootSolver2dStatus::FailedAtStart: return "failed at the start";
    case RootSolver2dStatus::FailedEvaluation: return "failed to evaluate a step";
    case RootSolver2dStatus::SingularJacobian: return "singular Jacobian";
    case RootSolver2dStatus::NoDecrease: return "no decrease";
    case RootSolver2dStatus::OutOfIterations: return "out of iterations";
  }
  return "?";
}

std::string RootSolver2dSummary::to_string() const {
  std::ostringstream os;
  os << "RootSolver2dSummary(" << lensmith::to_string(status) << ", " << iterations << " iterations, |r| " << residual_norm << ")";
  return os.str();
}

}  // namespace lensmith
