// Damped least squares with Ceres (Levenberg-Marquardt trust region, through lensmith/solve), central-
// difference derivatives of the merit function's residuals, bounds by Ceres' projection, glass
// substitution and a polishing stage.
#include "lensmith/design/optimizer.h"

#include <atomic>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

#include <omp.h>

#include "lensmith/core/errors.h"
#include "lensmith/core/number_parsing.h"
#include "lensmith/glass/glass_catalog.h"
#include "lensmith/paraxial/paraxial_system.h"
#include "lensmith/solve/ceres_solvers.h"

namespace lensmith {

namespace {

// Finite-difference steps (central differences). Each is about 1e-6 of what a designer would call a
// small change: small enough that the truncation error (step^2) vanishes, large enough above the tracer's
// rounding (about 1e-13 mm on landing points) that the quotient keeps seven or more digits.
constexpr double kRelativeStep = 1e-6;
constexpr double kAbbeStep = 1e-4;
// Variables are handed to Ceres divided by a scale 1e5 times their step, so that a step of the solver of
// about 1 is a designer's small change and the step norms Ceres reports are comparable across variables.
constexpr double kScalePerStep = 1e5;

// The lens's characteristic length, mm: |EFL| when it has one, else its length (an afocal lens).
double characteristic_length_mm(const Prescription& lens) {
  try {
    const double efl = std::abs(ParaxialSystem(lens).efl_mm());
    if (std::isfinite(efl) && efl > 0.0) return efl;
  } catch (const Error&) {
  }
  return std::max(1.0, std::abs(lens.last_vertex_z_mm()));
}

double step_of(const DesignVariable& v, double length_mm) {
  using K = DesignVariable::Kind;
  switch (v.kind) {
    case K::Curvature: return kRelativeStep / length_mm;
    case K::Thickness: return kRelativeStep * length_mm;
    case K::Conic: return kRelativeStep;
    case K::Asphere: return kRelativeStep / std::pow(length_mm, v.asphere_power - 1);
    case K::GlassIndex: return kRelativeStep;
    case K::GlassAbbe: return kAbbeStep;
  }
  return kRelativeStep;
}

// Whether `value` (the variable's unit) sits on one of its bounds, to 1e-9 of its size: where Ceres'
// projection left it, and what BFGS must then hold fixed.
bool on_bound(const DesignVariable& v, double value) {
  const double tolerance = 1e-9 * std::max(1.0, std::abs(value));
  return (v.min && std::abs(value - *v.min) <= tolerance) || (v.max && std::abs(value - *v.max) <= tolerance);
}

bool is_glass(const DesignVariable& v) {
  return v.kind == DesignVariable::Kind::GlassIndex || v.kind == DesignVariable::Kind::GlassAbbe;
}

// The merit function as the least-squares solver sees it: the scaled variables, the residuals of
// evaluate_merit, and a Jacobian by central differences computed in parallel.
class MeritCost final {
 public:
  MeritCost(const Prescription& lens, const MeritFunction& merit, std::vector<double> scales, int residuals, int threads,
            std::atomic<std::size_t>& evaluations)
      : lens_(lens), merit_(merit), scales_(std::move(scales)), residuals_(residuals), threads_(threads), evaluations_(evaluations) {}

  int num_residuals() const { return residuals_; }

  Prescription lens_at(const double* x) const {
    Prescription lens = lens_;
    for (std::size_t j = 0; j < scales_.size(); ++j) merit_.variables[j].apply(lens, x[j] * scales_[j]);
    if (merit_.efl_solve) merit_.efl_solve->apply(lens);
    return lens;
  }

  bool evaluate_at(const double* x, std::vector<double>& residuals) const {
    ++evaluations_;
    Prescription lens;
    try {
      lens = lens_at(x);
    } catch (const Error&) {
      return false;  // the solve has no answer here
    }
    const MeritEvaluation e = evaluate_merit(lens, merit_);
    if (!e.ok() || static_cast<int>(e.residuals.size()) != num_residuals()) return false;
    for (double r : e.residuals) {
      if (!std::isfinite(r)) return false;
    }
    residuals = e.residuals;
    return true;
  }

