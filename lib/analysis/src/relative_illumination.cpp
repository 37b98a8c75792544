// Relative illumination from the projected solid angle of the image-space beam (Rimmer, Proc. SPIE
// 655, 99 (1986)), and the vignetting factor from a pupil grid.
#include "lensmith/analysis/relative_illumination.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "analysis_detail.h"
#include "lensmith/core/units.h"
#include "pupil_grid.h"

namespace lensmith {

using analysis_detail::fixed;

void IlluminationOptions::validate() const {
  analysis_detail::check_count("IlluminationOptions::field_samples", field_samples, 2, 1001);
  analysis_detail::check_count("IlluminationOptions::pupil_grid", pupil_grid, 8, 1024);
}

namespace {

// Step for the derivative of the image-space direction cosines with respect to the pupil
// coordinate, normalised pupil units: small against a grid cell, large against rounding.
constexpr double kJacobianStep = 1e-4;

// |d(l, m) / d(px, py)| at a passed ray, by one-sided differences toward the pupil centre (with
// unclipped rays, so a ray at the edge of the beam still has neighbours). 0 when they fail.
double direction_cosine_jacobian(const AnalysisContext& context, const FieldPoint& field, const PupilCoordinate& p,
                                 const Ray& image_ray, double wavelength_nm) {
  const double hx = p.px > 0.0 ? -kJacobianStep : kJacobianStep;
  const double hy = p.py > 0.0 ? -kJacobianStep : kJacobianStep;
  const TracedRay rx = context.trace_unclipped(field, {p.px + hx, p.py}, wavelength_nm);
  const TracedRay ry = context.trace_unclipped(field, {p.px, p.py + hy}, wavelength_nm);
  if (!rx.ok() || !ry.ok()) return 0.0;
  const Eigen::Vector3d& d0 = image_ray.direction;
  const double dl_dx = (rx.image_ray.direction.x() - d0.x()) / hx;
  const double dm_dx = (rx.image_ray.direction.y() - d0.y()) / hx;
  const double dl_dy = (ry.image_ray.direction.x() - d0.x()) / hy;
  const double dm_dy = (ry.image_ray.direction.y() - d0.y()) / hy;
  return std::abs(dl_dx * dm_dy - dl_dy * dm_dx);
}

}  // namespace

RelativeIllumination compute_relative_illumination(const AnalysisContext& given, const IlluminationOptions& options) {
  options.validate();
  // The illumination measures the vignetting: the whole pupil, clipped by the apertures.
  std::optional<AnalysisContext> storage;
  const AnalysisContext& context = whole_pupil(given, storage);
  RelativeIllumination out;
  out.lens_name = context.lens().name;
  out.wavelength_nm = context.reference_wavelength_nm();
  out.field_unit = context.field_unit();
  out.pupil_grid = options.pupil_grid;
  const double cell_area = (2.0 / options.pupil_grid) * (2.0 / options.pupil_grid);

  const std::vector<double> fields = analysis_detail::relative_field_samples(options.field_samples);
  (void)context.field_at(fields.back());  // a lens without a field fails here, clearly
  for (double relative : fields) {
    IlluminationPoint p;
    p.relative_field = relative;
    p.field_value = context.field_value(relative);
    const FieldPoint field = context.field_at(relative);
    const analysis_detail::PupilGridTrace grid = analysis_detail::trace_pupil_grid(context, field, out.wavelength_nm, options.pupil_grid);
    p.rays_in_pupil = grid.inside_count;
    p.rays_passed = grid.passed_count;
    p.vignetting_factor = grid.inside_count ? static_cast<double>(grid.passed_count) / static_cast<double>(grid.inside_count) : 0.0;
    // Irradiance of a Lambertian object's image = radiance x projected solid angle of the beam,
    // which is its area in direction-cosine space: sum |J| over the passed pupil cells.
    double omega = 0.0;
    for (std::size_t i = 0; i < grid.rays.size(); ++i) {
      if (!grid.inside[i] || !grid.rays[i].ok()) continue;
      omega += direction_cosine_jacobian(context, field, grid.pupil[i], grid.rays[i].image_ray, out.wavelength_nm) * cell_area;
    }
    p.projected_solid_angle_sr = omega;
    const TracedRay chief = context.reference_ray(field, out.wavelength_nm);
    const double cos_angle = std::clamp(std::abs(chief.image_ray.direction.z()), 0.0, 1.0);
    p.chief_ray_angle_deg = deg_from_rad(std::acos(cos_angle));
    p.cos4_estimate = p.vignetting_factor * std::pow(cos_angle, 4);
    out.points.push_back(p);
  }
  double omega_max = 0.0;
  for (const auto& p : out.points) omega_max = std::max(omega_max, p.projected_solid_angle_sr);
  const double vignetting_axis = out.points.front().vignetting_factor;
  for (auto& p : out.points) {
    p.relative_illumination = omega_max > 0.0 ? p.projected_solid_angle_sr / omega_max : 0.0;
    if (vignetting_axis > 0.0) p.cos4_estimate /= vignetting_axis;
  }
  return out;
}

std::string RelativeIllumination::to_string() const {
  std::ostringstream os;
  os << "Relative illumination: " << lens_name << "\n";
  os << fixed(wavelength_nm, 4) << " nm; pupil grid " << pupil_grid << " x " << pupil_grid
     << "; RI = projected solid angle of the image-space beam / its maximum over the field;\n"
        "vignetting = passed / traced rays in the unit entrance pupil; cos4 = vignetting (relative to axis) x cos^4(chief-ray angle)\n\n";
  char line[192];
  std::snprintf(line, sizeof line, "%10s %12s %12s %14s %12s %14s %10s\n", "relative", ("field " + field_unit).c_str(), "vignetting",
                "rays", "RI", "chief deg", "cos4");
  os << line;
  for (const auto& p : points) {
    const std::string rays = std::to_string(p.rays_passed) + "/" + std::to_string(p.rays_in_pupil);
    std::snprintf(line, sizeof line, "%10.3f %12.4f %12.4f %14s %12.4f %14.3f %10.4f\n", p.relative_field, p.field_value,
                  p.vignetting_factor, rays.c_str(), p.relative_illumination, p.chief_ray_angle_deg, p.cos4_estimate);
    os << line;
  }
  return os.str();
}

}  // namespace lensmith
