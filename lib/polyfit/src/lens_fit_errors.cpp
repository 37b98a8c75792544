// The fit's held-out errors (lens_fit_stages.h): rays of a stream the fit never saw, each traced by the
// exact tracer and evaluated by the fitted maps both ways (sensor -> outer, outer -> sensor), with
// the stop crossing, the transmittance and the pass/clip verdict.
#include <algorithm>
#include <cmath>

#include "lens_fit_stages.h"

namespace lensmith::polyfit_detail {

namespace {

// The p-quantile of `values` by the nearest-rank rule (the ceil(p n)-th smallest, p in (0, 1]); 0 for none.
double percentile(std::vector<double> values, double p) {
  if (values.empty()) return 0.0;
  const std::size_t k = std::min(values.size() - 1, static_cast<std::size_t>(std::ceil(p * static_cast<double>(values.size()))) - 1);
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
  return values[k];
}

}  // namespace

LensFitErrors held_out_errors(const LensFit& fit, std::span<const Candidate> test, int stop_surface) {
  const std::size_t stop_index = static_cast<std::size_t>(stop_surface - 1);
  LensFitErrors e;
  std::vector<double> position_um, sensor_um;
  double direction2 = 0.0, stop2 = 0.0, t2 = 0.0, sensor_direction2 = 0.0;
  std::size_t mismatched = 0;
  for (const Candidate& c : test) {
    const FitTrace back = fit.from_sensor(c.sensor, c.wavelength_nm);
    mismatched += back.passes != c.passes ? 1 : 0;
    if (!c.passes) continue;
    position_um.push_back(1e3 * std::hypot(back.ray.x_mm - c.outer.x_mm, back.ray.y_mm - c.outer.y_mm));
    direction2 += std::pow(back.ray.dx - c.outer.dx, 2) + std::pow(back.ray.dy - c.outer.dy, 2);
    stop2 += std::pow(back.stop_x_mm - c.hit_x[stop_index], 2) + std::pow(back.stop_y_mm - c.hit_y[stop_index], 2);
    t2 += std::pow(fit.transmittance(c.sensor, c.wavelength_nm) - c.transmittance, 2);
    const FitTrace fwd = fit.from_outer(c.outer, c.wavelength_nm);
    sensor_um.push_back(1e3 * std::hypot(fwd.ray.x_mm - c.sensor.x_mm, fwd.ray.y_mm - c.sensor.y_mm));
    sensor_direction2 += std::pow(fwd.ray.dx - c.sensor.dx, 2) + std::pow(fwd.ray.dy - c.sensor.dy, 2);
  }
  const double n = static_cast<double>(position_um.size());
  e.test_rays = static_cast<int>(position_um.size());
  double p2 = 0.0, q2 = 0.0;
  for (const double v : position_um) p2 += v * v;
  for (const double v : sensor_um) q2 += v * v;
  e.position_rms_um = std::sqrt(p2 / n);
  e.position_p99_um = percentile(position_um, 0.99);
  e.direction_rms_mrad = 1e3 * std::sqrt(direction2 / n);
  e.stop_rms_um = 1e3 * std::sqrt(stop2 / n);
  e.transmittance_rms = std::sqrt(t2 / n);
  e.sensor_position_rms_um = std::sqrt(q2 / n);
  e.sensor_position_p99_um = percentile(sensor_um, 0.99);
  e.sensor_direction_rms_mrad = 1e3 * std::sqrt(sensor_direction2 / n);
  e.vignetting_mismatch = static_cast<double>(mismatched) / static_cast<double>(test.size());
  return e;
}

}  // namespace lensmith::polyfit_detail
