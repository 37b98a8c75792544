// A sparse polynomial in the five ray variables of polynomial optics (Hullin, Hanika & Heidrich
// 2012, sec. 3): position (x, y), direction (dx, dy) and wavelength lambda. The polynomial is
// unit-agnostic: callers choose (and document) the units and normalisation of the variables.
#pragma once

#include <array>
#include <cstdint>
#include <ostream>
#include <span>
#include <string>
#include <vector>

#include "lensmith/core/errors.h"

namespace lensmith {

// A fit could not be made or a polynomial is malformed (sizes differ, degree too high, no samples).
class FitError : public Error {
 public:
  using Error::Error;
};

// Index of each ray variable in the 5-vectors of this library.
enum class PolyVariable : int { kX = 0, kY = 1, kDx = 2, kDy = 3, kLambda = 4 };
inline constexpr int kPolyVariables = 5;
// Highest total degree a SparsePolynomial may hold; bounds the per-call power table on the stack.
inline constexpr int kMaxPolyDegree = 11;

using PolyPoint = std::array<double, kPolyVariables>;

// x^e0 y^e1 dx^e2 dy^e3 lambda^e4.
struct Monomial {
  std::array<std::uint8_t, kPolyVariables> exponents{};

  int total_degree() const;
  // Sum of the exponents of the four geometric variables (x, y, dx, dy); lambda excluded.
  int geometric_degree() const;
  // "1", "x", "x^2*dy*lambda", ...
  std::string to_string() const;
  friend bool operator==(const Monomial&, const Monomial&) = default;
  friend auto operator<=>(const Monomial&, const Monomial&) = default;
  friend std::ostream& operator<<(std::ostream& os, const Monomial& m) { return os << m.to_string(); }
};

// sum_i coefficients[i] * terms[i](v). Evaluation precomputes the powers of each variable once per
// point (on the stack) and then takes a dot product: no allocation per call.
class SparsePolynomial {
 public:
  SparsePolynomial() = default;
  // Throws FitError when the sizes differ or a term's total degree exceeds kMaxPolyDegree.
  SparsePolynomial(std::vector<Monomial> terms, std::vector<double> coefficients);

  const std::vector<Monomial>& terms() const { return terms_; }
  const std::vector<double>& coefficients() const { return coefficients_; }
  std::size_t size() const { return terms_.size(); }
  // Highest total degree of any term (0 for an empty polynomial).
  int degree() const { return degree_; }

  double evaluate(const PolyPoint& v) const;
  // out[i] = evaluate(points[i]); throws FitError when the spans differ in size.
  void evaluate(std::span<const PolyPoint> points, std::span<double> out) const;
  // d p / d v_k for k = 0..4 at v.
  void gradient(const PolyPoint& v, std::array<double, kPolyVariables>& out) const;
  // Value and gradient in one pass; returns the value.
  double evaluate_with_gradient(const PolyPoint& v, std::array<double, kPolyVariables>& gradient_out) const;

  // "+1.5*x^2*dy -0.25*lambda", shortest round-trip digits; "0" when empty.
  std::string to_string() const;
  friend std::ostream& operator<<(std::ostream& os, const SparsePolynomial& p) { return os << p.to_string(); }

 private:
  std::vector<Monomial> terms_;
  std::vector<double> coefficients_;
  std::array<int, kPolyVariables> max_exponent_{};  // highest power of each variable any term needs
  int degree_ = 0;
};

}  // namespace lensmith
