// Greedy term selection by order-recursive matching pursuit, then the coefficients by a column-pivoting
// QR (Eigen), or under a robust loss by Ceres (through lensmith/solve).
// Selection: with Q an orthonormal basis of the chosen columns and r = t - Q Q^T t the least-squares
// residual, adding column a_j lowers |r|^2 by <r, a_j>^2 / |a_j - Q Q^T a_j|^2 (r is orthogonal to
// Q). The denominators are updated by one dot product per step, so a step costs O(pool * samples).
#include "lensmith/polyfit/polynomial_fit.h"

#include "least_squares.h"
#include "lensmith/solve/ceres_solvers.h"
#include "power_table.h"

#include <Eigen/QR>

#include <algorithm>
#include <cmath>
#include <memory>
#include <sstream>
#include <string>

namespace lensmith {
namespace {

// A column whose part outside the span of the chosen ones is below 1e-5 of its norm is numerically
// dependent on them: choosing it would only make the coefficient solve ill-conditioned.
constexpr double kDependentColumn = 1e-10;


// Candidate column values select_columns keeps in memory (256 MiB of doubles).
constexpr std::size_t kCachedColumnValues = std::size_t{32} << 20;

double dot(const std::vector<double>& a, const std::vector<double>& b) {
  double s = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) s += a[i] * b[i];
  return s;
}

// Greedy selection for one or several targets sharing the chosen terms (simultaneous orthogonal
// matching pursuit: Tropp, Gilbert & Strauss 2006). A candidate's gain is the sum over targets of the
// fraction of that target's remaining squared residual it would remove, so outputs in different units
// (mm, direction cosines) count alike. Returns indices into pool in selection order and, per target,
// the least-squares RMS after each step. Candidates are scored in parallel; the choice does not
// depend on the thread count (ties go to the earlier, lower-degree term).
}  // namespace

std::vector<std::size_t> select_columns(std::size_t p, const ColumnFunction& column_of,
                                        const std::vector<std::vector<double>>& targets, const FitOptions& options,
                                        std::vector<std::vector<double>>& selection_rms) {
  const std::size_t n = targets.front().size();
  const std::size_t outputs = targets.size();
  // Candidate columns are kept when they fit in kCachedColumnValues doubles (formed once, not once per
  // step: an anamorphic fit's 420 candidates took 10 s a map to re-form); else formed when scored.
  const bool cached = p * n <= kCachedColumnValues;
  std::vector<double> cache(cached ? p * n : 0);
  std::vector<double> norm2(p), outside2(p), gain(p);
  // corr[j * outputs + k] = <column j, residual k>, updated as the residuals lose each chosen direction
  // (r_k -= <q, r_k> q changes it by -<q, r_k> <column j, q>): one dot per candidate and step, whatever
  // the number of outputs.
  std::vector<double> corr(p * outputs);
  std::vector<char> candidate(p);
#pragma omp parallel
  {
    std::vector<double> column(n);
#pragma omp for schedule(static)
    for (std::size_t j = 0; j < p; ++j) {
      column_of(j, column);
      if (cached) std::copy(column.begin(), column.end(), cache.begin() + static_cast<std::ptrdiff_t>(j * n));
      norm2[j] = outside2[j] = dot(column, column);
      candidate[j] = norm2[j] > 0.0;
      for (std::size_t k = 0; k < outputs; ++k) corr[j * outputs + k] = dot(column, targets[k]);
    }
  }
  std::vector<std::vector<double>> r = targets;
  std::vector<double> target_norm(outputs);
  for (std::size_t k = 0; k < outputs; ++k) target_norm[k] = std::sqrt(dot(targets[k], targets[k]));
  selection_rms.assign(outputs, {});
  std::vector<std::vector<double>> basis;
  std::vector<std::size_t> chosen;
  std::vector<double> weight(outputs);
  std::vector<double> last_projection(outputs);  // <q, r_k> of the last chosen direction q, before r_k lost it
  while (chosen.size() < static_cast<std::size_t>(options.max_terms)) {
    bool explained = true;
    for (std::size_t k = 0; k < outputs; ++k) {
      const double rn2 = dot(r[k], r[k]);
      const bool done = std::sqrt(rn2) <= options.relative_residual_tolerance * target_norm[k];
      weight[k] = done ? 0.0 : 1.0 / rn2;
      explained = explained && done;
    }
    if (explained) break;
#pragma omp parallel
    {
      std::vector<double> formed(cached ? 0 : n);
#pragma omp for schedule(dynamic, 4)
      for (std::size_t j = 0; j < p; ++j) {
        gain[j] = 0.0;
        if (!candidate[j]) continue;
        double* cj = &corr[j * outputs];
        if (!basis.empty()) {
          const double* column = cached ? &cache[j * n] : formed.data();
          if (!cached) column_of(j, formed);
          const std::vector<double>& q = basis.back();
          double c = 0.0;
          for (std::size_t i = 0; i < n; ++i) c += column[i] * q[i];
          outside2[j] -= c * c;
          for (std::size_t k = 0; k < outputs; ++k) cj[k] -= last_projection[k] * c;
          if (outside2[j] <= kDependentColumn * norm2[j]) {
            candidate[j] = false;
            continue;
          }
        }
        double g = 0.0;
        for (std::size_t k = 0; k < outputs; ++k) g += weight[k] * cj[k] * cj[k];
        gain[j] = g / outside2[j];
      }
    }
    std::size_t best = p;
    double best_gain = 0.0;
    for (std::size_t j = 0; j < p; ++j) {
      if (candidate[j] && gain[j] > best_gain) {  // strict: ties go to the earlier (lower-degree) term
        best_gain = gain[j];
        best = j;
      }
    }
    if (best == p) break;  // no remaining column lowers the residual
    // Orthogonalise the chosen column twice against the basis (Gram-Schmidt, then once more for
    // the rounding of the first pass: "twice is enough", Giraud et al. 2005).
    std::vector<double> q(n);
    if (cached) {
      std::copy(cache.begin() + static_cast<std::ptrdiff_t>(best * n), cache.begin() + static_cast<std::ptrdiff_t>((best + 1) * n), q.begin());
    } else {
      column_of(best, q);
    }
    for (int pass = 0; pass < 2; ++pass) {
      for (const auto& b : basis) {
        const double c = dot(q, b);
        for (std::size_t i = 0; i < n; ++i) q[i] -= c * b[i];
      }
    }
    const double qn = std::sqrt(dot(q, q));
    for (double& v : q) v /= qn;
    for (std::size_t k = 0; k < outputs; ++k) {
      const double cr = dot(q, r[k]);
      last_projection[k] = cr;
      for (std::size_t i = 0; i < n; ++i) r[k][i] -= cr * q[i];
      selection_rms[k].push_back(std::sqrt(dot(r[k], r[k]) / static_cast<double>(n)));
    }
    basis.push_back(std::move(q));
    candidate[best] = false;
    chosen.push_back(best);
  }
  return chosen;
}

