// Polynomials for a lens that is not rotationally symmetric but is symmetric under the mirrors of its two
// sections (x -> -x and y -> -y): an anamorphic lens of cylinders, toroids and biconics on one axis.
//
// Why not the invariant form (rotational_map.h): without rotational symmetry x^3 and x y^2 are no longer
// tied, nor the x output to the y output, so A p + B d cannot describe such a lens (its x section has
// another focal length). Each component of each output is then its own sparse polynomial in the ray's
// monomials x^a y^b dx^c dy^d lambda^e, and the two mirrors still remove every monomial whose
// coefficient must vanish: an x component changes sign under x -> -x and not under y -> -y, so it holds
// only monomials odd in (x, dx) and even in (y, dy); a y component the reverse; a scalar only even ones
// (term_pool.h, OutputParity; the parity rules of Hullin, Hanika & Heidrich 2012, sec. 4.1). The
// selection chooses the terms of both components together (a term is a monomial for one component),
// so a budget buys what the map needs in x and in y.
#pragma once

#include <array>
#include <cstdint>
#include <ostream>
#include <span>
#include <string>
#include <vector>

#include "lensmith/polyfit/polynomial.h"
#include "lensmith/polyfit/polynomial_fit.h"
#include "lensmith/polyfit/rotational_map.h"

namespace lensmith {

// Which value of an output a term adds to: the x or y component of a vector output, or a scalar output.
enum class MapComponent : std::uint8_t { kX = 0, kY = 1, kScalar = 2 };

struct ComponentTerm {
  Monomial monomial;
  MapComponent component = MapComponent::kScalar;

  int total_degree() const { return monomial.total_degree(); }
  std::string to_string() const;  // "x^2*dy->y", "lambda->x", "1" (a scalar's constant)
  friend std::ostream& operator<<(std::ostream& os, const ComponentTerm& t) { return os << t.to_string(); }
  friend bool operator==(const ComponentTerm&, const ComponentTerm&) = default;
  friend auto operator<=>(const ComponentTerm&, const ComponentTerm&) = default;
};

// Candidates up to a total degree for a lens symmetric under both section mirrors: vector maps take the
// monomials odd in x for x components and odd in y for y components, scalar maps the even ones.
// Graded order. Throws OptionsError unless 0 <= max_degree <= kMaxPolyDegree.
std::vector<ComponentTerm> vector_component_terms(int max_degree);
std::vector<ComponentTerm> scalar_component_terms(int max_degree);

class ComponentMap {
 public:
  ComponentMap() = default;
  // coefficients[t * outputs + k]. A vector map has only kX / kY terms and each output is a 2-vector; a
  // scalar map only kScalar terms. Throws FitError for mixed or repeated terms, mismatched sizes, outputs
  // outside 1..kMaxMapOutputs or a degree above kMaxPolyDegree.
  ComponentMap(std::vector<ComponentTerm> terms, int outputs, std::vector<double> coefficients);

  bool is_vector() const { return vector_; }
  int outputs() const { return outputs_; }
  std::size_t size() const { return terms_.size(); }
  int degree() const { return degree_; }
  const std::vector<ComponentTerm>& terms() const { return terms_; }
  const std::vector<double>& coefficients() const { return coefficients_; }
  double coefficient(std::size_t term, int output) const { return coefficients_[term * outputs_ + output]; }

  // As RotationalMap's: v = (x, y, dx, dy, lambda); a vector map writes out[2k], out[2k + 1] = output
  // k's (x, y), a scalar map out[k]. Sizes are not checked (hot path).
  void evaluate(const PolyPoint& v, std::span<double> out) const;
  std::array<double, 2> evaluate_output(const PolyPoint& v, int k) const;
  // Vector maps: output k's (x, y) and d(x, y) / d(x, y, dx, dy), row-major 2 x 4.
  void evaluate_with_jacobian(const PolyPoint& v, int k, std::array<double, 2>& value, std::array<double, 8>& jacobian) const;
  // Batch, structure of arrays, inputs normalised on the fly (v_i = in_i * scale_i + offset_i), as
  // RotationalMap::evaluate_batch. Allocation-free.
  void evaluate_batch(const std::array<const double*, kPolyVariables>& in, std::span<double* const> out, std::size_t count,
                      const std::array<double, kPolyVariables>& scale = {1, 1, 1, 1, 1},
                      const std::array<double, kPolyVariables>& offset = {}) const;

  std::string to_string() const;  // "ComponentMap{vector, outputs=2, terms=120, degree=7}"
  friend std::ostream& operator<<(std::ostream& os, const ComponentMap& m) { return os << m.to_string(); }
  friend bool operator==(const ComponentMap& a, const ComponentMap& b) {
    return a.terms_ == b.terms_ && a.coefficients_ == b.coefficients_ && a.outputs_ == b.outputs_;
  }

 private:
  std::vector<ComponentTerm> terms_;
  std::vector<double> coefficients_;
  int outputs_ = 0;
  bool vector_ = false;
  int degree_ = 0;
  std::array<int, kPolyVariables> max_exponent_{};
};

struct ComponentFitResult {
  ComponentMap map;
  std::vector<double> train_rms;  // per output, as RotationalFitResult's
  int solver_iterations = 0;
};

// Fits a vector map (targets[k][i] = output k's (x, y) for input i) or a scalar map from a pool of
// vector_component_terms or scalar_component_terms: the terms chosen greedily for all outputs together,
// each ray giving two rows (its x and its y component), then every output's coefficients by one rank-revealing QR.
ComponentFitResult fit_component_map(const std::vector<PolyPoint>& inputs,
                                     const std::vector<std::vector<std::array<double, 2>>>& targets,
                                     const std::vector<ComponentTerm>& pool, const FitOptions& options);
ComponentFitResult fit_component_scalar_map(const std::vector<PolyPoint>& inputs, const std::vector<std::vector<double>>& targets,
                                            const std::vector<ComponentTerm>& pool, const FitOptions& options);

}  // namespace lensmith
