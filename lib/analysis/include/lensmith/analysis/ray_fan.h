// Transverse ray-aberration fans (Welford, Aberrations of Optical Systems, sec. 4.8 and ch. 9):
// the tangential fan ey(py) = y - y_chief for rays along the pupil's y axis and the sagittal fan
// ex(px) = x - x_chief along its x axis, measured on the image plane against the chief ray of the
// reference (primary) wavelength, per field and wavelength (OpticStudio "Ray Aberration" fan).
#pragma once

#include <ostream>
#include <string>
#include <vector>

#include "lensmith/analysis/analysis_context.h"

namespace lensmith {

struct RayFanOptions {
  int samples = 41;        // pupil points from -1 to 1 on each axis, odd (so py = 0 is traced), 3 to 1001
  void validate() const;   // throws OptionsError
};

struct FanSample {
  double pupil = 0.0;              // py (tangential) or px (sagittal), normalised
  RayStatus status = RayStatus::Ok;
  int surface = 0;                 // where the ray died, 0 when ok
  double error_mm = 0.0;           // ey or ex on the image plane, mm; NaN when the ray died
  bool ok() const { return status == RayStatus::Ok; }
};

struct FanCurve {
  double wavelength_nm = 0.0;
  std::vector<FanSample> tangential;  // ey = y - y_chief against py
  std::vector<FanSample> sagittal;    // ex = x - x_chief against px
};

struct FieldFan {
  double relative_field = 0.0;
  double field_value = 0.0;
  std::string field_label;
  ImagePoint chief;               // reference: chief ray of the reference wavelength
  std::vector<FanCurve> curves;   // per wavelength
};

struct RayFan {
  std::string lens_name;
  std::vector<double> wavelengths_nm;
  double reference_wavelength_nm = 0.0;
  std::string field_unit;
  double image_plane_z_mm = 0.0;
  std::vector<FieldFan> fields;
  // Largest |error| over every passed sample, mm (sets a common plot scale); 0 when none passed.
  double max_abs_error_mm() const;
  std::string to_string() const;  // per field: py, ey per wavelength; px, ex per wavelength (um)
  friend std::ostream& operator<<(std::ostream& os, const RayFan& f) { return os << f.to_string(); }
};

// Throws ComputationError when a field's chief ray cannot be traced.
RayFan compute_ray_fan(const AnalysisContext& context, const RayFanOptions& options = {});

}  // namespace lensmith
