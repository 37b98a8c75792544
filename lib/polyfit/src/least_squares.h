// The two steps every fit of this library shares, on any family of basis functions: greedy
// selection of columns (simultaneous orthogonal matching pursuit) and the coefficient solve (a
// rank-revealing QR; Ceres for a robust loss).
// Private to lib/polyfit.
#pragma once

#include <functional>
#include <optional>
#include <vector>

#include "lensmith/polyfit/polynomial_fit.h"

namespace lensmith {

// Fills `out` (size: the number of rows) with basis function j evaluated at every row.
using ColumnFunction = std::function<void(std::size_t j, std::vector<double>& out)>;

// Chooses at most options.max_terms of the `pool_size` columns for all targets together (each
// target has one value per row); returns their indices in selection order and, per target, the
// least-squares RMS after each step. Candidates are scored in parallel; the result does not depend
// on the thread count.
std::vector<std::size_t> select_columns(std::size_t pool_size, const ColumnFunction& column,
                                        const std::vector<std::vector<double>>& targets, const FitOptions& options,
                                        std::vector<std::vector<double>>& selection_rms);

// Least squares design * c ~ targets[o] for every target at once (design row-major, rows x num_terms), by
// Eigen's column-pivoting Householder QR: rank-revealing, so nearly dependent columns (high-degree terms
// of a dense fit) get no wild coefficients, and one factorisation serves every output. Throws FitError
// when the solution is not finite.
std::vector<std::vector<double>> solve_least_squares(const std::vector<double>& design, int num_terms,
                                                     const std::vector<std::vector<double>>& targets);

// Least squares design * c ~ targets: without `huber_scale`, solve_least_squares (returns 1); with it,
// under Huber's loss of that scale by Ceres (solve_huber_linear: dense QR, one residual per row), in
// place from the current coefficients, returning its iterations. Throws FitError when Ceres fails.
int solve_coefficients(const std::vector<double>& design, const std::vector<double>& targets, int num_terms,
                       std::optional<double> huber_scale, std::vector<double>& coefficients);

}  // namespace lensmith
