// The diffraction MTF (and Strehl ratio) of real rays by FFT of the pupil function (Goodman, Introduction
// to Fourier Optics, sec. 6.3-6.4; OpticStudio's "FFT MTF"): the pupil function P = A exp(2 pi i W) on the
// wavefront's pupil grid (A = 1 where the ray passes, or the root of its Fresnel transmittance with
// `transmittance`; 0 where it dies or outside the pupil; W the OPD in
// waves, lensmith/analysis/wavefront.h), zero-padded, and the optical transfer function as its
// autocorrelation, computed as the inverse transform of |FFT(P)|^2. A pupil sample step dp (mm, on the
// paraxial exit pupil, whose radius the unit pupil coordinate stands for) is a spatial frequency step
// dp / (lambda R) in cycles/mm, R the reference sphere's radius: the cutoff 2 r_XP / (lambda R) is
// 1 / (lambda N_w). Polychromatic curves are the wavelengths' OTFs averaged with the given weights (equal
// by default: lensmith's prescriptions carry no wavelength weights) at common frequencies, and the
// polychromatic Strehl ratio the same average of the wavelengths' (each PSF's peak over its aberration-free peak). Tangential: frequencies along y (the field's direction);
// sagittal: along x.
//
// FFT: Eigen's FFT module (unsupported/Eigen/FFT, kissfft underneath), which Eigen 3.4 already brings: no
// new dependency, and a 256 x 256 transform takes milliseconds; FFTW would be faster for large grids.
#pragma once

#include <ostream>
#include <string>
#include <vector>

#include "lensmith/analysis/analysis_context.h"

namespace lensmith {

struct MtfOptions {
  int pupil_samples = 64;          // pupil grid across the unit pupil (16 to 512)
  int padding = 4;                 // transform size = pupil_samples x padding, rounded up to a power of two (2 to 16)
  int frequency_samples = 51;      // points of each curve from 0 to max_frequency (2 to 1001)
  double max_frequency_per_mm = 0.0;  // 0: the diffraction cutoff 1 / (lambda_min N_w) of the shortest wavelength
  // The pupil's amplitude from each ray's uncoated Fresnel transmittance (WavefrontOptions::transmittance):
  // an apodisation. Off: amplitude 1 wherever a ray passes (OpticStudio's default, polarisation off).
  bool transmittance = false;
  // Each analysed wavelength's weight in the polychromatic OTF, Strehl ratio and geometric MTF, one per
  // wavelength (>= 0, normalised to sum 1), as a lens file's wavelength weights; empty: equal weights.
  // The count is checked against the context's wavelengths (OptionsError).
  std::vector<double> wavelength_weights;
  void validate() const;           // throws OptionsError
};

struct MtfCurve {
  double relative_field = 0.0;
  double field_value = 0.0;
  std::string field_label;
  std::vector<double> tangential;   // per frequency, polychromatic
  std::vector<double> sagittal;
  std::vector<double> diffraction_limit;  // an aberration-free pupil of the same shape (tangential)
  // The geometric MTF for comparison (compute_mtf only): |mean of exp(2 pi i f y)| over the landing points
  // of the pupil grid's rays (Smith, Modern Optical Engineering, sec. 11.8), wavelengths averaged as above.
  std::vector<double> geometric_tangential;
  std::vector<double> geometric_sagittal;
  double strehl = 0.0;              // the mean over wavelengths of the PSF's peak over the aberration-free one's
};

struct Mtf {
  std::string lens_name;
  std::vector<double> wavelengths_nm;
  std::vector<double> frequencies_per_mm;
  double cutoff_per_mm = 0.0;            // 1 / (lambda N_w) at the reference wavelength, on axis
  std::vector<MtfCurve> fields;
  std::string to_string() const;         // per field: frequency, T, S, diffraction limit
  friend std::ostream& operator<<(std::ostream& os, const Mtf& m) { return os << m.to_string(); }
};

// Throws what compute_wavefront throws.
Mtf compute_mtf(const AnalysisContext& context, const MtfOptions& options = {});

// Through-focus MTF: the MTF at one frequency as the image plane moves along the axis by each of
// `focus_shifts_mm` (mm, + away from the lens), as OpticStudio's "FFT Through Focus MTF": the shift adds the
// defocus of a spherical wave to the pupil's phase, W_dz = n' dz (1 - cos a) with sin a = rho r_XP / R
// (Welford sec. 5.4; wavefront_test.cpp checks the form against real rays).
struct ThroughFocusMtf {
  std::string lens_name;
  double frequency_per_mm = 0.0;
  std::vector<double> focus_shifts_mm;
  std::vector<MtfCurve> fields;  // tangential, sagittal and diffraction_limit over the shifts (strehl not set)
  std::string to_string() const;
  friend std::ostream& operator<<(std::ostream& os, const ThroughFocusMtf& t) { return os << t.to_string(); }
};

// Throws OptionsError for a frequency that is not > 0 or no shifts, and what compute_mtf throws.
ThroughFocusMtf compute_through_focus_mtf(const AnalysisContext& context, double frequency_per_mm, const std::vector<double>& focus_shifts_mm,
                                          const MtfOptions& options = {});

// The diffraction PSF from the same pupil function: |FFT(P)|^2, per wavelength on its own sampling
// (lambda' R / (M dp)), resampled bilinearly onto the reference wavelength's grid and averaged with equal
// weights. Each wavelength's PSF is scaled so that its aberration-free pupil's peak is 1: the polychromatic
// peak is then about the Strehl ratio. Coordinates are image-plane mm about the reference sphere's centre
// (the reference wavelength's chief ray), x right and y up as the image plane's.
struct PsfOptions {
  int pupil_samples = 64;   // pupil grid across the unit pupil (16 to 512)
  int padding = 4;          // transform size = pupil_samples x padding, rounded up to a power of two (2 to 16)
  int size = 128;           // output samples across, centred (8 to the transform size)
  bool transmittance = false;  // as MtfOptions::transmittance
  std::vector<double> wavelength_weights;  // as MtfOptions::wavelength_weights
  void validate() const;    // throws OptionsError
};

struct FieldPsf {
  double relative_field = 0.0;
  double field_value = 0.0;
  std::string field_label;
  ImagePoint centre;              // the grid's centre: the reference chief ray on the image plane
  double strehl = 0.0;            // as MtfCurve::strehl
  double centroid_x_mm = 0.0;     // the PSF's centroid about `centre`
  double centroid_y_mm = 0.0;
  std::vector<double> intensity;  // size x size, row-major, the top row at +y
};

struct Psf {
  std::string lens_name;
  std::vector<double> wavelengths_nm;
  int size = 0;
  double spacing_mm = 0.0;        // between samples (the reference wavelength's FFT sampling)
  std::vector<FieldPsf> fields;
  std::string to_string() const;  // per field: Strehl, peak, centroid, the sampling
  friend std::ostream& operator<<(std::ostream& os, const Psf& p) { return os << p.to_string(); }
};

Psf compute_psf(const AnalysisContext& context, const PsfOptions& options = {});

}  // namespace lensmith
