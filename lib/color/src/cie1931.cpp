// CIE 1931 2-degree observer by Wyman, Sloan & Shirley (JCGT 2(2), 2013), eq. 2: the multi-lobe
// fit, each lobe a Gaussian with different widths left and right of its centre.
#include "lensmith/color/cie1931.h"

#include <cmath>
#include <sstream>

#include "lensmith/core/errors.h"

namespace lensmith {

namespace {

// g(lambda; mu, sigma_1, sigma_2) = exp(-1/2 ((lambda - mu) / sigma)^2), sigma = sigma_1 below mu
// and sigma_2 from mu up (Wyman et al. 2013, eq. 1 and 2).
double lobe(double wavelength_nm, double mu_nm, double sigma_below_nm, double sigma_above_nm) {
  const double t = (wavelength_nm - mu_nm) / (wavelength_nm < mu_nm ? sigma_below_nm : sigma_above_nm);
  return std::exp(-0.5 * t * t);
}

}  // namespace

Xyz cie1931_cmf(double wavelength_nm) {
  const double l = wavelength_nm;
  return {
      1.056 * lobe(l, 599.8, 37.9, 31.0) + 0.362 * lobe(l, 442.0, 16.0, 26.7) - 0.065 * lobe(l, 501.1, 20.4, 26.2),
      0.821 * lobe(l, 568.8, 46.9, 40.5) + 0.286 * lobe(l, 530.9, 16.3, 31.1),
      1.217 * lobe(l, 437.0, 11.8, 36.0) + 0.681 * lobe(l, 459.0, 26.0, 13.8),
  };
}

Chromaticity chromaticity(const Xyz& xyz) {
  const double sum = xyz.x + xyz.y + xyz.z;
  if (!(sum > 0.0)) {
    throw ComputationError("chromaticity of " + xyz.to_string() + ": X + Y + Z must be > 0");
  }
  return {xyz.x / sum, xyz.y / sum};
}

std::string Xyz::to_string() const {
  std::ostringstream os;
  os.precision(10);
  os << "XYZ(" << x << ", " << y << ", " << z << ")";
  return os.str();
}

std::string Chromaticity::to_string() const {
  std::ostringstream os;
  os.precision(10);
  os << "xy(" << x << ", " << y << ")";
  return os.str();
}

}  // namespace lensmith
