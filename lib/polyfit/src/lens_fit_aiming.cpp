// Newton aiming on the fitted maps (lens_fit.h): the sensor-side direction, or the outer-pupil position
// from an object point, whose fitted ray crosses the stop at a requested point; the front surface's
// sag and the object-side rays the outer maps take.
#include <cmath>

#include "lens_fit_stages.h"
#include "lensmith/core/number_parsing.h"
#include "lensmith/core/root_solver_2d.h"

namespace lensmith {

using polyfit_detail::in_domain;
using polyfit_detail::normalised;

namespace {

// Step halvings of the fits' line search: the shortest step tried is 2^-9 of Newton's.
constexpr int kMaxStepHalvings = 9;

// Damped Newton on two unknowns (RootSolver2d, the Jacobian from the fit): `residual(u, r, jacobian
// or null)` gives the stop miss (mm) at u and, when asked, d(miss) / du; false when u leaves the
// fit's domain. Each step is halved (at most 9 times) until the miss falls: the stop map is nearly
// linear, so the full step is almost always taken. Fills the iterations, miss, Jacobian and
// convergence of `aim`; returns the last accepted u.
template <class Residual>
std::array<double, 2> damped_newton(std::array<double, 2> u, const Residual& residual, const FitAimOptions& options,
                                    FitAim& aim) {
  RootSolver2dOptions o;
  o.jacobian = JacobianSource::Analytic;
  o.tolerance = options.tolerance_mm;
  o.max_iterations = options.max_iterations;
  o.max_halvings = kMaxStepHalvings;
  const RootSolver2dSummary summary = RootSolver2d(o).solve(residual, u);
  if (summary.status == RootSolver2dStatus::FailedAtStart) return u;
  aim.jacobian = summary.jacobian;
  aim.miss_mm = summary.residual_norm;
  aim.iterations = summary.iterations;
  aim.converged = summary.converged();
  return u;
}

}  // namespace

void FitAimOptions::validate() const {
  if (!(tolerance_mm > 0.0 && std::isfinite(tolerance_mm))) {
    throw OptionsError("aim tolerance must be a finite length > 0 mm, got " + format_number(tolerance_mm));
  }
  if (max_iterations < 1) throw OptionsError("aim needs at least 1 iteration, got " + std::to_string(max_iterations));
}

FitAim LensFit::aim_from_sensor(double x_mm, double y_mm, double stop_x_mm, double stop_y_mm, double wavelength_nm,
                                const FitAimOptions& options) const {
  options.validate();
  const double lambda = normalised_wavelength(wavelength_nm);
  const double ps = scales_.sensor_position_mm, ds = scales_.sensor_direction;
  // First guess: toward the paraxial exit-pupil image of the stop point, each section's in its own
  // coordinate (the same pupil for a rotationally symmetric lens).
  auto slope = [&](double at_mm, double stop_mm, const Pupils& p) {
    const double dz = sensor_z_mm_ - p.z_exit_pupil_mm;
    return dz == 0.0 ? 0.0 : (at_mm - stop_mm * p.exit_per_stop) / dz;
  };
  const double tx = slope(x_mm, stop_x_mm, pupils_x_), ty = slope(y_mm, stop_y_mm, pupils_);
  const double norm = std::sqrt(tx * tx + ty * ty + 1.0);
  FitAim aim;
  aim.ray = PlaneRay{x_mm, y_mm, tx / norm, ty / norm};
  const FittedMap& map = sensor_clip_;
  std::array<double, 2> at;
  std::array<double, 8> jac;
  auto residual = [&](const std::array<double, 2>& u, std::array<double, 2>& miss, std::array<double, 4>* j) {
    const PolyPoint va = normalised(PlaneRay{x_mm, y_mm, u[0], u[1]}, ps, ds, lambda);
    if (!in_domain(va)) return false;
    // Output 0 is the stop; its Jacobian columns 2, 3 are d/d(dx, dy) in normalised units.
    if (j) {
      map.evaluate_with_jacobian(va, 0, at, jac);
      *j = {jac[2] / ds, jac[3] / ds, jac[6] / ds, jac[7] / ds};
    } else {
      at = map.evaluate_output(va, 0);
    }
    miss = {at[0] - stop_x_mm, at[1] - stop_y_mm};
    return true;
  };
  const auto u = damped_newton({aim.ray.dx, aim.ray.dy}, residual, options, aim);
  aim.ray = PlaneRay{x_mm, y_mm, u[0], u[1]};
  return aim;
}

std::array<double, 2> LensFit::paraxial_outer_position(const ObjectPoint& o, double stop_x_mm, double stop_y_mm) const {
  const double w = o.inverse_depth_per_mm;
  // Each section's coordinate through its own entrance pupil (an anamorphic front group puts the x
  // section's far from the y section's; the same pupil for a rotationally symmetric lens).
  auto at_vertex_plane = [&](double stop_mm, double tan, const Pupils& p) {
    const double e = stop_mm * p.entrance_per_stop, ze = p.z_entrance_pupil_mm;
    // w times the vector from the object point to the entrance-pupil point (finite at w = 0).
    const double u = w * e - tan, uz = 1.0 + w * (ze - o.origin_z_mm);
    return e - u / uz * ze;
  };
  return {at_vertex_plane(stop_x_mm, o.tan_x, pupils_x_), at_vertex_plane(stop_y_mm, o.tan_y, pupils_)};
}

FitAim LensFit::aim_from_object(const ObjectPoint& o, double stop_x_mm, double stop_y_mm, double wavelength_nm,
                                std::optional<std::array<double, 2>> guess, const FitAimOptions& options) const {
  options.validate();
  FitAim aim = aim_from_object_at(o, stop_x_mm, stop_y_mm, wavelength_nm, guess ? *guess : paraxial_outer_position(o, stop_x_mm, stop_y_mm),
                                  options);
  if (aim.converged || guess) return aim;
  // Continuation along the field: where the paraxial entrance pupil is too far from the real one for
  // Newton to start from (a retrofocus's pupil moves forward and grows off axis: lentil 0005's chief
  // rays beyond 45 deg of its 55 deg frame corner were left unaimed, and the frame's outer band came
  // out as the fill's flat grey), the point's direction is approached in kContinuationSteps equal
  // steps of its tangent, each starting from the last one's solution.
  constexpr int kContinuationSteps = 8;
  std::optional<std::array<double, 2>> last;
  for (int k = 1; k <= kContinuationSteps; ++k) {
    const double f = static_cast<double>(k) / kContinuationSteps;
    const ObjectPoint p{f * o.tan_x, f * o.tan_y, o.inverse_depth_per_mm, o.origin_z_mm};
    const FitAim step = aim_from_object_at(p, stop_x_mm, stop_y_mm, wavelength_nm, last ? *last : paraxial_outer_position(p, stop_x_mm, stop_y_mm),
                                           options);
    if (!step.converged) {
      if (last) return aim;  // lost on the way out: not aimed
      continue;
    }
    if (k == kContinuationSteps) return step;
    last = std::array<double, 2>{step.ray.x_mm, step.ray.y_mm};
  }
  return aim;
}

FitAim LensFit::aim_from_object_at(const ObjectPoint& o, double stop_x_mm, double stop_y_mm, double wavelength_nm,
                                   const std::array<double, 2>& start, const FitAimOptions& options) const {
  const double lambda = normalised_wavelength(wavelength_nm);
  const double ps = scales_.outer_position_mm, ds = scales_.outer_direction;
  const FittedMap& map = outer_clip_;
  std::array<double, 2> at;
  std::array<double, 8> jac;
  auto residual = [&](const std::array<double, 2>& u, std::array<double, 2>& miss, std::array<double, 4>* j) {
    const std::optional<OuterLine> found = outer_line(o, u[0], u[1]);
    if (!found) return false;
    const OuterLine& l = *found;
    const PolyPoint va = normalised(l.ray, ps, ds, lambda);
    if (!in_domain(va)) return false;
    if (!j) {
      at = map.evaluate_output(va, 0);
      miss = {at[0] - stop_x_mm, at[1] - stop_y_mm};
      return true;
    }
    map.evaluate_with_jacobian(va, 0, at, jac);
    miss = {at[0] - stop_x_mm, at[1] - stop_y_mm};
    {
      // Chain rule through the normalisation and the direction's dependence on the outer position.
      const double* gx = jac.data();      // d stop_x / d(normalised x, y, dx, dy)
      const double* gy = jac.data() + 4;  // d stop_y / d(...)
      *j = {gx[0] / ps + gx[2] / ds * l.ddx_dx + gx[3] / ds * l.ddy_dx,
            gx[1] / ps + gx[2] / ds * l.ddx_dy + gx[3] / ds * l.ddy_dy,
            gy[0] / ps + gy[2] / ds * l.ddx_dx + gy[3] / ds * l.ddy_dx,
            gy[1] / ps + gy[2] / ds * l.ddx_dy + gy[3] / ds * l.ddy_dy};
    }
    return true;
  };
  FitAim aim;
  const auto u = damped_newton(start, residual, options, aim);
  const std::optional<OuterLine> last = outer_line(o, u[0], u[1]);
  aim.ray = last ? last->ray : PlaneRay{u[0], u[1], 0.0, 0.0};
  return aim;
}

std::optional<double> LensFit::front_sag(double x_mm, double y_mm, double& dz_dx, double& dz_dy) const {
  double z = 0.0;
  if (!front_shape_.sag_and_slope(x_mm, y_mm, z, dz_dx, dz_dy)) return std::nullopt;
  return z;
}

std::optional<LensFit::OuterLine> LensFit::outer_line(const ObjectPoint& o, double x, double y) const {
  double zx = 0.0, zy = 0.0;
  const std::optional<double> z = front_sag(x, y, zx, zy);
  if (!z) return std::nullopt;
  // w times the vector from the object point to the surface point (finite at w = 0).
  const double w = o.inverse_depth_per_mm;
  const double ux = w * x - o.tan_x, uy = w * y - o.tan_y, uz = 1.0 + w * (*z - o.origin_z_mm);
  if (uz <= 0.0) return std::nullopt;  // the object point is not in front of the surface
  const double len = std::sqrt(ux * ux + uy * uy + uz * uz);
  const double fx = ux / len, fy = uy / len, fz = uz / len;
  // d(w u) / dx = (w, 0, w dz/dx), d(w u) / dy = (0, w, w dz/dy); d f = (g - f (f.g)) / |w u|.
  const double fgx = w * (fx + fz * zx), fgy = w * (fy + fz * zy);
  return OuterLine{PlaneRay{x, y, fx, fy}, (w - fx * fgx) / len, (0.0 - fy * fgx) / len, (0.0 - fx * fgy) / len,
                   (w - fy * fgy) / len};
}

std::optional<PlaneRay> LensFit::outer_ray_from_object(const ObjectPoint& o, double x_mm, double y_mm) const {
  const std::optional<OuterLine> line = outer_line(o, x_mm, y_mm);
  if (!line) return std::nullopt;
  return line->ray;
}

std::optional<std::array<double, 2>> LensFit::stop_from_object(const ObjectPoint& o, double x_mm, double y_mm,
                                                              double wavelength_nm) const {
  const std::optional<PlaneRay> ray = outer_ray_from_object(o, x_mm, y_mm);
  if (!ray) return std::nullopt;
  const double lambda = normalised_wavelength(wavelength_nm);
  const PolyPoint v = normalised(*ray, scales_.outer_position_mm, scales_.outer_direction, lambda);
  if (!in_domain(v)) return std::nullopt;
  return outer_clip_.evaluate_output(v, 0);
}

}  // namespace lensmith