std::vector<std::vector<double>> solve_least_squares(const std::vector<double>& design, int num_terms,
                                                     const std::vector<std::vector<double>>& targets) {
  const auto n = static_cast<Eigen::Index>(num_terms);
  const auto rows = static_cast<Eigen::Index>(design.size()) / std::max<Eigen::Index>(n, 1);
  const Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> a(design.data(), rows, n);
  Eigen::MatrixXd b(rows, static_cast<Eigen::Index>(targets.size()));
  for (std::size_t o = 0; o < targets.size(); ++o) {
    if (static_cast<Eigen::Index>(targets[o].size()) != rows) throw FitError("solve_least_squares: one target per design row needed");
    b.col(static_cast<Eigen::Index>(o)) = Eigen::Map<const Eigen::VectorXd>(targets[o].data(), rows);
  }
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(a);
  const Eigen::MatrixXd c = qr.solve(b);
  if (!c.allFinite()) throw FitError("solve_least_squares: the solution is not finite");
  std::vector<std::vector<double>> out(targets.size(), std::vector<double>(static_cast<std::size_t>(n)));
  for (std::size_t o = 0; o < targets.size(); ++o) {
    for (Eigen::Index j = 0; j < n; ++j) out[o][static_cast<std::size_t>(j)] = c(j, static_cast<Eigen::Index>(o));
  }
  return out;
}

int solve_coefficients(const std::vector<double>& design, const std::vector<double>& targets, int num_terms,
                       std::optional<double> huber_scale, std::vector<double>& coefficients) {
  if (!huber_scale) {
    coefficients = solve_least_squares(design, num_terms, {targets}).front();
    return 1;
  }
  // The first step is the exact least-squares solution; later steps only move by rounding, which these
  // tolerances recognise (tighter ones made Ceres repeat QR factorisations for nothing).
  SolverLimits limits;
  limits.function_tolerance = 1e-12;
  limits.parameter_tolerance = 1e-12;
  limits.gradient_tolerance = 1e-20;
  limits.max_iterations = 100;
  const SolverReport report = solve_huber_linear(design, targets, *huber_scale, limits, coefficients);
  // On an ill-conditioned design (high-degree terms, nearly dependent columns) the first step already
  // holds the least-squares solution and later steps can only fail on rounding: Ceres then reports
  // FAILURE after its run of invalid steps but keeps the best parameters, which are usable when the
  // cost fell.
  const bool fell = std::isfinite(report.final_cost) && report.final_cost < report.initial_cost;
  if (!report.usable && !(report.failed && fell)) throw FitError("fit_polynomial: Ceres failed: " + report.brief);
  return report.iterations;
}

