// Longitudinal chromatic focal shift: the paraxial image distance (last vertex to the paraxial image
// of the object plane) at each wavelength minus the one at the reference wavelength, mm. Paraxial,
// as OpticStudio's "Chromatic Focal Shift" plot; a real marginal-zone focus would add spherochromatism.
#pragma once

#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "lensmith/prescription/prescription.h"

namespace lensmith {

struct FocalShiftOptions {
  int samples = 41;                    // evenly spaced wavelengths, 2 to 10001
  std::optional<double> min_nm;        // default: the shortest analysed wavelength
  std::optional<double> max_nm;        // default: the longest (both in (100, 20000) nm)
  // Analysed wavelengths (added to the samples); empty = the prescription's.
  std::vector<double> wavelengths_nm;
  void validate() const;               // throws OptionsError
};

struct FocalShiftPoint {
  double wavelength_nm = 0.0;
  double image_distance_mm = 0.0;  // last vertex to the paraxial image
  double shift_mm = 0.0;           // image_distance_mm minus the reference's (> 0: focus further back)
  bool extrapolated = false;       // a glass was evaluated outside its catalogue range
};

struct ChromaticFocalShift {
  std::string lens_name;
  double reference_wavelength_nm = 0.0;
  double reference_image_distance_mm = 0.0;
  std::vector<FocalShiftPoint> points;  // sorted by wavelength
  // max(shift) - min(shift) over the samples, mm ("maximum focal shift range" in OpticStudio).
  double range_mm() const;
  std::string to_string() const;
  friend std::ostream& operator<<(std::ostream& os, const ChromaticFocalShift& c) { return os << c.to_string(); }
};

// The reference wavelength is the prescription's primary when it is analysed, else the first.
// Throws OptionsError, ComputationError (afocal lens or an image at infinity).
ChromaticFocalShift compute_chromatic_focal_shift(const Prescription& lens, const FocalShiftOptions& options = {});

}  // namespace lensmith
