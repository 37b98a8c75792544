// The one home of a rotationally symmetric surface's shape: the sag of a conic plus an even
// polynomial, its slope, and the largest radius the conic allows. Surface::sag_mm, Surface::sag_and_slope
// (Standard surfaces and a toroid's y curve), Surface::max_semi_diameter_mm, the exact tracer's asphere
// intersection and the polynomial fits' front surface all evaluate it here.
//
//   z(u) = c u / (1 + sqrt(D)) + u sum_j a_j u^j,   D = 1 - (1 + k) c^2 u,   u = r^2 (mm^2),
//
// the conic written without the cancellation of (1 - sqrt(D)) / ((1 + k) c) near the vertex
// (W. J. Smith, Modern Optical Engineering, 4th ed., sec. 18.4; Zemax's "Standard" and "Even
// Asphere" surfaces). a_j is the r^(2j+2) coefficient (a2, a4, ..., a16), mm^(1 - 2(j+1)).
// Inline and allocation-free: the tracer calls it once per Newton step.
#pragma once

#include <cmath>
#include <limits>

namespace lensmith {

// The sag z (mm) at u = r^2 (mm^2) and dz/du (1/mm). False, nothing set, where D <= 0 (beyond the
// conic's rim, or on it where the slope is infinite) or the result is not finite. `terms` coefficients
// are read from `a` (a2 first).
inline bool conic_profile(double c_per_mm, double one_plus_conic, const double* a, int terms, double u_mm2, double& z_mm,
                          double& dz_du) {
  const double d = 1.0 - one_plus_conic * c_per_mm * c_per_mm * u_mm2;
  if (!(d > 0.0)) return false;
  const double root = std::sqrt(d);
  // Horner on q(u) = sum_j a_j u^j; the polynomial is u q(u), its derivative q + u q'.
  double q = 0.0, dq = 0.0;
  for (int j = terms - 1; j >= 0; --j) {
    dq = dq * u_mm2 + q;
    q = q * u_mm2 + a[j];
  }
  const double z = c_per_mm * u_mm2 / (1.0 + root) + u_mm2 * q;
  const double slope = 0.5 * c_per_mm / root + q + u_mm2 * dq;
  if (!std::isfinite(z) || !std::isfinite(slope)) return false;
  z_mm = z;
  dz_du = slope;
  return true;
}

// The sag alone (mm); defined on the rim itself (D = 0, a hemisphere's edge), NaN beyond it.
inline double conic_sag(double c_per_mm, double one_plus_conic, const double* a, int terms, double u_mm2) {
  const double d = 1.0 - one_plus_conic * c_per_mm * c_per_mm * u_mm2;
  if (d < 0.0) return std::numeric_limits<double>::quiet_NaN();
  double q = 0.0;
  for (int j = terms - 1; j >= 0; --j) q = q * u_mm2 + a[j];
  return c_per_mm * u_mm2 / (1.0 + std::sqrt(d)) + u_mm2 * q;
}

// The largest radius (mm) the conic's sag is defined for: 1 / sqrt((1 + k) c^2) where that is
// positive (a sphere: |R|), else +infinity (a plane, a paraboloid, a hyperboloid).
inline double conic_max_radius_mm(double c_per_mm, double one_plus_conic) {
  const double kc2 = one_plus_conic * c_per_mm * c_per_mm;
  return kc2 > 0.0 ? 1.0 / std::sqrt(kc2) : std::numeric_limits<double>::infinity();
}

}  // namespace lensmith
