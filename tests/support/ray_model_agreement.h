// How closely two ray models (the poly model and the exact model, say) agree ray by ray: the same scene
// points, wavelengths and stop points through both, and where the rays land, whether they pass and how
// far inside the apertures they pass. Shared by the render tests that check a fitted lens against exact
// tracing (anamorphic, mirror and tilt-shift lenses). Header-only: its users link the camera layer.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <span>
#include <sstream>
#include <string>
#include <vector>

#include "lensmith/camera/ray_model.h"
#include "lensmith/core/units.h"

namespace lensmith::testing {

struct RayModelAgreement {
  int rays = 0;
  int unlanded = 0;           // rays either model did not land (a failed aim or trace)
  int verdicts_differ = 0;    // rays one model passes and the other stops
  int stopped = 0;            // rays the reference stops
  double worst_px = 0.0;      // largest distance between the landing points, output pixels
  double worst_clearance = 0.0;  // largest difference of the clearances
  std::string worst_where;    // the ray of worst_px
};

// Every combination of depth (m), field tangents and wavelength (nm), through every stop point of `pupil`.
inline RayModelAgreement compare_ray_models(const RayModel& model, const RayModel& reference, const Camera& camera,
                                            std::span<const double> depths_m, std::span<const std::array<double, 2>> tangents,
                                            std::span<const double> wavelengths_nm, std::span<const PupilPoint> pupil) {
  RayModelAgreement r;
  std::vector<SensorHit> a(pupil.size()), b(pupil.size());
  for (const double depth_m : depths_m) {
    for (const auto& [tx, ty] : tangents) {
      for (const double nm : wavelengths_nm) {
        const ScenePoint point{tx, ty, 1.0 / mm_from_m(depth_m)};
        model.map(point, nm, pupil, a);
        reference.map(point, nm, pupil, b);
        for (std::size_t i = 0; i < pupil.size(); ++i) {
          ++r.rays;
          if (!a[i].unclipped || !b[i].unclipped) {
            ++r.unlanded;
            continue;
          }
          r.verdicts_differ += a[i].ok != b[i].ok ? 1 : 0;
          r.stopped += b[i].ok ? 0 : 1;
          const PixelPoint pa = camera.output_pixel(a[i].x_mm, a[i].y_mm), pb = camera.output_pixel(b[i].x_mm, b[i].y_mm);
          const double miss = std::hypot(pa.x - pb.x, pa.y - pb.y);
          if (miss > r.worst_px) {
            r.worst_px = miss;
            std::ostringstream where;
            where << "tangents (" << tx << ", " << ty << ") at " << depth_m << " m, " << nm << " nm, pupil point ("
                  << pupil[i].x << ", " << pupil[i].y << ")";
            r.worst_where = where.str();
          }
          r.worst_clearance = std::max(r.worst_clearance, std::abs(a[i].clearance - b[i].clearance));
        }
      }
    }
  }
  return r;
}

inline std::ostream& operator<<(std::ostream& os, const RayModelAgreement& r) {
  return os << "RayModelAgreement{" << r.rays << " rays, " << r.unlanded << " unlanded, " << r.verdicts_differ
            << " verdicts differ, " << r.stopped << " stopped, worst " << r.worst_px << " px at " << r.worst_where
            << ", clearance " << r.worst_clearance << "}";
}

}  // namespace lensmith::testing