void FitOptions::validate() const {
  if (max_degree < 1 || max_degree > kMaxPolyDegree) {
    throw OptionsError("FitOptions::max_degree = " + std::to_string(max_degree) + ": must be in 1.." +
                       std::to_string(kMaxPolyDegree));
  }
  if (max_terms < 1) throw OptionsError("FitOptions::max_terms = " + std::to_string(max_terms) + ": must be >= 1");
  if (max_selection_samples < 0) {
    throw OptionsError("FitOptions::max_selection_samples = " + std::to_string(max_selection_samples) + ": must be >= 0");
  }
  if (!(relative_residual_tolerance >= 0.0 && relative_residual_tolerance < 1.0)) {
    throw OptionsError("FitOptions::relative_residual_tolerance = " + std::to_string(relative_residual_tolerance) +
                       ": must be in [0, 1)");
  }
  if (huber_scale && !(*huber_scale > 0.0 && std::isfinite(*huber_scale))) {
    throw OptionsError("FitOptions::huber_scale = " + std::to_string(*huber_scale) + ": must be finite and > 0");
  }
}

std::string FitResult::to_string() const {
  std::ostringstream os;
  os << "FitResult{terms=" << polynomial.size() << ", degree=" << polynomial.degree() << ", train_rms=" << train_rms
     << ", train_max_abs=" << train_max_abs << ", solver_iterations=" << solver_iterations
     << ", polynomial=" << polynomial.to_string() << "}";
  return os.str();
}

FitResult fit_polynomial(const std::vector<PolyPoint>& inputs, const std::vector<double>& targets,
                         const std::vector<Monomial>& pool, const FitOptions& options) {
  options.validate();
  if (inputs.empty() || inputs.size() != targets.size()) {
    throw FitError("fit_polynomial: " + std::to_string(inputs.size()) + " inputs and " +
                   std::to_string(targets.size()) + " targets: need the same non-zero number");
  }
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    bool finite = std::isfinite(targets[i]);
    for (const double v : inputs[i]) finite = finite && std::isfinite(v);
    if (!finite) throw FitError("fit_polynomial: sample " + std::to_string(i) + " is not finite");
  }
  std::vector<Monomial> usable;
  for (const Monomial& m : pool) {
    if (m.total_degree() <= options.max_degree) usable.push_back(m);
  }
  if (usable.empty()) {
    throw FitError("fit_polynomial: no pool term has total degree <= FitOptions::max_degree = " +
                   std::to_string(options.max_degree));
  }
  {
    std::vector<Monomial> sorted = usable;
    std::sort(sorted.begin(), sorted.end());
    const auto dup = std::adjacent_find(sorted.begin(), sorted.end());
    if (dup != sorted.end()) throw FitError("fit_polynomial: the pool holds " + dup->to_string() + " twice");
  }
  int degree = 0;
  for (const Monomial& m : usable) degree = std::max(degree, m.total_degree());
  const polyfit_detail::SamplePowers powers(inputs, degree);

  FitResult result;
  std::vector<Monomial> terms;
  if (usable.size() <= static_cast<std::size_t>(options.max_terms)) {
    terms = usable;
  } else {
    const std::size_t m = options.max_selection_samples > 0
                              ? std::min(inputs.size(), static_cast<std::size_t>(options.max_selection_samples))
                              : inputs.size();
    const std::vector<PolyPoint> subset(inputs.begin(), inputs.begin() + static_cast<std::ptrdiff_t>(m));
    const polyfit_detail::SamplePowers subset_powers(subset, degree);
    std::vector<std::vector<double>> selection_rms;
    const auto chosen = select_columns(
        usable.size(), [&](std::size_t j, std::vector<double>& c) { subset_powers.column(usable[j], c); },
        {std::vector<double>(targets.begin(), targets.begin() + static_cast<std::ptrdiff_t>(m))}, options,
        selection_rms);
    for (const std::size_t j : chosen) terms.push_back(usable[j]);
    result.selection_rms = std::move(selection_rms.front());
  }

  const std::size_t k = terms.size();
  std::vector<double> coefficients(k, 0.0);
  if (k > 0) {
    std::vector<double> design(inputs.size() * k);
    for (std::size_t i = 0; i < inputs.size(); ++i) {
      for (std::size_t j = 0; j < k; ++j) design[i * k + j] = powers.monomial(i, terms[j]);
    }
    result.solver_iterations = solve_coefficients(design, targets, static_cast<int>(k), std::nullopt, coefficients);
    if (options.huber_scale) {
      // Start the robust solve at the least-squares optimum, where Huber's weights are meaningful.
      result.solver_iterations += solve_coefficients(design, targets, static_cast<int>(k), options.huber_scale, coefficients);
    }
  }
  result.polynomial = SparsePolynomial(std::move(terms), std::move(coefficients));
  double sum2 = 0.0;
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    const double e = result.polynomial.evaluate(inputs[i]) - targets[i];
    sum2 += e * e;
    result.train_max_abs = std::max(result.train_max_abs, std::abs(e));
  }
  result.train_rms = std::sqrt(sum2 / static_cast<double>(inputs.size()));
  return result;
}

}  // namespace lensmith
