// A square grid of rays over the unit entrance pupil, traced once: shared by the pupil-shape and
// relative-illumination analyses (not installed).
#pragma once

#include <vector>

#include "lensmith/analysis/analysis_context.h"

namespace lensmith::analysis_detail {

struct PupilGridTrace {
  int grid = 0;                            // cells across the diameter
  std::vector<PupilCoordinate> pupil;      // cell centres, row-major from py = +1, px from -1
  std::vector<bool> inside;                // centre inside the unit disc
  std::vector<TracedRay> rays;             // traced for cells inside (default-constructed outside)
  std::size_t inside_count = 0;
  std::size_t passed_count = 0;
};

// Centre of cell (row, column): px = -1 + (2c + 1) / grid, py = 1 - (2r + 1) / grid.
inline PupilCoordinate grid_cell_centre(int grid, int row, int column) {
  return {-1.0 + (2.0 * column + 1.0) / grid, 1.0 - (2.0 * row + 1.0) / grid};
}

inline PupilGridTrace trace_pupil_grid(const AnalysisContext& context, const FieldPoint& field, double wavelength_nm, int grid) {
  PupilGridTrace out;
  out.grid = grid;
  const auto cells = static_cast<std::size_t>(grid) * static_cast<std::size_t>(grid);
  out.pupil.reserve(cells);
  out.inside.reserve(cells);
  out.rays.resize(cells);
  for (int row = 0; row < grid; ++row) {
    for (int column = 0; column < grid; ++column) {
      const PupilCoordinate p = grid_cell_centre(grid, row, column);
      const bool inside = p.px * p.px + p.py * p.py <= 1.0;
      const std::size_t index = out.pupil.size();
      out.pupil.push_back(p);
      out.inside.push_back(inside);
      if (!inside) continue;
      ++out.inside_count;
      out.rays[index] = context.trace(field, p, wavelength_nm);
      if (out.rays[index].ok()) ++out.passed_count;
    }
  }
  return out;
}

}  // namespace lensmith::analysis_detail
