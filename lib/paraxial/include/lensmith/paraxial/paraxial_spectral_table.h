// First-order parameters of a lens sampled over wavelength, for renderers that need them per
// wavelength: 64 samples from 380 to 780 nm by default, cheap to interpolate.
#pragma once

#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "lensmith/prescription/prescription.h"

namespace lensmith {

struct ParaxialSample {
  double wavelength_nm = 0.0;
  double efl_mm = 0.0;
  double bfl_mm = 0.0;
  double ffl_mm = 0.0;
  double z_front_principal_mm = 0.0;
  double z_rear_principal_mm = 0.0;
  double z_entrance_pupil_mm = 0.0;
  double entrance_pupil_diameter_mm = 0.0;
  double z_exit_pupil_mm = 0.0;
  double exit_pupil_diameter_mm = 0.0;
  double image_distance_mm = 0.0;  // last vertex to the paraxial image of the object plane
  double magnification = 0.0;
  bool extrapolated = false;       // some glass was evaluated outside its catalogue range
};

// Linear interpolation between two samples, t in [0, 1] (0 gives `a`); `extrapolated` is set when a
// sample that contributes (non-zero weight) was extrapolated.
ParaxialSample interpolate(const ParaxialSample& a, const ParaxialSample& b, double t);

struct SpectralTableOptions {
  double min_wavelength_nm = 380.0;
  double max_wavelength_nm = 780.0;
  int samples = 64;                           // >= 2, evenly spaced, both ends included
  std::optional<double> object_distance_mm;   // empty = the prescription's
  void validate() const;                      // throws OptionsError naming the field
};

class ParaxialSpectralTable {
 public:
  ParaxialSpectralTable(const Prescription& lens, const SpectralTableOptions& options = {});
  const std::vector<ParaxialSample>& samples() const { return samples_; }
  // Linear interpolation in wavelength; clamps outside the sampled range.
  ParaxialSample at(double wavelength_nm) const;
  std::string to_string() const;

 private:
  std::vector<ParaxialSample> samples_;
};

}  // namespace lensmith
