// Tangential and sagittal field curves (astigmatic focal surfaces) against field, as focus shifts
// along z from the image plane, mm. Method: finite differences of real rays around the chief ray (the
// real-ray form of Coddington's equations; Welford sec. 9.4, Kingslake, Lens Design Fundamentals,
// ch. 4): two rays at pupil (0, +d) and (0, -d) meet in the meridional plane at the tangential focus;
// two rays at (+d, 0) and (-d, 0) meet the meridional plane at the sagittal focus. The symmetric pair
// cancels the odd (coma-like) terms, so the error is O(d^2). OpticStudio uses the chief ray and one
// ray at Py = 0.001 instead ("How does the field curvature and distortion calculate the tan and sag
// value", Zemax community, 2022).
#pragma once

#include <ostream>
#include <string>
#include <vector>

#include "lensmith/analysis/analysis_context.h"

namespace lensmith {

struct FieldCurveOptions {
  int field_samples = 21;     // evenly spaced relative fields from 0 to 1, 2 to 1001
  double pupil_step = 1e-3;   // d, normalised pupil units, in (0, 0.1]
  void validate() const;      // throws OptionsError
};

struct FieldCurvePoint {
  double relative_field = 0.0;
  double field_value = 0.0;
  // Focus minus image plane along z, mm (> 0: the focus lies behind the image plane). NaN when the
  // rays could not be traced or are parallel.
  double tangential_mm = 0.0;
  double sagittal_mm = 0.0;
};

struct FieldCurveSet {
  double wavelength_nm = 0.0;
  std::vector<FieldCurvePoint> points;
};

struct FieldCurves {
  std::string lens_name;
  std::string field_unit;
  double image_plane_z_mm = 0.0;
  double paraxial_focus_z_mm = 0.0;   // paraxial image of the object plane, reference wavelength
  double pupil_step = 0.0;
  std::vector<FieldCurveSet> curves;  // per wavelength
  std::string to_string() const;
  friend std::ostream& operator<<(std::ostream& os, const FieldCurves& f) { return os << f.to_string(); }
};

FieldCurves compute_field_curves(const AnalysisContext& context, const FieldCurveOptions& options = {});

}  // namespace lensmith
