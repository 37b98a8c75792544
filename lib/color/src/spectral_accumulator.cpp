// Mean of per-wavelength RGB contributions (see spectral_accumulator.h).
#include "lensmith/color/spectral_accumulator.h"

namespace lensmith {

void SpectralAccumulator::add(const WavelengthSample& sample, double spectral_value) {
  sum_ += spectral_value * sample.rgb_weight;
  ++count_;
}

Rgb SpectralAccumulator::mean() const {
  if (count_ == 0) return {};
  return (1.0 / static_cast<double>(count_)) * sum_;
}

std::string SpectralAccumulator::to_string() const {
  return "SpectralAccumulator(n = " + std::to_string(count_) + ", mean " + mean().to_string() + ")";
}

}  // namespace lensmith
