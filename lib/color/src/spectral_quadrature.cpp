// Midpoint wavelength quadrature with the calibrated spectrum -> Rec.709 map (see the header and
// docs/color.md for why the calibration makes every RGB, and grey in particular, round-trip).
#include "lensmith/color/spectral_quadrature.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "lensmith/color/cie1931.h"
#include "lensmith/core/errors.h"
#include "lensmith/core/number_parsing.h"

namespace lensmith {

namespace {

std::array<double, 3> rec709_unscaled(double wavelength_nm) {
  const Xyz c = cie1931_cmf(wavelength_nm);
  return kRec709FromXyz * std::array<double, 3>{c.x, c.y, c.z};
}

}  // namespace

void SpectralQuadratureOptions::validate() const {
  if (sample_count < 3 || sample_count > 4096) {
    throw OptionsError("SpectralQuadratureOptions::sample_count = " + std::to_string(sample_count) +
                       ": must be 3 to 4096 (three colour channels need at least three wavelengths)");
  }
  if (!(min_wavelength_nm >= 300.0 && min_wavelength_nm <= 900.0)) {
    throw OptionsError("SpectralQuadratureOptions::min_wavelength_nm = " + format_number(min_wavelength_nm) +
                       ": must be 300 to 900 nm");
  }
  if (!(max_wavelength_nm > min_wavelength_nm && max_wavelength_nm <= 900.0)) {
    throw OptionsError("SpectralQuadratureOptions::max_wavelength_nm = " + format_number(max_wavelength_nm) +
                       ": must be > min_wavelength_nm (" + format_number(min_wavelength_nm) + ") and <= 900 nm");
  }
}

std::string SpectralQuadratureOptions::to_string() const {
  return "SpectralQuadratureOptions(sample_count = " + std::to_string(sample_count) +
         ", min_wavelength_nm = " + format_number(min_wavelength_nm) + ", max_wavelength_nm = " + format_number(max_wavelength_nm) + ")";
}

std::string WavelengthSample::to_string() const {
  return "WavelengthSample(index = " + std::to_string(index) + ", wavelength_nm = " + format_number(wavelength_nm) +
         ", probability = " + format_number(probability) + ", pdf_per_nm = " + format_number(pdf_per_nm) +
         ", rgb_weight = " + rgb_weight.to_string() + ")";
}

SpectralQuadrature::SpectralQuadrature(const SpectralQuadratureOptions& options, const SpectralBasis& basis)
    : options_(options), basis_(basis) {
  options_.validate();
  const auto n = static_cast<std::size_t>(options_.sample_count);
  const double range_nm = options_.max_wavelength_nm - options_.min_wavelength_nm;
  const double step_nm = range_nm / static_cast<double>(n);
  wavelengths_nm_.resize(n);
  weights_nm_.assign(n, step_nm);
  for (std::size_t i = 0; i < n; ++i) {
    wavelengths_nm_[i] = options_.min_wavelength_nm + (static_cast<double>(i) + 0.5) * step_nm;
  }

  // A(:, j) = sum_i w_i b_j(lambda_i) M cmf(lambda_i): the uncalibrated RGB of basis function j.
  Matrix3 a;
  std::vector<std::array<double, 3>> unscaled(n);
  for (std::size_t i = 0; i < n; ++i) {
    unscaled[i] = rec709_unscaled(wavelengths_nm_[i]);
    const Rgb b = basis_.basis_values(wavelengths_nm_[i]);
    for (int row = 0; row < 3; ++row)
      for (int col = 0; col < 3; ++col) a.m[row][col] += weights_nm_[i] * b[col] * unscaled[i][row];
  }
  try {
    calibration_ = a.inverse();
  } catch (const ComputationError& e) {
    throw ComputationError("SpectralQuadrature: cannot calibrate " + basis_.to_string() + " on " +
                           options_.to_string() + ": " + e.what());
  }

  rgb_weights_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const auto v = calibration_ * unscaled[i];
    rgb_weights_[i] = weights_nm_[i] * Rgb{v[0], v[1], v[2]};
  }
}

Rgb SpectralQuadrature::integrate(const std::vector<double>& spectrum_values) const {
  if (spectrum_values.size() != size()) {
    throw ComputationError("SpectralQuadrature::integrate: " + std::to_string(spectrum_values.size()) +
                           " spectrum values for " + std::to_string(size()) + " wavelengths");
  }
  Rgb out;
  for (std::size_t i = 0; i < size(); ++i) out += spectrum_values[i] * rgb_weights_[i];
  return out;
}

Rgb SpectralQuadrature::round_trip(const Rgb& rgb) const {
  Rgb out;
  for (std::size_t i = 0; i < size(); ++i) out += basis_.spectrum_value(rgb, wavelengths_nm_[i]) * rgb_weights_[i];
  return out;
}

WavelengthSample SpectralQuadrature::sample(double u) const {
  const double scaled = std::floor(u * static_cast<double>(size()));
  // Clamp so that u = 1, rounding just below 0, or NaN still lands on a valid node.
  std::size_t i = 0;
  if (scaled >= static_cast<double>(size())) {
    i = size() - 1;
  } else if (scaled > 0.0) {
    i = static_cast<std::size_t>(scaled);
  }
  return sample_at(i);
}

WavelengthSample SpectralQuadrature::sample_at(std::size_t i) const {
  if (i >= size()) {
    throw std::out_of_range("SpectralQuadrature::sample_at(" + std::to_string(i) + "): only " +
                            std::to_string(size()) + " wavelengths");
  }
  const double probability = 1.0 / static_cast<double>(size());
  WavelengthSample s;
  s.index = i;
  s.wavelength_nm = wavelengths_nm_[i];
  s.probability = probability;
  s.pdf_per_nm = 1.0 / (options_.max_wavelength_nm - options_.min_wavelength_nm);
  s.rgb_weight = (1.0 / probability) * rgb_weights_[i];
  return s;
}

std::string SpectralQuadrature::to_string() const {
  return "SpectralQuadrature(" + options_.to_string() + ", " + basis_.to_string() + ", K = " +
         calibration_.to_string() + ")";
}

}  // namespace lensmith
