// Damped least squares: Levenberg-Marquardt (Ceres' trust-region solver) on the merit function of
// lensmith/design/merit_function.h, derivatives by central differences of the tracer (the tracer is
// written for doubles, not for Ceres' Jets), bounds by projection. Model glasses may be replaced by the
// nearest catalogue glass afterwards and the other variables polished. docs/optimize.md.
#pragma once

#include <cstddef>
#include <functional>
#include <ostream>
#include <string>
#include <vector>

#include "lensmith/design/merit_function.h"

namespace lensmith {

// The merit function evaluated on one lens.
struct MeritEvaluation {
  struct OperandValue {
    double value = 0.0;         // in the operand's unit (NaN when it could not be computed)
    double contribution = 0.0;  // its part of the merit, weight (value - goal)^2 (minimised ones: weight x RMS^2)
    std::string failure;        // why it could not be computed (empty when it could)
  };
  std::vector<OperandValue> operands;  // in the merit function's order
  std::vector<double> residuals;       // what the least squares see; their squares sum to `merit`
  double merit = 0.0;                  // the sum of the contributions
  bool ok() const;                     // every operand computed
};

// Evaluates every operand on `lens`. Real-ray operands trace without clipping at clear apertures (as
// optimisation with floating semi-diameters does; RayHeight limits the beams instead); central
// obscurations still stop rays. Never throws for a lens the optimiser wandered to: what cannot be
// computed is reported in OperandValue::failure and given a penalty residual.
MeritEvaluation evaluate_merit(const Prescription& lens, const MeritFunction& merit);

struct OptimizeProgress {
  int iteration = 0;          // 0 = the start
  double merit = 0.0;
  double step_norm = 0.0;     // in scaled variables (each divided by its finite-difference scale)
  bool step_accepted = true;
  std::string stage;          // "optimise" or "polish after glass substitution"
};

struct OptimizeOptions {
  int max_iterations = 50;        // Levenberg-Marquardt iterations per stage (1 to 10000)
  // Replace each model glass the optimisation chose (glass variables) by the nearest catalogue glass and
  // optimise the other variables again. The nearest: the smallest sqrt((dnd / 0.01)^2 + (dVd / 1)^2)
  // among the built-in catalogues' glasses whose status is not obsolete or special.
  bool substitute_glass = true;
  // Relative decrease of the merit per iteration below which Ceres stops (its function_tolerance).
  double merit_tolerance = 1e-9;
  int threads = 0;                // for the finite differences; 0 = OpenMP's default (every core, OMP_NUM_THREADS)
  std::function<void(const OptimizeProgress&)> progress;  // called after every iteration
  void validate() const;          // throws OptionsError
};

struct SubstitutedGlass {
  int surface = 0;                // 1-based: the glass after this surface
  double model_nd = 0.0, model_vd = 0.0;
  std::string glass;              // "SCHOTT N-SK16"
  double nd = 0.0, vd = 0.0;      // the catalogue glass's
};

struct OptimizeResult {
  Prescription start;
  Prescription result;
  MeritFunction merit_function;
  MeritEvaluation before;
  MeritEvaluation after;
  std::vector<double> start_values;   // each variable's, in its unit
  std::vector<double> result_values;
  int iterations = 0;                 // every stage's together
  std::size_t evaluations = 0;        // merit evaluations, finite differences included
  std::string termination;            // Ceres' reason for stopping, per stage
  std::vector<SubstitutedGlass> substitutions;
  std::vector<bool> at_bound;         // per variable: the result sits on a bound
  // The before/after table of variables and operands.
  std::string to_string() const;
  friend std::ostream& operator<<(std::ostream& os, const OptimizeResult& r) { return os << r.to_string(); }
};

// Optimises `lens`. Throws OptionsError (the merit function does not fit the lens, bad options),
// ComputationError when the starting lens's merit cannot be evaluated (e.g. an afocal lens asked for an EFL).
OptimizeResult optimize(const Prescription& lens, const MeritFunction& merit, const OptimizeOptions& options = {});

// The built-in catalogue glass nearest to (nd, Vd) by the distance of OptimizeOptions::substitute_glass.
const Glass& nearest_catalogue_glass(double nd, double vd);

}  // namespace lensmith