  // BoundedLeastSquares::evaluate: the residuals at x and, where `jacobian` is not null, their Jacobian.
  bool evaluate(const double* x, double* residuals, double* jacobian) const {
    const int n = static_cast<int>(scales_.size());
    const int m = num_residuals();
    std::vector<double> centre;
    if (!evaluate_at(x, centre)) return false;
    std::copy(centre.begin(), centre.end(), residuals);
    if (jacobian == nullptr) return true;
    // Columns j: residuals at x +- h e_j (h in scaled units: the variable's step). Where one side leaves the
    // region where the merit can be computed, the other side and the centre make a one-sided difference.
    const double h = 1.0 / kScalePerStep;
    std::vector<std::vector<double>> plus(static_cast<std::size_t>(n)), minus(static_cast<std::size_t>(n));
    std::vector<char> plus_ok(static_cast<std::size_t>(n)), minus_ok(static_cast<std::size_t>(n));
#pragma omp parallel for schedule(dynamic) num_threads(threads_)
    for (int k = 0; k < 2 * n; ++k) {
      const int j = k / 2;
      std::vector<double> shifted(x, x + n);
      shifted[static_cast<std::size_t>(j)] += (k % 2 == 0 ? h : -h);
      auto& out = k % 2 == 0 ? plus[static_cast<std::size_t>(j)] : minus[static_cast<std::size_t>(j)];
      auto& ok = k % 2 == 0 ? plus_ok[static_cast<std::size_t>(j)] : minus_ok[static_cast<std::size_t>(j)];
      ok = evaluate_at(shifted.data(), out) ? 1 : 0;
    }
    double* J = jacobian;
    for (int j = 0; j < n; ++j) {
      const auto u = static_cast<std::size_t>(j);
      for (int i = 0; i < m; ++i) {
        const auto r = static_cast<std::size_t>(i);
        double d = 0.0;
        if (plus_ok[u] && minus_ok[u]) {
          d = (plus[u][r] - minus[u][r]) / (2.0 * h);
        } else if (plus_ok[u]) {
          d = (plus[u][r] - centre[r]) / h;
        } else if (minus_ok[u]) {
          d = (centre[r] - minus[u][r]) / h;
        } else {
          return false;
        }
        J[i * n + j] = d;
      }
    }
    return true;
  }

 private:
  const Prescription& lens_;
  const MeritFunction& merit_;
  std::vector<double> scales_;
  int residuals_;
  int threads_;
  std::atomic<std::size_t>& evaluations_;
};

// The solvers' iterations as OptimizeProgress; `merit_per_cost`: 2 for the least-squares solver (its
// cost is half the sum of squares), 1 for the line search.
SolverProgress progress_of(const OptimizeOptions& options, const std::string& stage, double merit_per_cost) {
  if (!options.progress) return {};
  return [&options, stage, merit_per_cost](const SolverIteration& i) {
    OptimizeProgress p;
    p.iteration = i.iteration;
    p.merit = merit_per_cost * i.cost;
    p.step_norm = i.step_norm;
    p.step_accepted = i.step_accepted;
    p.stage = stage;
    options.progress(p);
  };
}

// The merit itself (the sum of squares) and its gradient 2 J^T r over the variables not held at a bound, for
// the line-search minimiser. Damped least squares (Gauss-Newton's J^T J) knows nothing of the residuals'
// own curvature, which is all there is where the optimum leaves residuals that cannot vanish: a singlet's
// spherical aberration is smallest at the best form, where dS_I/dX = 0 and J^T J is singular along the
// bending, so Levenberg-Marquardt crawls there. BFGS builds that curvature from successive gradients.
class MeritGradient final {
 public:
  MeritGradient(const MeritCost& cost, std::vector<double> x, std::vector<int> free, std::vector<double> lower, std::vector<double> upper)
      : cost_(cost), x_(std::move(x)), free_(std::move(free)), lower_(std::move(lower)), upper_(std::move(upper)) {}

  // The full scaled vector with the free variables from `parameters`.
  std::vector<double> full(const double* parameters) const {
    std::vector<double> x = x_;
    for (std::size_t k = 0; k < free_.size(); ++k) x[static_cast<std::size_t>(free_[k])] = parameters[k];
    return x;
  }

