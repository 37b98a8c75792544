// Published lens designs built in code straight from the book or paper tables (not from lenses/),
// so tests and benchmarks compare against the printed numbers and can check the shipped files.
#pragma once

#include <optional>

#include "lensmith/prescription/prescription.h"

namespace lensmith::testing {

// A surface with its material resolved against the built-in glass catalogues.
// radius_mm = +/-infinity makes a plane.
Surface make_surface(double radius_mm, double thickness_mm, const MaterialSpec& material,
                     std::optional<double> semi_diameter_mm = {});

// W. J. Smith, Modern Optical Engineering, 4th ed., ch. 6 (REFERENCE-VALUES.md section 1): model
// glasses from Smith's n_d and n_F - n_C, EPD 29.2 mm, chief-ray slope 0.21, stop at surface 5.
Prescription smith_cooke_triplet();

// Sasian triplet, ray-optics docs/source/examples/SasianTriplet (REFERENCE-VALUES.md section 2):
// Schott N-LAK9 and N-SF5, EPD 12.5 mm, half field 20 degrees, stop at surface 3.
Prescription sasian_triplet();

// Angenieux double Gauss, US 2,701,982 (1953), as in the lentil database entry 0001, with the
// patent's glass types from the Schott catalogue; 15 surfaces, aperture floating by the iris.
Prescription angenieux_double_gauss();

// A perfect imager: a Cartesian ellipsoid of index n = 1.5 (conic -1/n^2, R = 50 mm) focusing a parallel
// 20-mm beam without aberration at n R / (n - 1) = 150 mm inside the glass (Born & Wolf, Principles of
// Optics, sec. 4.2.3), its stop on the surface; the image plane `defocus_mm` behind that focus; the d line.
struct CartesianEllipsoid {
  static constexpr double kIndex = 1.5;
  static constexpr double kRadiusMm = 50.0;
  static constexpr double kFocusMm = kIndex * kRadiusMm / (kIndex - 1.0);
};
Prescription cartesian_ellipsoid(double defocus_mm);

}  // namespace lensmith::testing
