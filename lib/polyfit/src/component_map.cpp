// Component maps (component_map.h): pools for a lens symmetric under its two section mirrors, evaluation
// (per point, with Jacobian, batch) and fits.
#include "lensmith/polyfit/component_map.h"

#include <algorithm>
#include <sstream>

#include "lensmith/core/errors.h"
#include "lensmith/polyfit/term_pool.h"
#include "map_fit.h"
#include "power_table.h"

namespace lensmith {
namespace {

using polyfit_detail::fill_powers;
using Powers = polyfit_detail::PointPowers;

double monomial_value(const Powers& pw, const Monomial& m) {
  const auto& e = m.exponents;
  return pw[0][e[0]] * pw[1][e[1]] * pw[2][e[2]] * pw[3][e[3]] * pw[4][e[4]];
}

std::vector<ComponentTerm> component_terms(int max_degree, bool vector) {
  std::vector<ComponentTerm> pool;
  // all_monomials validates the degree; graded order is kept by merging per monomial.
  for (const Monomial& m : all_monomials(max_degree)) {
    if (!vector) {
      if (allowed_by_symmetry(m, OutputParity::kEven)) pool.push_back({m, MapComponent::kScalar});
      continue;
    }
    if (allowed_by_symmetry(m, OutputParity::kOddInX)) pool.push_back({m, MapComponent::kX});
    if (allowed_by_symmetry(m, OutputParity::kOddInY)) pool.push_back({m, MapComponent::kY});
  }
  return pool;
}


ComponentFitResult fit_component_rows(const std::vector<PolyPoint>& inputs, bool vector,
                                      const std::vector<std::vector<double>>& targets, const std::vector<ComponentTerm>& pool,
                                      const FitOptions& options) {
  options.validate();
  const std::size_t rows_per_input = vector ? 2 : 1;
  polyfit_detail::check_map_data("fit_component_map", inputs, rows_per_input, targets);
  std::vector<ComponentTerm> usable;
  for (const ComponentTerm& t : pool) {
    if (t.total_degree() > options.max_degree) continue;
    if ((t.component == MapComponent::kScalar) == vector) {
      throw FitError("fit_component_map: term " + t.to_string() + " does not belong in a " + (vector ? "vector" : "scalar") +
                     " map");
    }
    usable.push_back(t);
  }
  if (usable.empty()) throw FitError("fit_component_map: no pool term within the maximum degree");
  int degree = 0;
  for (const ComponentTerm& t : usable) degree = std::max(degree, t.total_degree());
  const polyfit_detail::SamplePowers table(inputs, degree);
  // A component term is its monomial in the rows of its own component and zero in the other's.
  auto basis = [&](std::size_t row, const ComponentTerm& t) {
    if (!vector) return table.monomial(row, t.monomial);
    const auto axis = static_cast<MapComponent>(row % 2);
    return axis == t.component ? table.monomial(row / 2, t.monomial) : 0.0;
  };
  return polyfit_detail::fit_map_rows<ComponentFitResult>(
      inputs, rows_per_input, targets, usable, options, basis,
      [](std::vector<ComponentTerm> terms, int outputs, std::vector<double> coefficients) {
        return ComponentMap(std::move(terms), outputs, std::move(coefficients));
      });
}

}  // namespace

std::string ComponentTerm::to_string() const {
  static constexpr std::array<const char*, kPolyVariables> kNames{"x", "y", "dx", "dy", "lambda"};
  std::string s;
  for (std::size_t i = 0; i < kPolyVariables; ++i) {
    const int e = monomial.exponents[i];
    if (e == 0) continue;
    if (!s.empty()) s += '*';
    s += kNames[i];
    if (e > 1) {
      s.push_back('^');
      s.append(std::to_string(e));
    }
  }
  if (s.empty()) s.push_back('1');
  if (component != MapComponent::kScalar) s.append(component == MapComponent::kX ? "->x" : "->y");
  return s;
}

std::vector<ComponentTerm> vector_component_terms(int max_degree) { return component_terms(max_degree, true); }
std::vector<ComponentTerm> scalar_component_terms(int max_degree) { return component_terms(max_degree, false); }

ComponentMap::ComponentMap(std::vector<ComponentTerm> terms, int outputs, std::vector<double> coefficients)
    : terms_(std::move(terms)), coefficients_(std::move(coefficients)), outputs_(outputs) {
  if (outputs_ < 1 || outputs_ > kMaxMapOutputs) {
    throw FitError("ComponentMap: " + std::to_string(outputs_) + " outputs: must be in 1.." + std::to_string(kMaxMapOutputs));
  }
  if (coefficients_.size() != terms_.size() * static_cast<std::size_t>(outputs_)) {
    throw FitError("ComponentMap: " + std::to_string(terms_.size()) + " terms x " + std::to_string(outputs_) +
                   " outputs need as many coefficients, got " + std::to_string(coefficients_.size()));
  }
  std::vector<ComponentTerm> sorted = terms_;
  std::sort(sorted.begin(), sorted.end());
  if (const auto dup = std::adjacent_find(sorted.begin(), sorted.end()); dup != sorted.end()) {
    throw FitError("ComponentMap: the term " + dup->to_string() + " is listed twice");
  }
  vector_ = !terms_.empty() && terms_.front().component != MapComponent::kScalar;
  for (const ComponentTerm& t : terms_) {
    if ((t.component != MapComponent::kScalar) != vector_) {
      throw FitError("ComponentMap: vector terms (->x, ->y) and scalar terms cannot share a map");
    }
    if (t.total_degree() > kMaxPolyDegree) {
      throw FitError("ComponentMap: term " + t.to_string() + " has total degree " + std::to_string(t.total_degree()) +
                     ": must be <= " + std::to_string(kMaxPolyDegree));
    }
    degree_ = std::max(degree_, t.total_degree());
    for (std::size_t i = 0; i < kPolyVariables; ++i) max_exponent_[i] = std::max<int>(max_exponent_[i], t.monomial.exponents[i]);
  }
}

namespace {

// Every term's monomial times its coefficients into acc[component][output]: contiguous in the outputs,
// so the inner loop vectorises (a clipping map has a dozen outputs). Built for AVX2+FMA too and chosen at
// load time, as RotationalMap's batch path is.
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
__attribute__((target_clones("arch=x86-64-v3", "default")))
#endif
void accumulate_terms(const Powers& pw, const ComponentTerm* terms, std::size_t count, const double* coefficients, int outputs,
                      double (*acc)[kMaxMapOutputs]) {
  for (std::size_t t = 0; t < count; ++t) {
    const double m = monomial_value(pw, terms[t].monomial);
    double* a = acc[terms[t].component == MapComponent::kY ? 1 : 0];
    const double* c = coefficients + t * static_cast<std::size_t>(outputs);
    for (int k = 0; k < outputs; ++k) a[k] += c[k] * m;
  }
}

}  // namespace

void ComponentMap::evaluate(const PolyPoint& v, std::span<double> out) const {
  Powers pw;
  fill_powers(v, max_exponent_, pw);
  double acc[2][kMaxMapOutputs] = {};
  accumulate_terms(pw, terms_.data(), terms_.size(), coefficients_.data(), outputs_, acc);
  for (int k = 0; k < outputs_; ++k) {
    if (vector_) {
      out[2 * static_cast<std::size_t>(k)] = acc[0][k];
      out[2 * static_cast<std::size_t>(k) + 1] = acc[1][k];
    } else {
      out[static_cast<std::size_t>(k)] = acc[0][k];
    }
  }
}

std::array<double, 2> ComponentMap::evaluate_output(const PolyPoint& v, int k) const {
  Powers pw;
  fill_powers(v, max_exponent_, pw);
  std::array<double, 2> value{};
  for (std::size_t i = 0; i < terms_.size(); ++i) {
    const double c = coefficient(i, k);
    if (c == 0.0) continue;
    value[terms_[i].component == MapComponent::kY ? 1 : 0] += c * monomial_value(pw, terms_[i].monomial);
  }
  return value;
}

void ComponentMap::evaluate_with_jacobian(const PolyPoint& v, int k, std::array<double, 2>& value,
                                          std::array<double, 8>& jacobian) const {
  Powers pw;
  fill_powers(v, max_exponent_, pw);
  value = {0.0, 0.0};
  jacobian.fill(0.0);
  for (std::size_t i = 0; i < terms_.size(); ++i) {
    const double c = coefficient(i, k);
    if (c == 0.0) continue;
    const auto& e = terms_[i].monomial.exponents;
    const std::size_t row = terms_[i].component == MapComponent::kY ? 1 : 0;
    const std::array<double, kPolyVariables> f{pw[0][e[0]], pw[1][e[1]], pw[2][e[2]], pw[3][e[3]], pw[4][e[4]]};
    value[row] += c * (f[0] * f[1] * f[2] * f[3] * f[4]);  // as evaluate_output rounds it
    // d/d(x, y, dx, dy): the power rule in one variable, the others' factors unchanged.
    for (std::size_t j = 0; j < 4; ++j) {
      if (e[j] == 0) continue;
      double g = c * e[j] * pw[j][e[j] - 1] * f[4];
      for (std::size_t l = 0; l < 4; ++l) {
        if (l != j) g *= f[l];
      }
      jacobian[4 * row + j] += g;
    }
  }
}

void ComponentMap::evaluate_batch(const std::array<const double*, kPolyVariables>& in, std::span<double* const> out,
                                  std::size_t count, const std::array<double, kPolyVariables>& scale,
                                  const std::array<double, kPolyVariables>& offset) const {
  std::array<double, 2 * kMaxMapOutputs> value{};
  const std::size_t values = static_cast<std::size_t>(outputs_) * (vector_ ? 2 : 1);
  for (std::size_t r = 0; r < count; ++r) {
    PolyPoint v;
    for (std::size_t i = 0; i < kPolyVariables; ++i) v[i] = in[i][r] * scale[i] + offset[i];
    evaluate(v, value);
    for (std::size_t o = 0; o < values; ++o) out[o][r] = value[o];
  }
}

std::string ComponentMap::to_string() const {
  std::ostringstream os;
  os << "ComponentMap{" << (vector_ ? "vector" : "scalar") << ", outputs=" << outputs_ << ", terms=" << terms_.size()
     << ", degree=" << degree_ << "}";
  return os.str();
}

ComponentFitResult fit_component_map(const std::vector<PolyPoint>& inputs,
                                     const std::vector<std::vector<std::array<double, 2>>>& targets,
                                     const std::vector<ComponentTerm>& pool, const FitOptions& options) {
  return fit_component_rows(inputs, true, polyfit_detail::target_rows(targets), pool, options);
}

ComponentFitResult fit_component_scalar_map(const std::vector<PolyPoint>& inputs, const std::vector<std::vector<double>>& targets,
                                            const std::vector<ComponentTerm>& pool, const FitOptions& options) {
  return fit_component_rows(inputs, false, targets, pool, options);
}

}  // namespace lensmith
