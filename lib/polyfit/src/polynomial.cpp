// Sparse polynomial in (x, y, dx, dy, lambda): evaluation through a per-point power table.
#include "lensmith/polyfit/polynomial.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <string>

#include "power_table.h"

namespace lensmith {
namespace {

constexpr std::array<const char*, kPolyVariables> kVariableNames{"x", "y", "dx", "dy", "lambda"};

std::string shortest(double value) {
  std::array<char, 32> buffer{};
  const auto result = std::to_chars(buffer.data(), buffer.data() + buffer.size(), value);
  return std::string(buffer.data(), result.ptr);
}

}  // namespace

int Monomial::total_degree() const {
  int d = 0;
  for (const auto e : exponents) d += e;
  return d;
}

int Monomial::geometric_degree() const {
  return exponents[0] + exponents[1] + exponents[2] + exponents[3];
}

std::string Monomial::to_string() const {
  std::string s;
  for (int k = 0; k < kPolyVariables; ++k) {
    if (exponents[k] == 0) continue;
    if (!s.empty()) s += '*';
    s += kVariableNames[k];
    if (exponents[k] > 1) s += '^' + std::to_string(exponents[k]);
  }
  return s.empty() ? "1" : s;
}

SparsePolynomial::SparsePolynomial(std::vector<Monomial> terms, std::vector<double> coefficients)
    : terms_(std::move(terms)), coefficients_(std::move(coefficients)) {
  if (terms_.size() != coefficients_.size()) {
    throw FitError("SparsePolynomial: " + std::to_string(terms_.size()) + " terms but " +
                   std::to_string(coefficients_.size()) + " coefficients: the counts must match");
  }
  for (const Monomial& m : terms_) {
    if (m.total_degree() > kMaxPolyDegree) {
      throw FitError("SparsePolynomial: term " + m.to_string() + " has total degree " +
                     std::to_string(m.total_degree()) + ": must be <= " + std::to_string(kMaxPolyDegree));
    }
    degree_ = std::max(degree_, m.total_degree());
    for (int k = 0; k < kPolyVariables; ++k) max_exponent_[k] = std::max<int>(max_exponent_[k], m.exponents[k]);
  }
}

double SparsePolynomial::evaluate(const PolyPoint& v) const {
  polyfit_detail::PointPowers pw;
  polyfit_detail::fill_powers(v, max_exponent_, pw);
  double sum = 0.0;
  for (std::size_t i = 0; i < terms_.size(); ++i) {
    const auto& e = terms_[i].exponents;
    sum += coefficients_[i] * (pw[0][e[0]] * pw[1][e[1]] * pw[2][e[2]] * pw[3][e[3]] * pw[4][e[4]]);
  }
  return sum;
}

void SparsePolynomial::evaluate(std::span<const PolyPoint> points, std::span<double> out) const {
  if (points.size() != out.size()) {
    throw FitError("SparsePolynomial::evaluate: " + std::to_string(points.size()) + " points but " +
                   std::to_string(out.size()) + " outputs: the sizes must match");
  }
  for (std::size_t i = 0; i < points.size(); ++i) out[i] = evaluate(points[i]);
}

double SparsePolynomial::evaluate_with_gradient(const PolyPoint& v,
                                                std::array<double, kPolyVariables>& gradient_out) const {
  polyfit_detail::PointPowers pw;
  polyfit_detail::fill_powers(v, max_exponent_, pw);
  double sum = 0.0;
  gradient_out.fill(0.0);
  for (std::size_t i = 0; i < terms_.size(); ++i) {
    const auto& e = terms_[i].exponents;
    const double c = coefficients_[i];
    std::array<double, kPolyVariables> f{pw[0][e[0]], pw[1][e[1]], pw[2][e[2]], pw[3][e[3]], pw[4][e[4]]};
    sum += c * (f[0] * f[1] * f[2] * f[3] * f[4]);
    // d/dv_k v_k^e = e v_k^(e-1); the product of the other four factors is taken explicitly so
    // that a zero coordinate does not poison the derivative (no division by v_k).
    for (int k = 0; k < kPolyVariables; ++k) {
      if (e[k] == 0) continue;
      double others = c * e[k] * pw[k][e[k] - 1];
      for (int j = 0; j < kPolyVariables; ++j) {
        if (j != k) others *= f[j];
      }
      gradient_out[k] += others;
    }
  }
  return sum;
}

void SparsePolynomial::gradient(const PolyPoint& v, std::array<double, kPolyVariables>& out) const {
  evaluate_with_gradient(v, out);
}

std::string SparsePolynomial::to_string() const {
  if (terms_.empty()) return "0";
  std::string s;
  for (std::size_t i = 0; i < terms_.size(); ++i) {
    if (i > 0) s += ' ';
    const double c = coefficients_[i];
    s += (c < 0.0 || (c == 0.0 && std::signbit(c))) ? "" : "+";
    s += shortest(c);
    if (terms_[i].total_degree() > 0) s += '*' + terms_[i].to_string();
  }
  return s;
}

}  // namespace lensmith
