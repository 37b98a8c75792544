// Rotation-invariant polynomial maps: pools, evaluation (per point, with Jacobian, blocked) and fits.
#include "lensmith/polyfit/rotational_map.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "map_fit.h"
#include "lensmith/core/errors.h"

namespace lensmith {
namespace {

constexpr std::size_t kBlock = 32;  // rays per block of the batch path
constexpr int kInvariants = 4;      // u, v, w, lambda

struct Invariants {
  double u, v, w, lambda;
};
Invariants invariants_of(const PolyPoint& p) {
  return {p[0] * p[0] + p[1] * p[1], p[0] * p[2] + p[1] * p[3], p[2] * p[2] + p[3] * p[3], p[4]};
}

using InvariantPowers = std::array<std::array<double, kMaxPolyDegree + 1>, kInvariants>;
void fill_powers(const Invariants& q, const std::array<int, kInvariants>& max_exponent, InvariantPowers& pw) {
  const std::array<double, kInvariants> base{q.u, q.v, q.w, q.lambda};
  for (int i = 0; i < kInvariants; ++i) {
    pw[i][0] = 1.0;
    for (int e = 1; e <= max_exponent[i]; ++e) pw[i][e] = pw[i][e - 1] * base[i];
  }
}

std::vector<InvariantTerm> invariant_terms(int max_degree, bool vector) {
  if (max_degree < 0 || max_degree > kMaxPolyDegree) {
    throw OptionsError("invariant term pool: max_degree = " + std::to_string(max_degree) + ": must be in 0.." +
                       std::to_string(kMaxPolyDegree));
  }
  std::vector<InvariantTerm> pool;
  for (int degree = 0; degree <= max_degree; ++degree) {
    for (int s = 0; 2 * s <= degree; ++s) {
      const int lambda = degree - 2 * s - (vector ? 1 : 0);
      if (lambda < 0) continue;
      for (int a = s; a >= 0; --a) {
        for (int b = s - a; b >= 0; --b) {
          const int c = s - a - b;
          InvariantTerm t;
          t.exponents = {static_cast<std::uint8_t>(a), static_cast<std::uint8_t>(b), static_cast<std::uint8_t>(c),
                         static_cast<std::uint8_t>(lambda)};
          if (vector) {
            t.factor = RayFactor::kPosition;
            pool.push_back(t);
            t.factor = RayFactor::kDirection;
          }
          pool.push_back(t);
        }
      }
    }
  }
  return pool;
}

// Invariant powers of every input, for the fit's columns: pw[(i * 4 + k) * (D + 1) + e].
class InvariantTable {
 public:
  InvariantTable(const std::vector<PolyPoint>& inputs, std::size_t count, int max_degree)
      : stride_(static_cast<std::size_t>(max_degree) + 1), values_(count * kInvariants * stride_) {
    for (std::size_t i = 0; i < count; ++i) {
      const Invariants q = invariants_of(inputs[i]);
      const std::array<double, kInvariants> base{q.u, q.v, q.w, q.lambda};
      for (int k = 0; k < kInvariants; ++k) {
        double* row = &values_[(i * kInvariants + static_cast<std::size_t>(k)) * stride_];
        row[0] = 1.0;
        for (std::size_t e = 1; e < stride_; ++e) row[e] = row[e - 1] * base[static_cast<std::size_t>(k)];
      }
    }
  }
  double monomial(std::size_t i, const InvariantTerm& t) const {
    const double* p = &values_[i * kInvariants * stride_];
    return p[t.exponents[0]] * p[stride_ + t.exponents[1]] * p[2 * stride_ + t.exponents[2]] *
           p[3 * stride_ + t.exponents[3]];
  }

