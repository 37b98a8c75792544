#include "lensmith/prescription/surface.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <cstdio>

#include "lensmith/core/units.h"

namespace lensmith {

double Surface::radius_mm() const { return curvature_per_mm == 0.0 ? kInfinity : 1.0 / curvature_per_mm; }

double Surface::max_semi_diameter_mm() const {
  const double kc2 = (1.0 + conic) * curvature_per_mm * curvature_per_mm;
  return kc2 > 0.0 ? 1.0 / std::sqrt(kc2) : kInfinity;
}

double Surface::sag_mm(double r_mm) const {
  const double c = curvature_per_mm;
  const double u = r_mm * r_mm;
  const double d = 1.0 - (1.0 + conic) * c * c * u;
  if (d < 0.0) return std::numeric_limits<double>::quiet_NaN();
  double poly = 0.0;
  for (std::size_t j = even_asphere.size(); j-- > 0;) poly = poly * u + even_asphere[j];
  // c u / (1 + sqrt(d)): the conic's sag without cancellation near the vertex.
  return c * u / (1.0 + std::sqrt(d)) + u * poly;
}

bool SurfaceAperture::passes(double x_mm, double y_mm, double tolerance_mm) const {
  const double x = x_mm - decenter_x_mm;
  const double y = y_mm - decenter_y_mm;
  // inside: within the shape grown by the tolerance (an aperture lets its rim pass); for an
  // obscuration the shape shrinks by it instead (its rim passes too).
  const double grow = obscuration ? -tolerance_mm : tolerance_mm;
  bool inside = false;
  switch (shape) {
    case Shape::Circular: {
      const double r = half_x_mm + grow;
      inside = r > 0.0 && x * x + y * y <= r * r;
      if (inside && !obscuration && min_radius_mm > 0.0) {
        const double r_min = std::max(0.0, min_radius_mm - tolerance_mm);
        if (x * x + y * y < r_min * r_min) return false;
      }
      break;
    }
    case Shape::Rectangular: inside = std::abs(x) <= half_x_mm + grow && std::abs(y) <= half_y_mm + grow; break;
    case Shape::Elliptical: {
      const double a = half_x_mm + grow, b = half_y_mm + grow;
      inside = a > 0.0 && b > 0.0 && (x / a) * (x / a) + (y / b) * (y / b) <= 1.0;
      break;
    }
  }
  return obscuration ? !inside : inside;
}

double SurfaceAperture::outer_radius_mm() const {
  if (obscuration) return kInfinity;
  const double dx = std::abs(decenter_x_mm), dy = std::abs(decenter_y_mm);
  switch (shape) {
    case Shape::Circular: return std::hypot(dx, dy) + half_x_mm;
    case Shape::Rectangular: return std::hypot(dx + half_x_mm, dy + half_y_mm);
    case Shape::Elliptical: return std::hypot(dx, dy) + std::max(half_x_mm, half_y_mm);
  }
  return kInfinity;
}

std::string SurfaceAperture::to_string() const {
  char buffer[160];
  const char* kind = shape == Shape::Circular ? "circular" : shape == Shape::Rectangular ? "rectangular" : "elliptical";
  if (shape == Shape::Circular) {
    std::snprintf(buffer, sizeof buffer, "%s%s r %.6g mm", kind, obscuration ? " obscuration" : "", half_x_mm);
  } else {
    std::snprintf(buffer, sizeof buffer, "%s%s %.6g x %.6g mm (half widths)", kind, obscuration ? " obscuration" : "", half_x_mm,
                  half_y_mm);
  }
  std::string s = buffer;
  if (min_radius_mm > 0.0) {
    std::snprintf(buffer, sizeof buffer, ", inner r %.6g mm", min_radius_mm);
    s += buffer;
  }
  if (decenter_x_mm != 0.0 || decenter_y_mm != 0.0) {
    std::snprintf(buffer, sizeof buffer, " at (%.6g, %.6g) mm", decenter_x_mm, decenter_y_mm);
    s += buffer;
  }
  return s;
}

bool Surface::has_asphere() const {
  return std::any_of(even_asphere.begin(), even_asphere.end(), [](double a) { return a != 0.0; });
}

std::string Surface::to_string() const {
  char buffer[256];
  const double r = radius_mm();
  char radius[32];
  if (curvature_per_mm == 0.0) {
    std::snprintf(radius, sizeof radius, "%s", "flat");
  } else {
    std::snprintf(radius, sizeof radius, "%.6g", r);
  }
  char semi[32];
  if (semi_diameter_mm) {
    std::snprintf(semi, sizeof semi, "%.6g", *semi_diameter_mm);
  } else {
    std::snprintf(semi, sizeof semi, "%s", "-");
  }
  std::snprintf(buffer, sizeof buffer, "R=%s mm t=%.6g mm %s sd=%s%s%s%s", radius, thickness_mm, material.to_string().c_str(),
                semi, semi_diameter_mm && !clips_rays ? " (not clipping)" : "", is_stop ? " STOP" : "", conic != 0.0 ? " conic" : "");
  std::string s = buffer;
  if (conic != 0.0) {
    std::snprintf(buffer, sizeof buffer, "=%.6g", conic);
    s += buffer;
  }
  if (has_asphere()) {
    s += " asphere[";
    for (std::size_t j = 0; j < even_asphere.size(); ++j) {
      if (even_asphere[j] == 0.0) continue;
      std::snprintf(buffer, sizeof buffer, " a%zu=%.6g", 2 * (j + 1), even_asphere[j]);
      s += buffer;
    }
    s += " ]";
  }
  if (aperture) s += " aperture[" + aperture->to_string() + "]";
  return s;
}

}  // namespace lensmith
