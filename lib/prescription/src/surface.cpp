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
  std::snprintf(buffer, sizeof buffer, "R=%s mm t=%.6g mm %s sd=%s%s%s", radius, thickness_mm, material.to_string().c_str(),
                semi, is_stop ? " STOP" : "", conic != 0.0 ? " conic" : "");
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
  return s;
}

}  // namespace lensmith
