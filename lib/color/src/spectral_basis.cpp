// Partition-of-unity RGB basis from two logistic steps (see spectral_basis.h and docs/color.md).
#include "lensmith/color/spectral_basis.h"

#include <cmath>
#include <sstream>

#include "lensmith/core/errors.h"
#include "lensmith/core/number_parsing.h"

namespace lensmith {

namespace {

// Logistic step 0 -> 1 centred on crossover_nm. Monotone in wavelength_nm, so S_1 >= S_2 holds
// in floating point as well and b_g never rounds below 0.
double step(double wavelength_nm, double crossover_nm, double width_nm) {
  return 1.0 / (1.0 + std::exp(-(wavelength_nm - crossover_nm) / width_nm));
}

}  // namespace

void SpectralBasisOptions::validate() const {
  // Negated comparisons so that NaN fails too.
  if (!(blue_green_crossover_nm >= 400.0 && blue_green_crossover_nm <= 700.0)) {
    throw OptionsError("SpectralBasisOptions::blue_green_crossover_nm = " + format_number(blue_green_crossover_nm) +
                       ": must be 400 to 700 nm");
  }
  if (!(green_red_crossover_nm > blue_green_crossover_nm && green_red_crossover_nm <= 700.0)) {
    throw OptionsError("SpectralBasisOptions::green_red_crossover_nm = " + format_number(green_red_crossover_nm) +
                       ": must be > blue_green_crossover_nm (" + format_number(blue_green_crossover_nm) + ") and <= 700 nm");
  }
  if (!(transition_width_nm >= 1.0 && transition_width_nm <= 100.0)) {
    throw OptionsError("SpectralBasisOptions::transition_width_nm = " + format_number(transition_width_nm) +
                       ": must be 1 to 100 nm");
  }
}

std::string SpectralBasisOptions::to_string() const {
  return "SpectralBasisOptions(blue_green_crossover_nm = " + format_number(blue_green_crossover_nm) +
         ", green_red_crossover_nm = " + format_number(green_red_crossover_nm) +
         ", transition_width_nm = " + format_number(transition_width_nm) + ")";
}

SpectralBasis::SpectralBasis(const SpectralBasisOptions& options) : options_(options) { options_.validate(); }

Rgb SpectralBasis::basis_values(double wavelength_nm) const {
  const double s1 = step(wavelength_nm, options_.blue_green_crossover_nm, options_.transition_width_nm);
  const double s2 = step(wavelength_nm, options_.green_red_crossover_nm, options_.transition_width_nm);
  return {s2, s1 - s2, 1.0 - s1};
}

double SpectralBasis::spectrum_value(const Rgb& rgb, double wavelength_nm) const {
  const Rgb b = basis_values(wavelength_nm);
  return rgb.r * b.r + rgb.g * b.g + rgb.b * b.b;
}

std::string SpectralBasis::to_string() const { return "SpectralBasis(" + options_.to_string() + ")"; }

}  // namespace lensmith
