// Polynomials for a rotationally symmetric lens written in the rotation invariants of the ray.
//
// Why: a lens symmetric under every rotation about z and every mirror containing z maps the ray
// (p, d) = ((x, y), (dx, dy)) to outputs that turn with it. Every such vector output is
//     out = A(u, v, w, lambda) p + B(u, v, w, lambda) d,   u = |p|^2, v = p.d, w = |d|^2,
// and every scalar output (a transmittance) is C(u, v, w, lambda) (the first fundamental theorem of
// invariant theory for the orthogonal group O(2); Weyl, The Classical Groups, 1939, ch. II). This is
// the form third-order aberration theory writes its sums in (Welford, Aberrations of Optical Systems,
// sec. 7.2, with the same three invariants). Fitting A, B and C instead of the monomials of x, y,
// dx, dy ties together what the symmetry ties (x^3 and x y^2, x and y outputs), so a term budget
// buys more accuracy, the y output costs nothing extra, and one term is cheaper to evaluate.
//
// A term is an invariant monomial u^a v^b w^c lambda^e times p, d (vector maps) or 1 (scalar maps).
// Its total degree in (x, y, dx, dy, lambda) is 2 (a + b + c) + 1 + e (vector) or 2 (a + b + c) + e.
#pragma once

#include <array>
#include <cstdint>
#include <ostream>
#include <span>
#include <string>
#include <vector>

#include "lensmith/polyfit/polynomial.h"
#include "lensmith/polyfit/polynomial_fit.h"

namespace lensmith {

// Outputs one map may have: bounds the per-block accumulators on the stack.
inline constexpr int kMaxMapOutputs = 16;

enum class RayFactor : std::uint8_t { kPosition = 0, kDirection = 1, kOne = 2 };

struct InvariantTerm {
  std::array<std::uint8_t, 4> exponents{};  // u, v, w, lambda
  RayFactor factor = RayFactor::kOne;

  int total_degree() const;  // in (x, y, dx, dy, lambda)
  std::string to_string() const;  // "u^2*lambda*p", "v*d", "1"
  friend std::ostream& operator<<(std::ostream& os, const InvariantTerm& t) { return os << t.to_string(); }
  friend bool operator==(const InvariantTerm&, const InvariantTerm&) = default;
  friend auto operator<=>(const InvariantTerm&, const InvariantTerm&) = default;
};

// Candidates up to a total degree: vector maps take every invariant monomial times p and times d,
// scalar maps every invariant monomial. Graded order. Throws OptionsError unless 0 <= degree <= 11.
std::vector<InvariantTerm> vector_invariant_terms(int max_degree);
std::vector<InvariantTerm> scalar_invariant_terms(int max_degree);

class RotationalMap {
 public:
  RotationalMap() = default;
  // coefficients[t * outputs + k]. A vector map has only kPosition / kDirection terms and each
  // output is a 2-vector; a scalar map only kOne terms. Throws FitError for mixed or repeated terms,
  // mismatched sizes, outputs outside 1..kMaxMapOutputs or a degree above kMaxPolyDegree.
  RotationalMap(std::vector<InvariantTerm> terms, int outputs, std::vector<double> coefficients);

  bool is_vector() const { return vector_; }
  int outputs() const { return outputs_; }
  std::size_t size() const { return terms_.size(); }
  int degree() const { return degree_; }
  const std::vector<InvariantTerm>& terms() const { return terms_; }
  const std::vector<double>& coefficients() const { return coefficients_; }
  double coefficient(std::size_t term, int output) const { return coefficients_[term * outputs_ + output]; }

  // v = (x, y, dx, dy, lambda). Vector map: out[2k], out[2k + 1] = output k's (x, y), out.size() =
  // 2 outputs(); scalar map: out[k], out.size() = outputs(). Sizes are not checked (hot path).
  void evaluate(const PolyPoint& v, std::span<double> out) const;
  // Vector maps: output k's (x, y) alone.
  std::array<double, 2> evaluate_output(const PolyPoint& v, int k) const;
  // Vector maps: output k's (x, y) and its Jacobian d(x, y) / d(x, y, dx, dy), row-major 2 x 4.
  void evaluate_with_jacobian(const PolyPoint& v, int k, std::array<double, 2>& value,
                              std::array<double, 8>& jacobian) const;
  // Batch, structure of arrays: in[i] holds `count` values of variable i; out has one pointer per
  // output value (2 per vector output, as in evaluate()). Blocks of rays together, vectorisable,
  // allocation-free.
  // `scale` and `offset`, when given, normalise the inputs on the fly: v_i = in_i * scale_i + offset_i.
  void evaluate_batch(const std::array<const double*, kPolyVariables>& in, std::span<double* const> out,
                      std::size_t count, const std::array<double, kPolyVariables>& scale = {1, 1, 1, 1, 1},
                      const std::array<double, kPolyVariables>& offset = {}) const;

  std::string to_string() const;  // "RotationalMap{vector, outputs=2, terms=40, degree=7}"
  friend std::ostream& operator<<(std::ostream& os, const RotationalMap& m) { return os << m.to_string(); }
  friend bool operator==(const RotationalMap&, const RotationalMap&) = default;

 private:
  std::vector<InvariantTerm> terms_;
  std::vector<double> coefficients_;
  int outputs_ = 0;
  bool vector_ = false;
  int degree_ = 0;
  std::array<int, 4> max_exponent_{};
  // The batch path's view of the terms: p terms first, then d terms (scalar maps: all), each as the
  // offsets of its four power rows in the block's power table, with its coefficients in that order.
  std::vector<std::array<std::uint32_t, 4>> batch_offsets_;
  std::vector<double> batch_coefficients_;
  std::size_t batch_position_terms_ = 0;
};

struct RotationalFitResult {
  RotationalMap map;
  std::vector<double> train_rms;  // per output: RMS length of the error vector (vector maps) or |error|
  int solver_iterations = 0;
};

// Fits a vector map: targets[k][i] is output k's (x, y) for input i; inputs as in evaluate(). The
// terms are chosen greedily for all outputs together from `pool` (vector_invariant_terms), each ray
// giving two rows (its x and its y component), then every output's coefficients by one rank-revealing QR.
RotationalFitResult fit_rotational_map(const std::vector<PolyPoint>& inputs,
                                       const std::vector<std::vector<std::array<double, 2>>>& targets,
                                       const std::vector<InvariantTerm>& pool, const FitOptions& options);
// Fits a scalar map from scalar_invariant_terms.
RotationalFitResult fit_rotational_scalar_map(const std::vector<PolyPoint>& inputs,
                                              const std::vector<std::vector<double>>& targets,
                                              const std::vector<InvariantTerm>& pool, const FitOptions& options);

}  // namespace lensmith
