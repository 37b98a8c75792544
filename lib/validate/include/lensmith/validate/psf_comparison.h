// Point-spread functions of a ray model on the sensor, and how far a fast model's PSF is from the
// exact tracer's: centroid offset (um), RMS-radius ratio, and overlap 1 - 1/2 L1 of the normalised
// PSFs binned on a common grid (1 = identical, 0 = disjoint). Issue 6's PSF-level validation.
#pragma once

#include <ostream>
#include <string>
#include <vector>

#include "lensmith/camera/aperture.h"
#include "lensmith/camera/ray_model.h"
#include "lensmith/render/image.h"

namespace lensmith {

// Where the rays of one scene point land at one wavelength, on the sensor (mm).
struct PointSpread {
  std::vector<double> x_mm;
  std::vector<double> y_mm;
  std::size_t traced = 0;    // pupil samples tried (inside the aperture)
  double centroid_x_mm = 0.0;
  double centroid_y_mm = 0.0;
  double rms_radius_mm = 0.0;  // about the centroid
  double transmitted() const { return traced ? static_cast<double>(x_mm.size()) / static_cast<double>(traced) : 0.0; }
  std::string to_string() const;
};

// The PSF of `model` for a scene point at one wavelength, from samples_per_axis^2 pupil points,
// one per cell of a square grid, jittered deterministically inside it (those inside the aperture).
PointSpread trace_point_spread(const RayModel& model, const ScenePoint& point, double wavelength_nm,
                               const Aperture& aperture, int samples_per_axis = 96);

struct PsfComparison {
  double centroid_offset_um = 0.0;  // |model centroid - reference centroid|
  double rms_radius_ratio = 0.0;    // model / reference (1 = same size; NaN if the reference is a point)
  double overlap = 0.0;             // 1 - 1/2 sum |p - q| over a common grid of bins
  std::string to_string() const;
  friend std::ostream& operator<<(std::ostream& os, const PsfComparison& c) { return os << c.to_string(); }
};

// The window both PSFs are binned on: centred on the reference centroid, its half-width (mm) the
// farthest ray of either from there (plus 5 %), and at least min_half_width_mm.
double comparison_half_width_mm(const PointSpread& reference, const PointSpread& model, double min_half_width_mm = 0.0);

// Compares `model` with `reference` on bins x bins bins over the common window. A renderer cares
// about differences at its pixel scale: give min_half_width_mm a few sensor pixels so PSFs smaller
// than that are compared as the dots they are in a picture. Throws ComputationError when either
// PSF has no ray.
PsfComparison compare_point_spreads(const PointSpread& reference, const PointSpread& model, int bins = 32,
                                    double min_half_width_mm = 0.0);

// The two PSFs binned on the common window (bins x bins, normalised to sum 1), for pictures.
Image bin_point_spread(const PointSpread& psf, double centre_x_mm, double centre_y_mm, double half_width_mm, int bins);

}  // namespace lensmith
