// The powers of the polynomial variables, the one home of the tables every polynomial form evaluates
// from: PointPowers for one point (evaluation, Jacobians) and SamplePowers for every sample of a fit
// (its columns). Private to lib/polyfit.
#pragma once

#include <array>
#include <cstddef>
#include <vector>

#include "lensmith/polyfit/polynomial.h"

namespace lensmith::polyfit_detail {

// table[k][e] = v[k]^e.
using PointPowers = std::array<std::array<double, kMaxPolyDegree + 1>, kPolyVariables>;

// table[k][e] = v[k]^e for e = 0..max_exponent[k], by repeated multiplication (exact for e <= 2).
inline void fill_powers(const PolyPoint& v, const std::array<int, kPolyVariables>& max_exponent, PointPowers& table) {
  for (int k = 0; k < kPolyVariables; ++k) {
    auto& row = table[k];
    row[0] = 1.0;
    for (int e = 1; e <= max_exponent[k]; ++e) row[e] = row[e - 1] * v[k];
  }
}

// Powers of every variable of every sample: values[(i * 5 + k) * (D + 1) + e] = inputs[i][k]^e.
class SamplePowers {
 public:
  SamplePowers(const std::vector<PolyPoint>& inputs, int max_degree)
      : stride_(max_degree + 1), values_(inputs.size() * kPolyVariables * static_cast<std::size_t>(stride_)) {
    for (std::size_t i = 0; i < inputs.size(); ++i) {
      for (int k = 0; k < kPolyVariables; ++k) {
        double* row = &values_[(i * kPolyVariables + k) * stride_];
        row[0] = 1.0;
        for (int e = 1; e < stride_; ++e) row[e] = row[e - 1] * inputs[i][k];
      }
    }
  }
  double monomial(std::size_t i, const Monomial& m) const {
    const double* p = &values_[i * kPolyVariables * stride_];
    return p[m.exponents[0]] * p[stride_ + m.exponents[1]] * p[2 * stride_ + m.exponents[2]] *
           p[3 * stride_ + m.exponents[3]] * p[4 * stride_ + m.exponents[4]];
  }
  void column(const Monomial& m, std::vector<double>& out) const {
    for (std::size_t i = 0; i < out.size(); ++i) out[i] = monomial(i, m);
  }

 private:
  int stride_;
  std::vector<double> values_;
};

}  // namespace lensmith::polyfit_detail
