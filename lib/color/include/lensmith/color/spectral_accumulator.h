// Running Monte-Carlo estimate of a pixel's RGB from wavelength samples: the mean of
// spectral_value * WavelengthSample::rgb_weight, whose expectation is the quadrature's RGB.
#pragma once

#include <cstddef>
#include <ostream>
#include <string>

#include "lensmith/color/spectral_quadrature.h"

namespace lensmith {

class SpectralAccumulator {
 public:
  // Add one sample: spectral_value is s(sample.wavelength_nm) as carried by the traced ray.
  void add(const WavelengthSample& sample, double spectral_value);
  std::size_t count() const { return count_; }
  // The mean estimate; RGB(0, 0, 0) before the first sample.
  Rgb mean() const;

  std::string to_string() const;  // "SpectralAccumulator(n = 64, mean RGB(...))"
  friend std::ostream& operator<<(std::ostream& os, const SpectralAccumulator& a) { return os << a.to_string(); }

 private:
  Rgb sum_;
  std::size_t count_ = 0;
};

}  // namespace lensmith
