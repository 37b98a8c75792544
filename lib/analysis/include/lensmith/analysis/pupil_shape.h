// The unvignetted entrance pupil per field: which rays of a square grid in the unit entrance pupil
// reach the image plane (off axis, the "cat's eye" that shapes off-axis bokeh), the area fraction
// that passes, the surfaces that cut the beam, and the outline of the passing region found by
// bisection with real rays along rays from its centroid (exact for star-shaped regions, which the
// intersection of circular apertures seen through a lens normally is).
#pragma once

#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

#include "lensmith/analysis/analysis_context.h"

namespace lensmith {

struct PupilShapeOptions {
  int grid = 64;             // grid cells across the pupil diameter, 8 to 1024
  int outline_points = 96;   // outline vertices, 8 to 4096 (0 = no outline)
  void validate() const;     // throws OptionsError
};

// Why rays at one pupil grid point did not pass.
struct PupilCell {
  bool inside = false;               // inside the unit pupil
  RayStatus status = RayStatus::Ok;  // for cells inside
  int surface = 0;                   // where the ray died
};

struct SurfaceLoss {
  int surface = 0;
  RayStatus status = RayStatus::Vignetted;
  std::size_t rays = 0;
};

struct FieldPupilShape {
  double relative_field = 0.0;
  double field_value = 0.0;
  std::string field_label;
  int grid = 0;
  // grid * grid cells, row-major from py = +1 (top row) down to py = -1, px from -1 to +1; the
  // centre of cell (row r, column c) is px = -1 + (2c + 1) / grid, py = 1 - (2r + 1) / grid.
  std::vector<PupilCell> cells;
  std::size_t rays_in_pupil = 0;
  std::size_t rays_passed = 0;
  double area_fraction = 0.0;          // rays_passed / rays_in_pupil (the vignetting factor)
  PupilCoordinate centroid;            // of the passing cells
  std::vector<PupilCoordinate> outline;  // counter-clockwise; empty when nothing passes
  std::vector<SurfaceLoss> losses;     // by surface and reason, in surface order
  const PupilCell& cell(int row, int column) const { return cells[static_cast<std::size_t>(row * grid + column)]; }
  static PupilCoordinate cell_centre(int grid, int row, int column);
};

struct PupilShape {
  std::string lens_name;
  double wavelength_nm = 0.0;   // reference wavelength
  std::string field_unit;
  std::vector<FieldPupilShape> fields;
  // Per field: area fraction, losses, and a character picture of the pupil ('#' passes, the
  // surface number's last digit where a ray died, ' ' outside).
  std::string to_string() const;
  friend std::ostream& operator<<(std::ostream& os, const PupilShape& p) { return os << p.to_string(); }
};

PupilShape compute_pupil_shape(const AnalysisContext& context, const PupilShapeOptions& options = {});

}  // namespace lensmith
