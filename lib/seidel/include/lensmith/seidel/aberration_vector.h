// Born & Wolf's third-order aberration vector (Principles of Optics, 7th ed., sec. 5.3-5.5), the
// form Asberg's bokeh method applies (Marsicano 2023, eq. 3.35):
//   dp_x = B rho^3 sin(t) - 2 F y0 rho^2 sin(t) cos(t) + D y0^2 rho sin(t)
//   dp_y = B rho^3 cos(t) - F y0 rho^2 (1 + 2 cos^2(t)) + (2C + D) y0^2 rho cos(t) - E y0^3
// with (rho, t) polar coordinates on the pupil (t measured from +y, the meridional direction) and y0
// the field coordinate. lensmith derives B..F from Welford's sums rather than transcribing Born &
// Wolf's per-surface formulas (the thesis's OCR copy has typos); with k = 1 / (2 n' u'):
//   B = k S_I, C = k S_III, D = k (S_III + S_IV), E = -k S_V, F = -k S_II     (mm)
// in lensmith's normalisation: rho = 1 at the pupil edge, y0 = 1 at the field the sums were computed
// for, dp in mm on the Gaussian image plane. The exact tracer checks the result (tests/seidel/).
#pragma once

#include <ostream>
#include <string>

#include "lensmith/seidel/seidel_analysis.h"

namespace lensmith {

// Transverse displacement from the Gaussian image point, mm (x sagittal, y meridional).
struct ImageDisplacement {
  double x_mm = 0.0;
  double y_mm = 0.0;
};

// Born & Wolf's units (sec. 5.3): object-side field y0_BW = Y0 / D0 (D0 = distance from the object
// plane to the entrance pupil; for an object at infinity y0_BW = tan of the field angle), pupil
// radius rho_BW in mm on the entrance pupil (lambda0 = 1 mm), and dp_BW = (P1 - P1*) / D1, an angle
// (D1 = distance from the exit pupil to the Gaussian image plane). Coefficients in those units.
struct BornWolfUnits {
  double B = 0.0, C = 0.0, D = 0.0, E = 0.0, F = 0.0;
  double D0_mm = 0.0;  // object plane to entrance pupil (+inf for an object at infinity)
  double D1_mm = 0.0;  // exit pupil to Gaussian image plane
  std::string to_string() const;
};

struct AberrationCoefficients {
  double B_mm = 0.0;  // spherical aberration
  double C_mm = 0.0;  // astigmatism
  double D_mm = 0.0;  // field curvature (with C: sagittal focus)
  double E_mm = 0.0;  // distortion
  double F_mm = 0.0;  // coma
  // What rho = 1 and y0 = 1 mean: the entrance-pupil radius and the maximum field used.
  double pupil_radius_mm = 0.0;       // entrance-pupil radius
  double max_field_tangent = 0.0;     // Y0max / D0, or tan(angle) for an object at infinity
  double exit_pupil_to_image_mm = 0.0;      // D1
  double object_to_entrance_pupil_mm = 0.0; // D0 (+inf at infinity)

  // From a Seidel analysis (its aperture, field, wavelength and object distance).
  static AberrationCoefficients from(const SeidelAnalysis& seidel);

  // The aberration vector at normalised pupil point (rho, theta) and field y0, mm.
  ImageDisplacement displacement(double rho, double theta_rad, double y0) const;
  // The same coefficients in Born & Wolf's units (see BornWolfUnits).
  BornWolfUnits in_born_wolf_units() const;

  std::string to_string() const;
  friend std::ostream& operator<<(std::ostream& os, const AberrationCoefficients& c) { return os << c.to_string(); }
};

}  // namespace lensmith
