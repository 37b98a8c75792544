// Real-ray distortion against field: D = (y_real - y_paraxial) / y_paraxial * 100 %, where y_real is
// where the real chief ray of the reference wavelength meets the image plane (the prescription's, or
// the paraxial focus with ImagePlane::ParaxialFocus) and y_paraxial is the paraxial image height of
// the same field point: n tan(theta) f for an object at infinity ("F-Tan(Theta)" distortion, as
// OpticStudio's Field Curvature and Distortion plot), or m h for a finite object (Welford sec. 9.2).
#pragma once

#include <ostream>
#include <string>
#include <vector>

#include "lensmith/analysis/analysis_context.h"

namespace lensmith {

struct DistortionOptions {
  int field_samples = 21;  // evenly spaced relative fields from 0 to 1, 2 to 1001
  // These relative fields (each in [0, 1]) instead of the even samples, when not empty.
  std::vector<double> relative_fields;
  void validate() const;   // throws OptionsError
};

struct DistortionPoint {
  double relative_field = 0.0;
  double field_value = 0.0;          // in the field unit
  double real_height_mm = 0.0;       // y of the real chief ray on the image plane
  double paraxial_height_mm = 0.0;   // paraxial image height of this field point
  // On axis: the limit as the field goes to 0 (0 when the image plane is the paraxial focus; else
  // the image plane's defocus seen along the chief ray, a constant percentage). Heights are 0 there.
  double distortion_percent = 0.0;
};

struct DistortionCurve {
  std::string lens_name;
  double wavelength_nm = 0.0;        // the reference wavelength
  std::string field_unit;
  double image_plane_z_mm = 0.0;
  std::string paraxial_reference;    // "f tan(theta), f = ... mm" or "m h, m = ..."
  std::vector<DistortionPoint> points;
  std::string to_string() const;
  friend std::ostream& operator<<(std::ostream& os, const DistortionCurve& d) { return os << d.to_string(); }
};

// Throws OptionsError when the lens has no field and none was given, ComputationError when a chief
// ray cannot be traced.
DistortionCurve compute_distortion(const AnalysisContext& context, const DistortionOptions& options = {});

}  // namespace lensmith
