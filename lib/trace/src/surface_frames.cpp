// Surface frames from the chain of thicknesses and coordinate breaks (OpticStudio's sequential convention:
// "Coordinate Break" in its manual; a break followed by the same break negated with the order toggled is the
// identity, tests/trace/surface_frames_test.cpp).
#include "lensmith/trace/surface_frames.h"

#include <Eigen/Geometry>

#include "lensmith/core/units.h"

namespace lensmith {

namespace {

Eigen::Matrix3d rotation(double angle_deg, const Eigen::Vector3d& axis) {
  return Eigen::AngleAxisd(angle_deg * kPi / 180.0, axis).toRotationMatrix();
}

}  // namespace

SurfaceFrame SurfaceFrame::after_break(const SurfaceFrame& frame, const CoordinateBreak& b) {
  // Right-handed rotations of the coordinate system about its own axes compose by right multiplication.
  const Eigen::Matrix3d rx = rotation(b.tilt_x_deg, Eigen::Vector3d::UnitX());
  const Eigen::Matrix3d ry = rotation(b.tilt_y_deg, Eigen::Vector3d::UnitY());
  const Eigen::Matrix3d rz = rotation(b.tilt_z_deg, Eigen::Vector3d::UnitZ());
  const Eigen::Vector3d decentre(b.decenter_x_mm, b.decenter_y_mm, 0.0);
  SurfaceFrame out;
  if (b.tilt_first) {
    out.axes = frame.axes * rz * ry * rx;
    out.origin_mm = frame.origin_mm + out.axes * decentre;
  } else {
    out.origin_mm = frame.origin_mm + frame.axes * decentre;
    out.axes = frame.axes * rx * ry * rz;
  }
  return out;
}

LensFrames surface_frames(const Prescription& lens, double image_distance_mm) {
  LensFrames frames;
  frames.surfaces.reserve(lens.surfaces.size());
  SurfaceFrame current;
  for (std::size_t k = 0; k < lens.surfaces.size(); ++k) {
    const Surface& s = lens.surfaces[k];
    if (s.is_coordinate_break()) current = SurfaceFrame::after_break(current, s.coordinate_break);
    frames.surfaces.push_back(current);
    const double thickness = k + 1 == lens.surfaces.size() ? image_distance_mm : s.thickness_mm;
    current.origin_mm += current.axes.col(2) * thickness;
  }
  frames.image = current;
  return frames;
}

}  // namespace lensmith
