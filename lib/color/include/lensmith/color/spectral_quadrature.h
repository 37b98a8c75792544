// Spectrum -> linear Rec.709 by a wavelength quadrature: out = K * sum_i w_i s(lambda_i) M cmf(lambda_i),
// with M = kRec709FromXyz, cmf the CIE 1931 observer, midpoint nodes lambda_i and weights w_i (nm),
// and K (3x3) calibrated so that each basis function of the SpectralBasis integrates to its own
// unit RGB vector. Hence RGB -> spectrum -> RGB is the identity at the nodes and grey stays grey.
#pragma once

#include <cstddef>
#include <ostream>
#include <string>
#include <vector>

#include "lensmith/color/rgb.h"
#include "lensmith/color/spectral_basis.h"

namespace lensmith {

struct SpectralQuadratureOptions {
  int sample_count = 64;            // number of wavelengths N: 3 to 4096 (64 matches the lens tables)
  double min_wavelength_nm = 380.0;  // start of the range: 300 to 900 nm
  double max_wavelength_nm = 780.0;  // end of the range: above min_wavelength_nm, up to 900 nm

  void validate() const;  // throws OptionsError naming the field and the violated constraint
  std::string to_string() const;
  friend std::ostream& operator<<(std::ostream& os, const SpectralQuadratureOptions& o) { return os << o.to_string(); }
};

// One Monte-Carlo wavelength: the quadrature node drawn, with the probability of drawing it.
// rgb_weight = rgb_weights(index) / probability, so s(wavelength_nm) * rgb_weight is an unbiased
// estimate of the quadrature's RGB.
struct WavelengthSample {
  std::size_t index = 0;
  double wavelength_nm = 0.0;
  double probability = 0.0;       // discrete probability of this node (1 / N)
  double pdf_per_nm = 0.0;        // the same as a density over the wavelength range (1 / range)
  Rgb rgb_weight;                 // RGB per unit spectral value, divided by probability

  std::string to_string() const;
  friend std::ostream& operator<<(std::ostream& os, const WavelengthSample& s) { return os << s.to_string(); }
};

class SpectralQuadrature {
 public:
  // Throws OptionsError for invalid options and ComputationError if the basis cannot be
  // calibrated on these nodes (its 3x3 RGB matrix is singular).
  explicit SpectralQuadrature(const SpectralQuadratureOptions& options = {}, const SpectralBasis& basis = SpectralBasis{});

  const SpectralQuadratureOptions& options() const { return options_; }
  const SpectralBasis& basis() const { return basis_; }
  std::size_t size() const { return wavelengths_nm_.size(); }
  // Node i is the midpoint of the i-th of N equal strata: min + (i + 1/2) * range / N.
  const std::vector<double>& wavelengths_nm() const { return wavelengths_nm_; }
  // Quadrature weights in nm (range / N each).
  const std::vector<double>& weights_nm() const { return weights_nm_; }
  // K: the 3x3 that makes each basis function integrate to its unit RGB vector.
  const Matrix3& calibration() const { return calibration_; }
  // RGB contribution per unit spectral value at node i: w_i K M cmf(lambda_i). Throws
  // std::out_of_range for i >= size().
  const Rgb& rgb_weights(std::size_t i) const { return rgb_weights_.at(i); }

  // The RGB of the spectrum whose values at the nodes are spectrum_values (size() of them).
  // Throws ComputationError on a size mismatch.
  Rgb integrate(const std::vector<double>& spectrum_values) const;
  // RGB -> basis spectrum -> RGB through this quadrature; the identity to rounding.
  Rgb round_trip(const Rgb& rgb) const;

  // The Monte-Carlo sample for u in [0, 1): node floor(u N) (clamped to [0, N-1]). Feed
  // stratified u = (k + jitter) / N to visit every node once in N samples.
  WavelengthSample sample(double u) const;
  // The sample for node i (stratum i). Throws std::out_of_range for i >= size().
  WavelengthSample sample_at(std::size_t i) const;

  std::string to_string() const;
  friend std::ostream& operator<<(std::ostream& os, const SpectralQuadrature& q) { return os << q.to_string(); }

 private:
  SpectralQuadratureOptions options_;
  SpectralBasis basis_;
  std::vector<double> wavelengths_nm_;
  std::vector<double> weights_nm_;
  Matrix3 calibration_;
  std::vector<Rgb> rgb_weights_;
};

}  // namespace lensmith
