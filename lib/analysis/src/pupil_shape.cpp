// The passing part of the entrance pupil per field: a grid of real rays and a bisected outline.
#include "lensmith/analysis/pupil_shape.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

#include "analysis_detail.h"
#include "lensmith/core/units.h"
#include "pupil_grid.h"

namespace lensmith {

using analysis_detail::fixed;

void PupilShapeOptions::validate() const {
  analysis_detail::check_count("PupilShapeOptions::grid", grid, 8, 1024);
  if (outline_points != 0) analysis_detail::check_count("PupilShapeOptions::outline_points", outline_points, 8, 4096);
}

PupilCoordinate FieldPupilShape::cell_centre(int grid, int row, int column) {
  return analysis_detail::grid_cell_centre(grid, row, column);
}

namespace {

// Bisection steps for the outline: 2^-30 of a grid step is far below anything a picture shows.
constexpr int kBisections = 30;

// Where the ray from `c` along `d` leaves the passing region: march in steps of about half a grid
// cell until a ray fails or the unit disc ends, then bisect between the last pass and the failure.
PupilCoordinate boundary_along(const AnalysisContext& context, const FieldPoint& field, double wavelength_nm,
                               const PupilCoordinate& c, double dx, double dy, double step) {
  // |c + t d| = 1 with |d| = 1: t = -c.d + sqrt((c.d)^2 - |c|^2 + 1).
  const double cd = c.px * dx + c.py * dy;
  const double cc = c.px * c.px + c.py * c.py;
  const double t_disc = -cd + std::sqrt(std::max(0.0, cd * cd - cc + 1.0));
  auto passes = [&](double t) { return context.trace(field, {c.px + t * dx, c.py + t * dy}, wavelength_nm).ok(); };
  double t_pass = 0.0;
  double t_fail = -1.0;
  for (double t = step; t < t_disc; t += step) {
    if (!passes(t)) {
      t_fail = t;
      break;
    }
    t_pass = t;
  }
  if (t_fail < 0.0) {
    // Nothing failed before the disc edge: the edge itself bounds the region if its ray passes.
    const double t_edge = t_disc * (1.0 - 1e-12);
    if (passes(t_edge)) return {c.px + t_edge * dx, c.py + t_edge * dy};
    t_fail = t_edge;
  }
  for (int i = 0; i < kBisections; ++i) {
    const double t = 0.5 * (t_pass + t_fail);
    (passes(t) ? t_pass : t_fail) = t;
  }
  return {c.px + t_pass * dx, c.py + t_pass * dy};
}

}  // namespace

PupilShape compute_pupil_shape(const AnalysisContext& given, const PupilShapeOptions& options) {
  // The shape of what passes: the whole pupil, clipped by the apertures.
  std::optional<AnalysisContext> storage;
  const AnalysisContext& context = whole_pupil(given, storage);
  options.validate();
  PupilShape out;
  out.lens_name = context.lens().name;
  out.wavelength_nm = context.reference_wavelength_nm();
  out.field_unit = context.field_unit();
  for (double relative : context.relative_fields()) {
    FieldPupilShape shape;
    shape.relative_field = relative;
    shape.field_value = context.field_value(relative);
    shape.field_label = context.field_label(relative);
    shape.grid = options.grid;
    const FieldPoint field = context.field_at(relative);
    const analysis_detail::PupilGridTrace grid = analysis_detail::trace_pupil_grid(context, field, out.wavelength_nm, options.grid);
    shape.rays_in_pupil = grid.inside_count;
    shape.rays_passed = grid.passed_count;
    shape.area_fraction = grid.inside_count ? static_cast<double>(grid.passed_count) / static_cast<double>(grid.inside_count) : 0.0;
    std::map<std::pair<int, int>, std::size_t> losses;
    double sx = 0.0, sy = 0.0;
    shape.cells.resize(grid.rays.size());
    for (std::size_t i = 0; i < grid.rays.size(); ++i) {
      PupilCell& cell = shape.cells[i];
      cell.inside = grid.inside[i];
      if (!cell.inside) continue;
      cell.status = grid.rays[i].status;
      cell.surface = grid.rays[i].surface;
      if (grid.rays[i].ok()) {
        sx += grid.pupil[i].px;
        sy += grid.pupil[i].py;
      } else {
        ++losses[{cell.surface, static_cast<int>(cell.status)}];
      }
    }
    for (const auto& [key, rays] : losses) shape.losses.push_back({key.first, static_cast<RayStatus>(key.second), rays});
    if (grid.passed_count > 0) {
      shape.centroid = {sx / static_cast<double>(grid.passed_count), sy / static_cast<double>(grid.passed_count)};
      const double step = 1.0 / options.grid;
      for (int k = 0; k < options.outline_points; ++k) {
        const double phi = 2.0 * kPi * k / options.outline_points;
        shape.outline.push_back(
            boundary_along(context, field, out.wavelength_nm, shape.centroid, std::cos(phi), std::sin(phi), step));
      }
    }
    out.fields.push_back(std::move(shape));
  }
  return out;
}

std::string PupilShape::to_string() const {
  std::ostringstream os;
  os << "Unvignetted entrance pupil: " << lens_name << ", " << fixed(wavelength_nm, 4) << " nm\n";
  os << "'#' passes; a digit is the last digit of the surface where the ray died; blank: outside the pupil\n";
  for (const auto& f : fields) {
    os << "\nField " << f.field_label << " (relative " << f.relative_field << "): " << f.rays_passed << " of " << f.rays_in_pupil
       << " rays pass, area fraction " << fixed(f.area_fraction, 4) << "\n";
    for (const auto& loss : f.losses) {
      os << "  surface " << loss.surface << ": " << loss.rays << " rays " << lensmith::to_string(loss.status) << "\n";
    }
    // Two characters per cell horizontally keeps the picture round in a terminal; at most 32 rows.
    const int stride = std::max(1, f.grid / 32);
    for (int row = stride / 2; row < f.grid; row += stride) {
      std::string line = "  ";
      for (int column = stride / 2; column < f.grid; column += stride) {
        const PupilCell& c = f.cell(row, column);
        char ch = ' ';
        if (c.inside) ch = c.status == RayStatus::Ok ? '#' : static_cast<char>('0' + c.surface % 10);
        line += ch;
        line += ch == '#' ? '#' : ch;
      }
      while (!line.empty() && line.back() == ' ') line.pop_back();
      os << line << "\n";
    }
  }
  return os.str();
}

}  // namespace lensmith
