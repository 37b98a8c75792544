// The two steps every fit of this library shares, on any family of basis functions: greedy
// selection of columns (simultaneous orthogonal matching pursuit) and the coefficient solve by Ceres.
// Private to lib/polyfit.
#pragma once

#include <functional>
#include <vector>

#include "lensmith/polyfit/polynomial_fit.h"

namespace ceres {
class LossFunction;
}

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

// Least squares design * c ~ targets by Ceres (dense QR), design row-major (rows x num_terms), in place
// from the current coefficients; with `loss` (e.g. Huber) one residual block per row. Returns the
// iterations. Throws FitError when Ceres fails.
int solve_coefficients(const std::vector<double>& design, const std::vector<double>& targets, int num_terms,
                       ceres::LossFunction* loss, std::vector<double>& coefficients);

}  // namespace lensmith
