// The CIE 1931 2-degree standard observer as the multi-lobe piecewise-Gaussian fit of C. Wyman,
// P.-P. Sloan, P. Shirley, "Simple Analytic Approximations to the CIE XYZ Color Matching
// Functions", JCGT 2(2), 2013, eq. 2; coefficients and their provenance in docs/color.md.
#pragma once

#include <ostream>
#include <string>

namespace lensmith {

// CIE 1931 tristimulus values (or colour-matching-function values at one wavelength).
struct Xyz {
  double x = 0.0;
  double y = 0.0;
  double z = 0.0;

  std::string to_string() const;  // "XYZ(0.5, 1, 0.25)"
  friend std::ostream& operator<<(std::ostream& os, const Xyz& v) { return os << v.to_string(); }
};

// CIE xy chromaticity: x = X / (X + Y + Z), y = Y / (X + Y + Z).
struct Chromaticity {
  double x = 0.0;
  double y = 0.0;

  std::string to_string() const;  // "xy(0.3333, 0.3333)"
  friend std::ostream& operator<<(std::ostream& os, const Chromaticity& c) { return os << c.to_string(); }
};

// x-bar, y-bar, z-bar at wavelength_nm (vacuum wavelength in nanometres), by Wyman et al.'s
// multi-lobe fit. Defined for every wavelength; the fit is meant for 360 to 830 nm and decays to
// zero outside it. Values are dimensionless, with y-bar(555 nm) close to 1.
Xyz cie1931_cmf(double wavelength_nm);

// Chromaticity of a tristimulus value. Throws ComputationError when X + Y + Z is not > 0.
Chromaticity chromaticity(const Xyz& xyz);

}  // namespace lensmith
