// RGB -> smooth spectrum: s(lambda) = r b_r(lambda) + g b_g(lambda) + b b_b(lambda) with three
// smooth, non-negative basis functions that sum to 1 at every wavelength (a partition of unity),
// built from two logistic steps: b_b = 1 - S_1, b_g = S_1 - S_2, b_r = S_2, with
// S_k(lambda) = 1 / (1 + exp(-(lambda - crossover_k) / width)). See docs/color.md.
#pragma once

#include <ostream>
#include <string>

#include "lensmith/color/rgb.h"

namespace lensmith {

struct SpectralBasisOptions {
  double blue_green_crossover_nm = 490.0;  // where b_b = b_g (for a wide green band): 400 to 700 nm
  double green_red_crossover_nm = 590.0;   // where b_g = b_r: above blue_green_crossover_nm, up to 700 nm
  double transition_width_nm = 12.0;       // logistic scale of each step (10-90 % over 4.4 widths): 1 to 100 nm

  void validate() const;  // throws OptionsError naming the field and the violated constraint
  std::string to_string() const;
  friend std::ostream& operator<<(std::ostream& os, const SpectralBasisOptions& o) { return os << o.to_string(); }
};

class SpectralBasis {
 public:
  // Throws OptionsError when the options are invalid.
  explicit SpectralBasis(const SpectralBasisOptions& options = {});

  const SpectralBasisOptions& options() const { return options_; }

  // (b_r, b_g, b_b) at wavelength_nm: each in [0, 1], and they sum to 1 (to rounding).
  Rgb basis_values(double wavelength_nm) const;

  // The smooth spectrum of a linear Rec.709 colour at wavelength_nm (same units as the RGB:
  // a grey (c, c, c) gives the flat spectrum c; a non-negative RGB a non-negative spectrum).
  double spectrum_value(const Rgb& rgb, double wavelength_nm) const;

  std::string to_string() const;
  friend std::ostream& operator<<(std::ostream& os, const SpectralBasis& b) { return os << b.to_string(); }

 private:
  SpectralBasisOptions options_;
};

}  // namespace lensmith