 private:
  std::size_t stride_;
  std::vector<double> values_;
};

// Value of a basis function at row r: vector maps have two rows per input (its x, then its y).
double basis_value(const InvariantTable& table, const std::vector<PolyPoint>& inputs, bool vector, std::size_t row,
                   const InvariantTerm& t) {
  if (!vector) return table.monomial(row, t);
  const std::size_t i = row / 2;
  const std::size_t axis = row % 2;
  const double factor = t.factor == RayFactor::kPosition ? inputs[i][axis] : inputs[i][2 + axis];
  return table.monomial(i, t) * factor;
}

RotationalFitResult fit_rows(const std::vector<PolyPoint>& inputs, bool vector,
                             const std::vector<std::vector<double>>& targets, const std::vector<InvariantTerm>& pool,
                             const FitOptions& options) {
  options.validate();
  const std::size_t rows_per_input = vector ? 2 : 1;
  polyfit_detail::check_map_data("fit_rotational_map", inputs, rows_per_input, targets);
  std::vector<InvariantTerm> usable;
  for (const InvariantTerm& t : pool) {
    if (t.total_degree() > options.max_degree) continue;
    if ((t.factor == RayFactor::kOne) == vector) {
      throw FitError("fit_rotational_map: term " + t.to_string() + " does not belong in a " +
                     (vector ? "vector" : "scalar") + " map");
    }
    usable.push_back(t);
  }
  if (usable.empty()) throw FitError("fit_rotational_map: no pool term within the maximum degree");
  int degree = 0;
  for (const InvariantTerm& t : usable) degree = std::max(degree, t.total_degree());
  const InvariantTable table(inputs, inputs.size(), degree);
  return polyfit_detail::fit_map_rows<RotationalFitResult>(
      inputs, rows_per_input, targets, usable, options,
      [&](std::size_t row, const InvariantTerm& t) { return basis_value(table, inputs, vector, row, t); },
      [](std::vector<InvariantTerm> terms, int outputs, std::vector<double> coefficients) {
        return RotationalMap(std::move(terms), outputs, std::move(coefficients));
      });
}

}  // namespace

int InvariantTerm::total_degree() const {
  const int s = exponents[0] + exponents[1] + exponents[2];
  return 2 * s + exponents[3] + (factor == RayFactor::kOne ? 0 : 1);
}

std::string InvariantTerm::to_string() const {
  static constexpr std::array<const char*, 4> kNames{"u", "v", "w", "lambda"};
  std::string s;
  for (int i = 0; i < 4; ++i) {
    if (exponents[i] == 0) continue;
    if (!s.empty()) s += '*';
    s += kNames[i];
    if (exponents[i] > 1) s += '^' + std::to_string(exponents[i]);
  }
  if (factor != RayFactor::kOne) {
    if (!s.empty()) s += '*';
    s += factor == RayFactor::kPosition ? "p" : "d";
  }
  return s.empty() ? "1" : s;
}

std::vector<InvariantTerm> vector_invariant_terms(int max_degree) { return invariant_terms(max_degree, true); }
std::vector<InvariantTerm> scalar_invariant_terms(int max_degree) { return invariant_terms(max_degree, false); }

RotationalMap::RotationalMap(std::vector<InvariantTerm> terms, int outputs, std::vector<double> coefficients)
    : terms_(std::move(terms)), coefficients_(std::move(coefficients)), outputs_(outputs) {
  if (outputs_ < 1 || outputs_ > kMaxMapOutputs) {
    throw FitError("RotationalMap: " + std::to_string(outputs_) + " outputs: must be in 1.." +
                   std::to_string(kMaxMapOutputs));
  }
  if (coefficients_.size() != terms_.size() * static_cast<std::size_t>(outputs_)) {
    throw FitError("RotationalMap: " + std::to_string(terms_.size()) + " terms x " + std::to_string(outputs_) +
                   " outputs need as many coefficients, got " + std::to_string(coefficients_.size()));
  }
  std::vector<InvariantTerm> sorted = terms_;
  std::sort(sorted.begin(), sorted.end());
  if (const auto dup = std::adjacent_find(sorted.begin(), sorted.end()); dup != sorted.end()) {
    throw FitError("RotationalMap: the term " + dup->to_string() + " is listed twice");
  }
  vector_ = !terms_.empty() && terms_.front().factor != RayFactor::kOne;
  for (const InvariantTerm& t : terms_) {
    if ((t.factor != RayFactor::kOne) != vector_) {
      throw FitError("RotationalMap: vector terms (times p or d) and scalar terms cannot share a map");
    }
    if (t.total_degree() > kMaxPolyDegree) {
      throw FitError("RotationalMap: term " + t.to_string() + " has total degree " + std::to_string(t.total_degree()) +
                     ": must be <= " + std::to_string(kMaxPolyDegree));
    }
    degree_ = std::max(degree_, t.total_degree());
    for (int i = 0; i < kInvariants; ++i) max_exponent_[i] = std::max<int>(max_exponent_[i], t.exponents[i]);
  }
  for (const RayFactor pass : {RayFactor::kPosition, RayFactor::kDirection, RayFactor::kOne}) {
    for (std::size_t t = 0; t < terms_.size(); ++t) {
      if (terms_[t].factor != pass) continue;
      std::array<std::uint32_t, 4> offsets{};
      for (int i = 0; i < kInvariants; ++i) {
        offsets[static_cast<std::size_t>(i)] =
            static_cast<std::uint32_t>((i * (kMaxPolyDegree + 1) + terms_[t].exponents[static_cast<std::size_t>(i)]) * kBlock);
      }
      batch_offsets_.push_back(offsets);
      for (int k = 0; k < outputs_; ++k) batch_coefficients_.push_back(coefficient(t, k));
    }
    if (pass == RayFactor::kPosition) batch_position_terms_ = batch_offsets_.size();
  }
}

void RotationalMap::evaluate(const PolyPoint& v, std::span<double> out) const {
  InvariantPowers pw;
  fill_powers(invariants_of(v), max_exponent_, pw);
  std::array<double, kMaxMapOutputs> a{}, b{};
  const double* c = coefficients_.data();
  for (const InvariantTerm& t : terms_) {
    const auto& e = t.exponents;
    const double m = pw[0][e[0]] * pw[1][e[1]] * pw[2][e[2]] * pw[3][e[3]];
    double* acc = t.factor == RayFactor::kDirection ? b.data() : a.data();
    for (int k = 0; k < outputs_; ++k) acc[k] += c[k] * m;
    c += outputs_;
  }
  if (!vector_) {
    for (int k = 0; k < outputs_; ++k) out[k] = a[k];
    return;
  }
  for (int k = 0; k < outputs_; ++k) {
    out[2 * k] = a[k] * v[0] + b[k] * v[2];
    out[2 * k + 1] = a[k] * v[1] + b[k] * v[3];
  }
}

std::array<double, 2> RotationalMap::evaluate_output(const PolyPoint& v, int k) const {
  InvariantPowers pw;
  fill_powers(invariants_of(v), max_exponent_, pw);
  double a = 0.0, b = 0.0;
  for (std::size_t i = 0; i < terms_.size(); ++i) {
    const auto& e = terms_[i].exponents;
    const double m = coefficient(i, k) * (pw[0][e[0]] * pw[1][e[1]] * pw[2][e[2]] * pw[3][e[3]]);
    (terms_[i].factor == RayFactor::kDirection ? b : a) += m;
  }
  return {a * v[0] + b * v[2], a * v[1] + b * v[3]};
}

void RotationalMap::evaluate_with_jacobian(const PolyPoint& v, int k, std::array<double, 2>& value,
                                           std::array<double, 8>& jacobian) const {
  const Invariants q = invariants_of(v);
  InvariantPowers pw;
  fill_powers(q, max_exponent_, pw);
  // A, B and their derivatives in u, v, w.
  double a = 0.0, b = 0.0;
  std::array<double, 3> da{}, db{};
  for (std::size_t i = 0; i < terms_.size(); ++i) {
    const double c = coefficient(i, k);
    if (c == 0.0) continue;
    const auto& e = terms_[i].exponents;
    const std::array<double, 4> f{pw[0][e[0]], pw[1][e[1]], pw[2][e[2]], pw[3][e[3]]};
    const bool is_b = terms_[i].factor == RayFactor::kDirection;
    (is_b ? b : a) += c * f[0] * f[1] * f[2] * f[3];
    auto& d = is_b ? db : da;
    for (int j = 0; j < 3; ++j) {
      if (e[j] == 0) continue;
      double g = c * e[j] * pw[j][e[j] - 1] * f[3];
      for (int l = 0; l < 3; ++l) {
        if (l != j) g *= f[l];
      }
      d[j] += g;
    }
  }
  const double x = v[0], y = v[1], dx = v[2], dy = v[3];
  // d(u, v, w) / d(x, y, dx, dy).
  const std::array<std::array<double, 4>, 3> dq{{{2 * x, 2 * y, 0.0, 0.0}, {dx, dy, x, y}, {0.0, 0.0, 2 * dx, 2 * dy}}};
  value = {a * x + b * dx, a * y + b * dy};
  for (int i = 0; i < 4; ++i) {
    const double ga = da[0] * dq[0][i] + da[1] * dq[1][i] + da[2] * dq[2][i];
    const double gb = db[0] * dq[0][i] + db[1] * dq[1][i] + db[2] * dq[2][i];
    jacobian[i] = ga * x + gb * dx + (i == 0 ? a : 0.0) + (i == 2 ? b : 0.0);
    jacobian[4 + i] = ga * y + gb * dy + (i == 1 ? a : 0.0) + (i == 3 ? b : 0.0);
  }
}

namespace {

// Accumulates the block's A and B (or scalar) sums. Two outputs (the ray maps) take a register-
// blocked path: 16 rays at a time, the four sums in registers, each monomial used as soon as it is
// formed; other maps form each monomial once and add it to every output.
void accumulate(const double* pw, const std::array<std::uint32_t, 4>* offsets, const double* coefficients,
                std::size_t first_terms, std::size_t all_terms, int outputs, bool vector, double (*acc)[kBlock]) {
  constexpr std::size_t kSub = 16;
  if (vector && outputs == 2) {
    // Sum of the terms [from, to) into x, y (16 rays each), kept in registers.
    const auto sum = [&](std::size_t s, std::size_t from, std::size_t to, double* __restrict x, double* __restrict y) {
      double u[kSub] = {}, v[kSub] = {};
      for (std::size_t t = from; t < to; ++t) {
        const auto& o = offsets[t];
        const double* p0 = pw + o[0] + s;
        const double* p1 = pw + o[1] + s;
        const double* p2 = pw + o[2] + s;
        const double* p3 = pw + o[3] + s;
        const double c0 = coefficients[2 * t], c1 = coefficients[2 * t + 1];
        for (std::size_t r = 0; r < kSub; ++r) {
          const double m = p0[r] * p1[r] * p2[r] * p3[r];
          u[r] += c0 * m;
          v[r] += c1 * m;
        }
      }
      for (std::size_t r = 0; r < kSub; ++r) {
        x[r] = u[r];
        y[r] = v[r];
      }
    };
    for (std::size_t s = 0; s < kBlock; s += kSub) {
      sum(s, 0, first_terms, acc[0] + s, acc[1] + s);
      sum(s, first_terms, all_terms, acc[2] + s, acc[3] + s);
    }
    return;
  }
  const int accumulators = vector ? 2 * outputs : outputs;
  for (int k = 0; k < accumulators; ++k) std::fill(acc[k], acc[k] + kBlock, 0.0);
  alignas(64) double m[kBlock];
  for (std::size_t t = 0; t < all_terms; ++t) {
    const auto& o = offsets[t];
    for (std::size_t r = 0; r < kBlock; ++r) m[r] = pw[o[0] + r] * pw[o[1] + r] * pw[o[2] + r] * pw[o[3] + r];
    const int offset = vector && t >= first_terms ? outputs : 0;
    for (int k = 0; k < outputs; ++k) {
      const double ck = coefficients[t * static_cast<std::size_t>(outputs) + static_cast<std::size_t>(k)];
      double* a = acc[offset + k];
      for (std::size_t r = 0; r < kBlock; ++r) a[r] += ck * m[r];
    }
  }
}

// The whole batch: per block, the invariants and their powers, the sums, and out = A p + B d. With
// GCC on x86-64 it is built twice, for AVX2+FMA (x86-64-v3) and the baseline, and chosen at load time,
// as the splat buffer's inner loop is.
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
__attribute__((target_clones("arch=x86-64-v3", "default")))
#endif
void evaluate_blocks(const std::array<const double*, kPolyVariables>& in, double* const* out, std::size_t count,
                     const std::array<double, kPolyVariables>& scale, const std::array<double, kPolyVariables>& offset,
                     const std::array<int, 4>& max_exponent, const std::array<std::uint32_t, 4>* offsets,
                     const double* coefficients, std::size_t first_terms, std::size_t all_terms, int outputs,
                     bool vector) {
  alignas(64) double pw[kInvariants][kMaxPolyDegree + 1][kBlock];
  alignas(64) double acc[2 * kMaxMapOutputs][kBlock];  // A_k, then B_k (vector maps)
  alignas(64) double p[kPolyVariables][kBlock];
  for (std::size_t start = 0; start < count; start += kBlock) {
    const std::size_t n = std::min(kBlock, count - start);
    for (int i = 0; i < kPolyVariables; ++i) {
      const double* src = in[static_cast<std::size_t>(i)] + start;
      const double a = scale[static_cast<std::size_t>(i)], b = offset[static_cast<std::size_t>(i)];
      for (std::size_t r = 0; r < n; ++r) p[i][r] = src[r] * a + b;
      for (std::size_t r = n; r < kBlock; ++r) p[i][r] = 0.0;
    }
    for (std::size_t r = 0; r < kBlock; ++r) {
      pw[0][1][r] = p[0][r] * p[0][r] + p[1][r] * p[1][r];
      pw[1][1][r] = p[0][r] * p[2][r] + p[1][r] * p[3][r];
      pw[2][1][r] = p[2][r] * p[2][r] + p[3][r] * p[3][r];
      pw[3][1][r] = p[4][r];
    }
    for (int i = 0; i < kInvariants; ++i) {
      for (std::size_t r = 0; r < kBlock; ++r) pw[i][0][r] = 1.0;
      for (int e = 2; e <= max_exponent[static_cast<std::size_t>(i)]; ++e) {
        for (std::size_t r = 0; r < kBlock; ++r) pw[i][e][r] = pw[i][e - 1][r] * pw[i][1][r];
      }
    }
    accumulate(&pw[0][0][0], offsets, coefficients, first_terms, all_terms, outputs, vector, acc);
    if (!vector) {
      for (int k = 0; k < outputs; ++k) std::copy(acc[k], acc[k] + n, out[k] + start);
      continue;
    }
    for (int k = 0; k < outputs; ++k) {
      const double* a = acc[k];
      const double* b = acc[outputs + k];
      double* ox = out[2 * k] + start;
      double* oy = out[2 * k + 1] + start;
      for (std::size_t r = 0; r < n; ++r) {
        ox[r] = a[r] * p[0][r] + b[r] * p[2][r];
        oy[r] = a[r] * p[1][r] + b[r] * p[3][r];
      }
    }
  }
}

}  // namespace

void RotationalMap::evaluate_batch(const std::array<const double*, kPolyVariables>& in, std::span<double* const> out,
                                   std::size_t count, const std::array<double, kPolyVariables>& scale,
                                   const std::array<double, kPolyVariables>& offset) const {
  evaluate_blocks(in, out.data(), count, scale, offset, max_exponent_, batch_offsets_.data(), batch_coefficients_.data(),
                  vector_ ? batch_position_terms_ : batch_offsets_.size(), batch_offsets_.size(), outputs_, vector_);
}

std::string RotationalMap::to_string() const {
  std::ostringstream os;
  os << "RotationalMap{" << (vector_ ? "vector" : "scalar") << ", outputs=" << outputs_ << ", terms=" << terms_.size()
     << ", degree=" << degree_ << "}";
  return os.str();
}

RotationalFitResult fit_rotational_map(const std::vector<PolyPoint>& inputs,
                                       const std::vector<std::vector<std::array<double, 2>>>& targets,
                                       const std::vector<InvariantTerm>& pool, const FitOptions& options) {
  return fit_rows(inputs, true, polyfit_detail::target_rows(targets), pool, options);
}

RotationalFitResult fit_rotational_scalar_map(const std::vector<PolyPoint>& inputs,
                                              const std::vector<std::vector<double>>& targets,
                                              const std::vector<InvariantTerm>& pool, const FitOptions& options) {
  return fit_rows(inputs, false, targets, pool, options);
}

}  // namespace lensmith
