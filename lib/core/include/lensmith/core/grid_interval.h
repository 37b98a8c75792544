// Where a value falls on a sorted grid of samples, for the tables that interpolate linearly between
// them (the aberration table, the fitted Seidel terms).
#pragma once

#include <algorithm>
#include <cstddef>
#include <utility>
#include <vector>

namespace lensmith {

// The index i of the interval [grid[i], grid[i + 1]] of the ascending `grid` that holds x, and x's
// fraction within it; clamped to the first and last intervals (fraction 0 below, 1 above). A grid of
// fewer than two samples gives (0, 0).
inline std::pair<std::size_t, double> grid_interval(const std::vector<double>& grid, double x) {
  if (grid.size() < 2 || x <= grid.front()) return {0, 0.0};
  if (x >= grid.back()) return {grid.size() - 2, 1.0};
  const auto it = std::upper_bound(grid.begin(), grid.end(), x);
  const std::size_t i = static_cast<std::size_t>(it - grid.begin()) - 1;
  return {i, (x - grid[i]) / (grid[i + 1] - grid[i])};
}

}  // namespace lensmith
