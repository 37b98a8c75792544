// The wavefront of real rays: the optical path difference (OPD) against the reference sphere at the exit
// pupil, per field and wavelength, as OpticStudio's OPD fan and Wavefront Map give it (Welford,
// Aberrations of Optical Systems, ch. 5 and 9; docs/wavefront.md).
//
// Reference sphere: centred on the image plane where the reference (primary) wavelength's chief ray meets
// it, through the point where this wavelength's chief ray crosses the paraxial exit pupil's plane (so
// lateral colour shows as tilt and axial colour as defocus, as in OpticStudio). Each ray is followed back
// from the image plane to the sphere; its OPD is the chief ray's optical path to the sphere minus its own,
// so that W > 0 where the wavefront runs ahead of the sphere: with it the transverse error is
// e_y = -(R / n') dW/dy (Welford eq. 5.9), and an undercorrected lens's spherical aberration is positive,
// as its Seidel W040 = S_I / 8 is. Values are in waves of the ray's own wavelength.
#pragma once

#include <ostream>
#include <string>
#include <vector>

#include "lensmith/analysis/analysis_context.h"
#include "lensmith/analysis/zernike.h"

namespace lensmith {

struct WavefrontOptions {
  int grid = 64;            // pupil samples across the square around the unit pupil (8 to 1024)
  int fan_samples = 41;     // points of each OPD fan from -1 to 1, odd (3 to 1001)
  ZernikeOrdering ordering = ZernikeOrdering::Fringe;
  int zernike_terms = 37;   // terms fitted (1 to the ordering's maximum: Fringe 37, Standard 231)
  // Fill OpdSample::amplitude with the square root of each ray's uncoated Fresnel transmittance
  // (lensmith/trace/fresnel.h), for the MTF's and PSF's pupil amplitude. Off: amplitude 1 (OpticStudio's
  // FFT MTF without polarisation).
  bool transmittance = false;
  void validate() const;    // throws OptionsError
};

// OPD (waves) at one pupil point; NaN where the ray died.
struct OpdSample {
  double px = 0.0, py = 0.0;  // normalised pupil coordinates
  double opd_waves = 0.0;
  RayStatus status = RayStatus::Ok;
  double x_mm = 0.0, y_mm = 0.0;  // where the ray meets the image plane, global frame (the geometric MTF's spot)
  double amplitude = 1.0;         // the pupil function's modulus here: 1, or sqrt(transmittance) (WavefrontOptions)
};

struct WavefrontMap {
  double relative_field = 0.0;
  double field_value = 0.0;
  std::string field_label;
  double wavelength_nm = 0.0;
  ImagePoint reference;               // the reference sphere's centre (reference wavelength's chief ray)
  double reference_radius_mm = 0.0;   // its radius, exit pupil to image (> 0: image after the pupil)
  int grid = 0;
  std::vector<OpdSample> map;         // grid x grid, row-major, rows from py = -1 (bottom) up; points outside the unit pupil absent (NaN)
  std::vector<OpdSample> tangential;  // OPD against py (px = 0)
  std::vector<OpdSample> sagittal;    // OPD against px (py = 0)
  double rms_waves = 0.0;             // RMS over the passed pupil points, piston (the mean) removed
  double rms_tilt_removed_waves = 0.0;  // also without tilt (referenced to the best-fit image point)
  double pv_waves = 0.0;              // peak to valley
  std::size_t samples = 0;            // passed pupil points of the map
  RayLossCount lost;                  // the map's points whose rays died
  std::vector<double> zernike;        // coefficients (waves) of terms 1..WavefrontOptions::zernike_terms
};

struct Wavefront {
  std::string lens_name;
  std::vector<double> wavelengths_nm;
  double reference_wavelength_nm = 0.0;
  double image_plane_z_mm = 0.0;
  double exit_pupil_z_mm = 0.0;   // paraxial, reference wavelength
  ZernikeOrdering ordering = ZernikeOrdering::Fringe;
  std::vector<WavefrontMap> maps;  // per field, then per wavelength
  std::string to_string() const;   // per field and wavelength: RMS, P-V, the Zernike coefficients
  friend std::ostream& operator<<(std::ostream& os, const Wavefront& w) { return os << w.to_string(); }
};

// Throws ComputationError when a field's chief ray cannot be traced, when the exit pupil lies on the image
// plane (no reference sphere), or when too few rays pass for the Zernike fit.
Wavefront compute_wavefront(const AnalysisContext& context, const WavefrontOptions& options = {});

}  // namespace lensmith
