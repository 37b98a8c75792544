// Where the surfaces of a sequential lens lie in space: each surface's local frame (its vertex and axes) in
// the global frame of `Ray` (surface 1's vertex at the origin, +z its axis). A coaxial lens has every frame
// on the z axis, unturned; coordinate breaks move and turn the frames of the surfaces after them, in
// OpticStudio's convention (CoordinateBreak in lensmith/prescription/surface.h): the next surface lies a
// thickness along the current frame's z axis, mirrors do not turn the frame (after one, light travels
// toward -z and thicknesses are negative).
#pragma once

#include <vector>

#include <Eigen/Core>

#include "lensmith/prescription/prescription.h"

namespace lensmith {

struct SurfaceFrame {
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();  // columns: the local x, y, z axes in global coordinates
  Eigen::Vector3d origin_mm = Eigen::Vector3d::Zero();  // the vertex, global (mm)

  Eigen::Vector3d to_local(const Eigen::Vector3d& global_mm) const { return axes.transpose() * (global_mm - origin_mm); }
  Eigen::Vector3d to_global(const Eigen::Vector3d& local_mm) const { return origin_mm + axes * local_mm; }
  // `frame` moved and turned by a coordinate break (decentres in mm, tilts right-handed about the frame's own axes).
  static SurfaceFrame after_break(const SurfaceFrame& frame, const CoordinateBreak& b);
};

struct LensFrames {
  std::vector<SurfaceFrame> surfaces;  // surfaces[k]: surface k + 1 (a coordinate break: the frame after it)
  SurfaceFrame image;                  // the image plane: `image_distance_mm` along the last frame's z axis
};

// The frames of every surface and of the image plane, `image_distance_mm` (mm, signed as a thickness) after
// the last surface.
LensFrames surface_frames(const Prescription& lens, double image_distance_mm);

}  // namespace lensmith
