// One map of a lens fit in whichever form the lens's symmetry calls for: the invariant form of a
// rotationally symmetric lens (rotational_map.h) or the component form of a lens symmetric only under
// its two section mirrors (component_map.h). LensFit and the ray model call the map through this one
// interface, so the form is decided once, when the lens is fitted or its fit file read.
#pragma once

#include <array>
#include <span>
#include <string>
#include <variant>

#include "lensmith/polyfit/component_map.h"
#include "lensmith/polyfit/rotational_map.h"

namespace lensmith {

class FittedMap {
 public:
  FittedMap() = default;
  FittedMap(RotationalMap map) : map_(std::move(map)) {}  // NOLINT(google-explicit-constructor): a form of the map
  FittedMap(ComponentMap map) : map_(std::move(map)) {}   // NOLINT(google-explicit-constructor)

  bool is_rotational() const { return std::holds_alternative<RotationalMap>(map_); }
  // The form held; throw std::bad_variant_access for the other.
  const RotationalMap& rotational() const { return std::get<RotationalMap>(map_); }
  const ComponentMap& component() const { return std::get<ComponentMap>(map_); }

  bool is_vector() const { return std::visit([](const auto& m) { return m.is_vector(); }, map_); }
  int outputs() const { return std::visit([](const auto& m) { return m.outputs(); }, map_); }
  std::size_t size() const { return std::visit([](const auto& m) { return m.size(); }, map_); }  // terms
  int degree() const { return std::visit([](const auto& m) { return m.degree(); }, map_); }

  // As RotationalMap's (and ComponentMap's) evaluation.
  void evaluate(const PolyPoint& v, std::span<double> out) const {
    std::visit([&](const auto& m) { m.evaluate(v, out); }, map_);
  }
  std::array<double, 2> evaluate_output(const PolyPoint& v, int k) const {
    return std::visit([&](const auto& m) { return m.evaluate_output(v, k); }, map_);
  }
  void evaluate_with_jacobian(const PolyPoint& v, int k, std::array<double, 2>& value, std::array<double, 8>& jacobian) const {
    std::visit([&](const auto& m) { m.evaluate_with_jacobian(v, k, value, jacobian); }, map_);
  }
  void evaluate_batch(const std::array<const double*, kPolyVariables>& in, std::span<double* const> out, std::size_t count,
                      const std::array<double, kPolyVariables>& scale = {1, 1, 1, 1, 1},
                      const std::array<double, kPolyVariables>& offset = {}) const {
    std::visit([&](const auto& m) { m.evaluate_batch(in, out, count, scale, offset); }, map_);
  }

  std::string to_string() const { return std::visit([](const auto& m) { return m.to_string(); }, map_); }
  friend std::ostream& operator<<(std::ostream& os, const FittedMap& m) { return os << m.to_string(); }
  friend bool operator==(const FittedMap&, const FittedMap&) = default;

 private:
  std::variant<RotationalMap, ComponentMap> map_;
};

}  // namespace lensmith
