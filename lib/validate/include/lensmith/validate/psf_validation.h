// PSF-level validation of the fast ray models (paraxial, seidel) against the exact tracer, over a
// grid of field positions, depths and wavelengths, for `lensmith validate` (docs/validation.md).
#pragma once

#include <ostream>
#include <string>
#include <vector>

#include "lensmith/validate/psf_comparison.h"

namespace lensmith {

struct PsfValidationOptions {
  std::vector<double> relative_fields{0.0, 0.5, 0.9};  // fractions of the frame's half-width, along +x (0..1)
  std::vector<double> depths_m;                        // empty: 0.5, 0.8, 1, 2 times the focus distance, and infinity
  std::vector<double> wavelengths_nm{486.1327, 587.5618, 656.2725};  // F, d, C lines
  int pupil_samples_per_axis = 96;                     // pupil grid (2..512)
  int bins = 32;                                       // comparison grid per axis (2..512)
  // The comparison window is at least this many output pixels (of the camera's frame) on either
  // side of the exact centroid: differences far below a pixel do not count as disagreement.
  double min_half_width_px = 2.0;
  void validate() const;                               // throws OptionsError
};

struct PsfValidationEntry {
  double relative_field = 0.0;
  double depth_m = 0.0;  // +inf: infinitely far
  double wavelength_nm = 0.0;
  RayModelKind model = RayModelKind::Seidel;
  double exact_rms_radius_um = 0.0;
  double exact_transmitted = 0.0;  // fraction of the exact model's pupil rays reaching the sensor
  bool compared = false;           // false when the exact model lost every ray (fully vignetted)
  PsfComparison comparison;
};

struct PsfModelSummary {
  RayModelKind model = RayModelKind::Seidel;
  std::size_t compared = 0;
  double mean_overlap = 0.0;
  double worst_overlap = 1.0;
  double max_centroid_offset_um = 0.0;
  double worst_rms_ratio_error = 0.0;  // max |ratio - 1|
};

struct PsfValidation {
  std::vector<PsfValidationEntry> entries;
  std::vector<PsfModelSummary> summaries;  // one per model, in the order asked
  std::string to_markdown() const;         // the per-model summary and the full table
};

// Compares each of `models` (not exact) with the exact model built from the same camera. Throws
// OptionsError for a thin-lens camera (there is no prescription to trace).
PsfValidation validate_point_spreads(const Camera& camera, const std::vector<RayModelKind>& models,
                                     const Aperture& aperture, const PsfValidationOptions& options = {},
                                     const RayModelOptions& model_options = {});

// A picture of the PSFs at the reference wavelength: one row per (field, depth), tiles exact |
// model | |difference| for each model, each tile scaled to the exact PSF's peak. RGB, linear.
Image psf_grid_picture(const Camera& camera, const std::vector<RayModelKind>& models, const Aperture& aperture,
                       const PsfValidationOptions& options = {}, const RayModelOptions& model_options = {});

// The same tiles as a figure a person can read (`lensmith validate`'s psf.png): each row labelled
// with its field and depth and a scale bar in micrometres on the sensor (rows differ: each has its
// own comparison window), each column with exact, the model's name or |diff|. Linear RGB on white.
// `font_path` empty: no text (tiles and scale bars only).
Image psf_grid_figure(const Camera& camera, const std::vector<RayModelKind>& models, const Aperture& aperture,
                      const PsfValidationOptions& options, const RayModelOptions& model_options, const std::string& font_path);

}  // namespace lensmith
