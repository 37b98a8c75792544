// One real ray traced through the lens, surface by surface: what `lensmith trace` prints. The ray is
// made from a field point and a normalised pupil coordinate by RayAimer and traced by
// SequentialTracer; positions are in the global frame of `lensmith info --json` (mm, z = 0 at the
// vertex of surface 1), directions are unit vectors of direction cosines (l, m, n).
#pragma once

#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "lensmith/analysis/analysis_context.h"

namespace lensmith {

struct RayTraceOptions {
  FieldPoint field;                      // default: on axis
  PupilCoordinate pupil;                 // normalised, inside the unit disc
  std::optional<double> wavelength_nm;   // default: the primary wavelength; (100, 20000)
  std::optional<RayAiming> aiming;  // as AnalysisOptions::aiming: empty = the lens file's
  TracerOptions::ImagePlane image_plane = TracerOptions::ImagePlane::AsPrescribed;
  void validate() const;                 // throws OptionsError ("pupil (2, 0): must lie in the unit disc")
};

struct RayTraceListing {
  std::string lens_name;
  FieldPoint field;
  PupilCoordinate pupil;
  double wavelength_nm = 0.0;
  RayStatus status = RayStatus::Ok;
  int surface = 0;                       // where the ray died; 0 when it reached the image
  Ray object_ray;                        // the aimed ray in object space
  std::vector<SurfaceHit> hits;          // one per surface reached
  // The same hits in each surface's own frame (its vertex at the origin, z the sag, directions in its axes):
  // what OpticStudio's Single Ray Trace lists. Filled for systems with tilts or decentres (folded = true).
  std::vector<SurfaceHit> local_hits;
  bool folded = false;
  std::optional<ImagePoint> image;       // on the image plane; empty when the ray died
  Eigen::Vector3d image_direction{0.0, 0.0, 1.0};
  double image_plane_z_mm = 0.0;
  std::string to_string() const;        // a surface table with units
  friend std::ostream& operator<<(std::ostream& os, const RayTraceListing& r) { return os << r.to_string(); }
};

// Traces one ray. A ray that dies is a result (status and surface), not an error. Throws
// OptionsError, PrescriptionError, ComputationError (e.g. an afocal lens has no paraxial pupil).
RayTraceListing trace_ray_listing(const Prescription& lens, const RayTraceOptions& options);

}  // namespace lensmith
