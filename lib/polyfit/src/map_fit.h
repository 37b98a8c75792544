// The fit of a ray map from rows, shared by the invariant form (rotational_map.cpp) and the component
// form (component_map.cpp): the data checked, the terms chosen greedily for all outputs together
// (select_columns), every output's coefficients by one rank-revealing QR, and the training RMS. A vector map has
// two rows per input (its x, then its y component); a scalar map one. Private to lib/polyfit.
#pragma once

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "least_squares.h"
#include "lensmith/polyfit/polynomial.h"
#include "lensmith/polyfit/rotational_map.h"

namespace lensmith::polyfit_detail {

// Checks what every fit needs (inputs, one target per row of every output, finite data); `what` names
// the fit in the message. Throws FitError.
inline void check_map_data(const char* what, const std::vector<PolyPoint>& inputs, std::size_t rows_per_input,
                           const std::vector<std::vector<double>>& targets) {
  const std::string name(what);
  if (inputs.empty()) throw FitError(name + ": no samples");
  if (targets.empty() || targets.size() > static_cast<std::size_t>(kMaxMapOutputs)) {
    throw FitError(name + ": " + std::to_string(targets.size()) + " outputs: need 1.." + std::to_string(kMaxMapOutputs));
  }
  for (const auto& t : targets) {
    if (t.size() != inputs.size() * rows_per_input) throw FitError(name + ": every output needs one target per input");
    for (const double v : t) {
      if (!std::isfinite(v)) throw FitError(name + ": a target is not finite");
    }
  }
  for (const PolyPoint& p : inputs) {
    for (const double v : p) {
      if (!std::isfinite(v)) throw FitError(name + ": an input is not finite");
    }
  }
}

// Vector targets ((x, y) per input) as rows: x, y of input 0, then of input 1, ...
inline std::vector<std::vector<double>> target_rows(const std::vector<std::vector<std::array<double, 2>>>& targets) {
  std::vector<std::vector<double>> rows;
  for (const auto& t : targets) {
    std::vector<double> r;
    r.reserve(2 * t.size());
    for (const auto& xy : t) {
      r.push_back(xy[0]);
      r.push_back(xy[1]);
    }
    rows.push_back(std::move(r));
  }
  return rows;
}

// Selects from `usable` (already checked against the map's kind and degree) and solves. `basis(row,
// term)` is the term's basis function at a row; `make(terms, outputs, coefficients)` builds the map.
// Result has members map, train_rms and solver_iterations.
template <class Result, class Term, class Basis, class Make>
Result fit_map_rows(const std::vector<PolyPoint>& inputs, std::size_t rows_per_input,
                    const std::vector<std::vector<double>>& targets, const std::vector<Term>& usable, const FitOptions& options,
                    const Basis& basis, const Make& make) {
  const std::size_t rows = inputs.size() * rows_per_input;
  std::vector<Term> terms;
  if (usable.size() <= static_cast<std::size_t>(options.max_terms)) {
    terms = usable;
  } else {
    std::size_t m = rows;
    if (options.max_selection_samples > 0) {
      m = std::min(rows, static_cast<std::size_t>(options.max_selection_samples) / rows_per_input * rows_per_input);
      m = std::max(m, rows_per_input);
    }
    std::vector<std::vector<double>> subset;
    for (const auto& t : targets) subset.emplace_back(t.begin(), t.begin() + static_cast<std::ptrdiff_t>(m));
    std::vector<std::vector<double>> selection_rms;
    const auto chosen = select_columns(
        usable.size(),
        [&](std::size_t j, std::vector<double>& column) {
          for (std::size_t r = 0; r < column.size(); ++r) column[r] = basis(r, usable[j]);
        },
        subset, options, selection_rms);
    for (const std::size_t j : chosen) terms.push_back(usable[j]);
  }

  const std::size_t k = terms.size();
  const std::size_t outputs = targets.size();
  Result result;
  std::vector<double> coefficients(k * outputs, 0.0);
  if (k > 0) {
    std::vector<double> design(rows * k);
    for (std::size_t r = 0; r < rows; ++r) {
      for (std::size_t j = 0; j < k; ++j) design[r * k + j] = basis(r, terms[j]);
    }
    const std::vector<std::vector<double>> c = solve_least_squares(design, static_cast<int>(k), targets);
    result.solver_iterations = 1;
    for (std::size_t o = 0; o < outputs; ++o) {
      for (std::size_t j = 0; j < k; ++j) coefficients[j * outputs + o] = c[o][j];
    }
  }
  result.map = make(std::move(terms), static_cast<int>(outputs), std::move(coefficients));
  result.train_rms.assign(outputs, 0.0);
  std::vector<double> value(outputs * rows_per_input);
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    result.map.evaluate(inputs[i], value);
    for (std::size_t o = 0; o < outputs; ++o) {
      for (std::size_t a = 0; a < rows_per_input; ++a) {
        const double e = value[o * rows_per_input + a] - targets[o][i * rows_per_input + a];
        result.train_rms[o] += e * e;
      }
    }
  }
  for (double& v : result.train_rms) v = std::sqrt(v / static_cast<double>(inputs.size()));
  return result;
}

}  // namespace lensmith::polyfit_detail
