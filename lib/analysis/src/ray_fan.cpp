// Tangential and sagittal transverse ray fans against the reference chief ray (Welford sec. 4.8).
#include "lensmith/analysis/ray_fan.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

#include "lensmith/core/errors.h"
#include "lensmith/core/units.h"

namespace lensmith {

void RayFanOptions::validate() const {
  if (samples < 3 || samples > 1001 || samples % 2 == 0) {
    throw OptionsError("RayFanOptions::samples = " + std::to_string(samples) + ": must be odd, 3 to 1001 (so the chief ray is sampled)");
  }
}

RayFan compute_ray_fan(const AnalysisContext& context, const RayFanOptions& options) {
  options.validate();
  RayFan out;
  out.lens_name = context.lens().name;
  out.wavelengths_nm = context.wavelengths_nm();
  out.reference_wavelength_nm = context.reference_wavelength_nm();
  out.field_unit = context.field_unit();
  out.image_plane_z_mm = context.tracer().image_plane_z_mm();
  const double nan = std::numeric_limits<double>::quiet_NaN();

  for (double relative : context.relative_fields()) {
    FieldFan fan;
    fan.relative_field = relative;
    fan.field_value = context.field_value(relative);
    fan.field_label = context.field_label(relative);
    const FieldPoint field = context.field_at(relative);
    fan.chief = ImagePoint::from(context.reference_ray(field, context.reference_wavelength_nm()).image_ray.position_mm);
    for (double wavelength : context.wavelengths_nm()) {
      FanCurve curve;
      curve.wavelength_nm = wavelength;
      for (int i = 0; i < options.samples; ++i) {
        // Symmetric samples; the middle one is exactly 0.
        const double p = -1.0 + 2.0 * i / (options.samples - 1);
        const TracedRay t = context.trace(field, {0.0, p}, wavelength);
        curve.tangential.push_back({p, t.status, t.surface, t.ok() ? t.image_ray.position_mm.y() - fan.chief.y_mm : nan});
        const TracedRay s = context.trace(field, {p, 0.0}, wavelength);
        curve.sagittal.push_back({p, s.status, s.surface, s.ok() ? s.image_ray.position_mm.x() - fan.chief.x_mm : nan});
      }
      fan.curves.push_back(std::move(curve));
    }
    out.fields.push_back(std::move(fan));
  }
  return out;
}

double RayFan::max_abs_error_mm() const {
  double m = 0.0;
  for (const auto& f : fields) {
    for (const auto& c : f.curves) {
      for (const auto* samples : {&c.tangential, &c.sagittal}) {
        for (const auto& s : *samples) {
          if (s.ok()) m = std::max(m, std::abs(s.error_mm));
        }
      }
    }
  }
  return m;
}

std::string RayFan::to_string() const {
  std::ostringstream os;
  char cell[64];
  os << "Ray fans: " << lens_name << "\n";
  os << "Transverse errors in micrometres on the image plane (z = " << image_plane_z_mm << " mm) against the chief ray at "
     << reference_wavelength_nm << " nm; '-' = the ray died (status in --json).\n";
  for (const FieldFan& f : fields) {
    os << "\nField " << f.field_label << " (relative " << f.relative_field << "), chief ray at x = " << f.chief.x_mm
       << ", y = " << f.chief.y_mm << " mm\n";
    for (int fan = 0; fan < 2; ++fan) {
      os << (fan == 0 ? "   py" : "   px");
      for (const auto& c : f.curves) {
        std::snprintf(cell, sizeof cell, "  %s %6.1f nm", fan == 0 ? "ey" : "ex", c.wavelength_nm);
        os << cell;
      }
      os << "\n";
      if (f.curves.empty()) continue;
      const std::size_t n = f.curves.front().tangential.size();
      for (std::size_t i = 0; i < n; ++i) {
        std::snprintf(cell, sizeof cell, "%5.2f", f.curves.front().tangential[i].pupil);
        os << cell;
        for (const auto& c : f.curves) {
          const FanSample& s = fan == 0 ? c.tangential[i] : c.sagittal[i];
          if (s.ok()) {
            std::snprintf(cell, sizeof cell, "  %14.3f", um_from_mm(s.error_mm));
          } else {
            std::snprintf(cell, sizeof cell, "  %14s", "-");
          }
          os << cell;
        }
        os << "\n";
      }
    }
  }
  return os.str();
}

}  // namespace lensmith
