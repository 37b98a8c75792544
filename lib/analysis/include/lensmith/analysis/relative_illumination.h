// Relative illumination and vignetting against field, for a uniform Lambertian object. The vignetting
// factor is the fraction of a square grid of rays in the unit entrance pupil that reaches the image.
// The relative illumination is the projected solid angle of the image-space beam, i.e. the area the
// passed rays cover in direction-cosine space (l, m) at the image (Rimmer, "Relative illumination
// calculations", Proc. SPIE 655, 99 (1986); the method of OpticStudio's Relative Illumination),
// normalised to its largest value over the field. It includes cos^4-type fall-off, vignetting, pupil
// aberration and distortion. A simpler estimate, vignetting x cos^4 of the image-space chief-ray
// angle, is given beside it.
#pragma once

#include <ostream>
#include <string>
#include <vector>

#include "lensmith/analysis/analysis_context.h"

namespace lensmith {

struct IlluminationOptions {
  int field_samples = 21;  // evenly spaced relative fields from 0 to 1, 2 to 1001
  int pupil_grid = 64;     // grid cells across the pupil diameter, 8 to 1024
  void validate() const;   // throws OptionsError
};

struct IlluminationPoint {
  double relative_field = 0.0;
  double field_value = 0.0;
  std::size_t rays_in_pupil = 0;      // grid points inside the unit pupil
  std::size_t rays_passed = 0;        // of those, reaching the image plane
  double vignetting_factor = 0.0;     // rays_passed / rays_in_pupil
  double projected_solid_angle_sr = 0.0;  // of the image-space beam, sr (direction-cosine area)
  double relative_illumination = 0.0;     // projected solid angle / its maximum over the field
  double chief_ray_angle_deg = 0.0;       // image-space chief-ray angle to the axis
  double cos4_estimate = 0.0;             // vignetting / on-axis vignetting x cos^4(chief_ray_angle)
};

struct RelativeIllumination {
  std::string lens_name;
  double wavelength_nm = 0.0;  // reference wavelength (relative illumination is monochromatic)
  std::string field_unit;
  int pupil_grid = 0;
  std::vector<IlluminationPoint> points;
  std::string to_string() const;
  friend std::ostream& operator<<(std::ostream& os, const RelativeIllumination& r) { return os << r.to_string(); }
};

RelativeIllumination compute_relative_illumination(const AnalysisContext& context, const IlluminationOptions& options = {});

}  // namespace lensmith
