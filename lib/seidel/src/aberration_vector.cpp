#include "lensmith/seidel/aberration_vector.h"

#include <cmath>
#include <cstdio>

#include "lensmith/core/units.h"

namespace lensmith {

AberrationCoefficients AberrationCoefficients::from(const SeidelAnalysis& seidel) {
  const double k = 1.0 / (2.0 * seidel.image_index() * seidel.image_slope());
  const SeidelSums& s = seidel.sums();
  AberrationCoefficients c;
  c.B_mm = k * s.S1;
  c.C_mm = k * s.S3;
  c.D_mm = k * (s.S3 + s.S4);
  c.E_mm = -k * s.S5;
  c.F_mm = -k * s.S2;
  const ParaxialSystem& p = seidel.paraxial();
  c.pupil_radius_mm = 0.5 * p.entrance_pupil().diameter_mm;
  const ParaxialRayTable& chief = *p.chief_ray();
  // The chief ray crosses the entrance pupil at height 0 with object-space slope ubar: the field
  // tangent seen from the entrance pupil is |ubar| (conventions.h: ubar > 0 for a positive field).
  c.max_field_tangent = std::abs(chief.object_slope);
  c.object_to_entrance_pupil_mm = std::isinf(p.object_distance_mm()) ? kInfinity : p.entrance_pupil().z_mm + p.object_distance_mm();
  c.exit_pupil_to_image_mm = p.z_image_mm() - p.exit_pupil().z_mm;
  return c;
}

ImageDisplacement AberrationCoefficients::displacement(double rho, double theta, double y0) const {
  const double s = std::sin(theta);
  const double co = std::cos(theta);
  const double rho2 = rho * rho;
  const double rho3 = rho2 * rho;
  ImageDisplacement d;
  d.x_mm = B_mm * rho3 * s - 2.0 * F_mm * y0 * rho2 * s * co + D_mm * y0 * y0 * rho * s;
  d.y_mm = B_mm * rho3 * co - F_mm * y0 * rho2 * (1.0 + 2.0 * co * co) + (2.0 * C_mm + D_mm) * y0 * y0 * rho * co - E_mm * y0 * y0 * y0;
  return d;
}

BornWolfUnits AberrationCoefficients::in_born_wolf_units() const {
  // rho_BW = rho * r (mm), y0_BW = y0 * t, dp_BW = dp / D1: each coefficient is divided by D1 and by
  // the powers of r and t its term carries.
  const double r = pupil_radius_mm;
  const double t = max_field_tangent;
  BornWolfUnits u;
  u.D0_mm = object_to_entrance_pupil_mm;
  u.D1_mm = exit_pupil_to_image_mm;
  const double d1 = exit_pupil_to_image_mm;
  u.B = B_mm / (d1 * r * r * r);
  u.F = F_mm / (d1 * r * r * t);
  u.C = C_mm / (d1 * r * t * t);
  u.D = D_mm / (d1 * r * t * t);
  u.E = E_mm / (d1 * t * t * t);
  return u;
}

std::string BornWolfUnits::to_string() const {
  char buffer[200];
  std::snprintf(buffer, sizeof buffer, "B=%.6g C=%.6g D=%.6g E=%.6g F=%.6g (Born & Wolf units, D0=%.6g mm, D1=%.6g mm)", B, C, D, E, F,
                D0_mm, D1_mm);
  return buffer;
}

std::string AberrationCoefficients::to_string() const {
  char buffer[240];
  std::snprintf(buffer, sizeof buffer,
                "B=%.6g C=%.6g D=%.6g E=%.6g F=%.6g mm (rho = 1 at EP radius %.6g mm, y0 = 1 at field tangent %.6g)", B_mm, C_mm,
                D_mm, E_mm, F_mm, pupil_radius_mm, max_field_tangent);
  return buffer;
}

}  // namespace lensmith
