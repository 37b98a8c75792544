// Spot diagrams: where a bundle of rays from one field point lands on the image plane, per field and
// wavelength, with RMS and geometric (largest) radii about the chief ray of the reference wavelength
// and about the spot's centroid (Welford, Aberrations of Optical Systems, ch. 9; OpticStudio User
// Guide, "Standard Spot Diagram": referenced to the real chief ray by default).
#pragma once

#include <ostream>
#include <string>
#include <vector>

#include "lensmith/analysis/analysis_context.h"
#include "lensmith/analysis/pupil_sampling.h"

namespace lensmith {

struct SpotOptions {
  PupilSampling sampling;  // hexapolar, 6 rings by default
  void validate() const { sampling.validate(); }
};

// Statistics of the rays that reached the image plane. Radii are in mm; NaN when no ray passed.
struct SpotStatistics {
  std::size_t traced = 0;           // rays launched
  std::size_t passed = 0;           // rays that reached the image plane (the only ones counted below)
  RayLossCount lost;                // the others, by reason
  double centroid_x_mm = 0.0;       // mean landing point, global frame
  double centroid_y_mm = 0.0;
  double rms_radius_chief_mm = 0.0;     // sqrt(mean |p - chief|^2)
  double geo_radius_chief_mm = 0.0;     // max |p - chief|
  double rms_radius_centroid_mm = 0.0;  // sqrt(mean |p - centroid|^2) (never larger than about the chief)
  double geo_radius_centroid_mm = 0.0;  // max |p - centroid|
  std::string to_string() const;
};

// One wavelength at one field point.
struct Spot {
  double wavelength_nm = 0.0;
  std::vector<PupilCoordinate> pupil;  // pupil coordinate of each passed ray
  std::vector<ImagePoint> points;      // where each passed ray meets the image plane
  SpotStatistics stats;
};

struct FieldSpot {
  double relative_field = 0.0;
  double field_value = 0.0;            // in AnalysisContext::field_unit()
  std::string field_label;
  ImagePoint chief;                    // chief ray of the reference wavelength (the reference point)
  std::vector<Spot> spots;             // one per wavelength, in the context's order
  SpotStatistics polychromatic;        // every wavelength together, equal weights
};

struct SpotDiagram {
  std::string lens_name;
  PupilSampling sampling;
  std::vector<double> wavelengths_nm;
  double reference_wavelength_nm = 0.0;
  std::string field_unit;
  double image_plane_z_mm = 0.0;
  // Working f-number in image space, 1 / (2 n' |u'|) of the paraxial marginal ray at the reference
  // wavelength and the prescription's object distance (every field shares that conjugate): the Airy
  // disc's first dark ring has radius 1.22 lambda N_w (Born & Wolf, Principles of Optics, 8.5.2).
  double working_f_number = 0.0;
  std::vector<FieldSpot> fields;
  // 1.22 lambda N_w, mm, at `wavelength_nm`.
  double airy_radius_mm(double wavelength_nm) const;
  std::string to_string() const;  // a table of radii in micrometres per field and wavelength
  friend std::ostream& operator<<(std::ostream& os, const SpotDiagram& s) { return os << s.to_string(); }
};

// Traces `options.sampling` at every field and wavelength of `context`. Throws ComputationError when
// a field's chief ray cannot be traced, OptionsError for bad options.
SpotDiagram compute_spot_diagram(const AnalysisContext& context, const SpotOptions& options = {});

// Statistics of `points` about `reference` (x, y only). Exposed for tests.
SpotStatistics spot_statistics(const std::vector<ImagePoint>& points, const ImagePoint& reference);

}  // namespace lensmith