  // LineSearchMinimisation::evaluate over the free variables.
  bool evaluate(const double* parameters, double* merit, double* gradient) const {
    const std::vector<double> x = full(parameters);
    // Outside a bound the evaluation fails: the line search then shortens its step.
    for (std::size_t j = 0; j < x.size(); ++j) {
      if (x[j] < lower_[j] || x[j] > upper_[j]) return false;
    }
    const auto m = static_cast<std::size_t>(cost_.num_residuals());
    const std::size_t n = x.size();
    std::vector<double> r(m), J(gradient != nullptr ? m * n : 0);
    if (!cost_.evaluate(x.data(), r.data(), gradient != nullptr ? J.data() : nullptr)) return false;
    double sum = 0.0;
    for (double v : r) sum += v * v;
    *merit = sum;
    if (gradient != nullptr) {
      for (std::size_t k = 0; k < free_.size(); ++k) {
        double g = 0.0;
        for (std::size_t i = 0; i < m; ++i) g += 2.0 * r[i] * J[i * n + static_cast<std::size_t>(free_[k])];
        gradient[k] = g;
      }
    }
    return true;
  }

 private:
  const MeritCost& cost_;
  std::vector<double> x_;
  std::vector<int> free_;
  std::vector<double> lower_, upper_;
};

struct StageResult {
  Prescription lens;
  int iterations = 0;
  std::string termination;
};

// One Levenberg-Marquardt run over `merit`'s variables from `lens`.
StageResult run_stage(const Prescription& lens, const MeritFunction& merit, const OptimizeOptions& options, const std::string& stage,
                      std::atomic<std::size_t>& evaluations) {
  const double length = characteristic_length_mm(lens);
  const std::size_t n = merit.variables.size();
  std::vector<double> scales(n), x(n);
  for (std::size_t j = 0; j < n; ++j) {
    scales[j] = step_of(merit.variables[j], length) * kScalePerStep;
    x[j] = merit.variables[j].value(lens) / scales[j];
  }
  const MeritEvaluation start = evaluate_merit(lens, merit);
  ++evaluations;
  if (!start.ok()) {
    for (std::size_t i = 0; i < start.operands.size(); ++i) {
      if (!start.operands[i].failure.empty()) {
        throw ComputationError("the merit function cannot be evaluated on the " + std::string(stage == "optimise" ? "starting" : "substituted") +
                               " lens: operands[" + std::to_string(i) + "] (" + merit.operands[i].label() + "): " + start.operands[i].failure);
      }
    }
  }
  const int threads = options.threads > 0 ? options.threads : omp_get_max_threads();
  const MeritCost cost(lens, merit, scales, static_cast<int>(start.residuals.size()), threads, evaluations);
  // Levenberg-Marquardt within the variables' bounds, then BFGS on the merit over the variables it left
  // off their bounds (MeritGradient says why).
  std::vector<double> lower(n, -std::numeric_limits<double>::infinity()), upper(n, std::numeric_limits<double>::infinity());
  for (std::size_t j = 0; j < n; ++j) {
    const DesignVariable& v = merit.variables[j];
    if (v.min) lower[j] = *v.min / scales[j];
    if (v.max) upper[j] = *v.max / scales[j];
  }
  SolverLimits limits;
  limits.max_iterations = options.max_iterations;
  limits.function_tolerance = options.merit_tolerance;
  limits.gradient_tolerance = 1e-14;
  limits.parameter_tolerance = 1e-12;
  BoundedLeastSquares problem;
  problem.residuals = cost.num_residuals();
  problem.evaluate = [&cost](const double* at, double* residuals, double* jacobian) { return cost.evaluate(at, residuals, jacobian); };
  problem.lower = lower;
  problem.upper = upper;
  problem.limits = limits;
  problem.progress = progress_of(options, stage, 2.0);
  const SolverReport summary = solve_bounded_least_squares(problem, x);
  StageResult out{cost.lens_at(x.data()), summary.iterations - 1, summary.message};

  std::vector<int> free;
  for (std::size_t j = 0; j < n; ++j) {
    if (!on_bound(merit.variables[j], x[j] * scales[j])) free.push_back(static_cast<int>(j));
  }
  if (!free.empty()) {
    const MeritGradient gradient(cost, x, free, lower, upper);
    std::vector<double> p;
    for (int j : free) p.push_back(x[static_cast<std::size_t>(j)]);
    LineSearchMinimisation polish_problem;
    polish_problem.evaluate = [&gradient](const double* at, double* value, double* g) { return gradient.evaluate(at, value, g); };
    polish_problem.limits = limits;
    polish_problem.progress = progress_of(options, stage + ", BFGS", 1.0);
    const SolverReport polish = minimise_bfgs(polish_problem, p);
    const std::vector<double> polished = gradient.full(p.data());
    out.lens = cost.lens_at(polished.data());
    out.iterations += polish.iterations - 1;
    out.termination += " Then BFGS: " + polish.message;
  }
  return out;
}

std::string fixed_text(double v, int significant) { return std::isfinite(v) ? format_rounded(v, significant) : "-"; }

}  // namespace

void OptimizeOptions::validate() const {
  if (max_iterations < 1 || max_iterations > 10000) throw OptionsError("OptimizeOptions::max_iterations = " + std::to_string(max_iterations) + ": must be 1 to 10000");
  if (!(merit_tolerance > 0.0 && merit_tolerance < 1.0)) throw OptionsError("OptimizeOptions::merit_tolerance must be in (0, 1)");
  if (threads < 0) throw OptionsError("OptimizeOptions::threads must be >= 0");
}

const Glass& nearest_catalogue_glass(double nd, double vd) {
  struct Candidate {
    double nd, vd;
    const Glass* glass;
  };
  static const std::vector<Candidate> candidates = [] {
    std::vector<Candidate> list;
    for (const Glass& g : GlassCatalog::builtin().glasses()) {
      if (g.status() == Glass::Status::Obsolete || g.status() == Glass::Status::Special) continue;
      const double gvd = g.vd();
      if (!std::isfinite(gvd) || g.is_air()) continue;
      list.push_back({g.nd(), gvd, &g});
    }
    return list;
  }();
  // One glass-map distance: 0.01 in nd counts as 1 in Vd (OptimizeOptions::substitute_glass).
  const Candidate* best = nullptr;
  double best_distance = std::numeric_limits<double>::infinity();
  for (const Candidate& c : candidates) {
    const double d = std::hypot((c.nd - nd) / 0.01, c.vd - vd);
    if (d < best_distance) {
      best_distance = d;
      best = &c;
    }
  }
  if (best == nullptr) throw ComputationError("no catalogue glass to substitute");
  return *best->glass;
}

OptimizeResult optimize(const Prescription& lens, const MeritFunction& merit, const OptimizeOptions& options) {
  options.validate();
  merit.validate(lens);
  lens.validate();
  OptimizeResult result;
  result.start = lens;
  result.merit_function = merit;
  for (const DesignVariable& v : merit.variables) result.start_values.push_back(v.value(lens));
  std::atomic<std::size_t> evaluations{0};
  result.before = evaluate_merit(lens, merit);
  Prescription solved = lens;
  if (merit.efl_solve) merit.efl_solve->apply(solved);
  StageResult stage = run_stage(solved, merit, options, "optimise", evaluations);
  result.iterations = stage.iterations;
  result.termination = stage.termination;
  Prescription current = stage.lens;

  bool has_glass = false;
  for (const DesignVariable& v : merit.variables) has_glass = has_glass || is_glass(v);
  if (options.substitute_glass && has_glass) {
    std::vector<int> done;
    for (const DesignVariable& v : merit.variables) {
      if (!is_glass(v) || std::find(done.begin(), done.end(), v.surface) != done.end()) continue;
      done.push_back(v.surface);
      Surface& s = current.surfaces.at(static_cast<std::size_t>(v.surface - 1));
      SubstitutedGlass sub;
      sub.surface = v.surface;
      sub.model_nd = s.medium.nd();
      sub.model_vd = s.medium.vd();
      const Glass& glass = nearest_catalogue_glass(sub.model_nd, sub.model_vd);
      s.material = MaterialSpec::catalog(glass.name(), glass.vendor());
      s.medium = glass;
      sub.glass = glass.vendor() + " " + glass.name();
      sub.nd = glass.nd();
      sub.vd = glass.vd();
      result.substitutions.push_back(sub);
    }
    MeritFunction rest = merit;
    rest.variables.clear();
    for (const DesignVariable& v : merit.variables) {
      if (!is_glass(v)) rest.variables.push_back(v);
    }
    if (!rest.variables.empty()) {
      StageResult polish = run_stage(current, rest, options, "polish after glass substitution", evaluations);
      current = polish.lens;
      result.iterations += polish.iterations;
      result.termination += "; after glass substitution: " + polish.termination;
    }
  }
  result.result = current;
  result.after = evaluate_merit(current, merit);
  for (const DesignVariable& v : merit.variables) {
    const double value = v.value(current);
    result.result_values.push_back(value);
    result.at_bound.push_back(on_bound(v, value));
  }
  result.evaluations = evaluations + 1;
  return result;
}

std::string OptimizeResult::to_string() const {
  std::ostringstream os;
  char line[256];
  os << "Optimised: " << start.name << "\n\n";
  std::snprintf(line, sizeof line, "%-46s %16s %16s\n", "variable", "start", "result");
  os << line;
  for (std::size_t j = 0; j < merit_function.variables.size(); ++j) {
    const DesignVariable& v = merit_function.variables[j];
    const std::string name = v.name() + (v.unit().empty() ? "" : " (" + v.unit() + ")");
    std::snprintf(line, sizeof line, "%-46s %16s %16s%s\n", name.c_str(), fixed_text(start_values[j], 8).c_str(),
                  fixed_text(result_values[j], 8).c_str(), at_bound[j] ? "  at its bound" : "");
    os << line;
  }
  if (merit_function.efl_solve) {
    const int k = merit_function.efl_solve->surface;
    const std::string name = "curvature of surface " + std::to_string(k) + " (1/mm)";
    std::snprintf(line, sizeof line, "%-46s %16s %16s  solved for EFL %s mm\n", name.c_str(),
                  fixed_text(start.surfaces.at(static_cast<std::size_t>(k - 1)).curvature_per_mm, 8).c_str(),
                  fixed_text(result.surfaces.at(static_cast<std::size_t>(k - 1)).curvature_per_mm, 8).c_str(),
                  format_number(merit_function.efl_solve->efl_mm).c_str());
    os << line;
  }
  os << "\n";
  std::snprintf(line, sizeof line, "%-44s %12s %8s %13s %13s %12s %12s\n", "operand", "goal", "weight", "start", "result", "start merit",
                "result merit");
  os << line;
  for (std::size_t i = 0; i < merit_function.operands.size(); ++i) {
    const Operand& o = merit_function.operands[i];
    const std::string name = o.label() + (o.unit().empty() ? "" : " (" + o.unit() + ")");
    std::snprintf(line, sizeof line, "%-44s %12s %8s %13s %13s %12s %12s\n", name.c_str(), o.goal().c_str(), format_rounded(o.weight, 4).c_str(),
                  fixed_text(before.operands[i].value, 7).c_str(), fixed_text(after.operands[i].value, 7).c_str(),
                  fixed_text(before.operands[i].contribution, 4).c_str(), fixed_text(after.operands[i].contribution, 4).c_str());
    os << line;
  }
  os << "\nmerit " << fixed_text(before.merit, 6) << " -> " << fixed_text(after.merit, 6) << " in " << iterations << " iterations, " << evaluations
     << " evaluations (" << termination << ")\n";
  for (const SubstitutedGlass& s : substitutions) {
    std::snprintf(line, sizeof line, "glass after surface %d: model nd %.4f Vd %.2f -> %s (nd %.5f, Vd %.2f)\n", s.surface, s.model_nd, s.model_vd,
                  s.glass.c_str(), s.nd, s.vd);
    os << line;
  }
  return os.str();
}

}  // namespace lensmith
