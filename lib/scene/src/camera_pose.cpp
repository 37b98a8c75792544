#include "lensmith/scene/camera_pose.h"

#include <cmath>
#include <sstream>

#include <Eigen/Geometry>

#include "lensmith/scene/scene_error.h"

namespace lensmith {

namespace {

// Shorter vectors carry no direction worth normalising.
constexpr double kMinDirectionLength = 1e-12;
// Up closer than this (radians, as the sine of the angle) to the look direction leaves no image x axis.
constexpr double kMinUpAngleRad = 1e-6;

bool finite(const Eigen::Vector3d& v) { return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z()); }

}  // namespace

std::string format_vector(const Eigen::Vector3d& v) {
  std::ostringstream os;
  os.precision(6);
  os << "[" << v.x() << ", " << v.y() << ", " << v.z() << "]";
  return os.str();
}

CameraPose CameraPose::looking_at(const Eigen::Vector3d& position_m, const Eigen::Vector3d& target_m, const Eigen::Vector3d& up) {
  CameraPose pose;
  pose.position_m = position_m;
  pose.look_direction = target_m - position_m;
  pose.up = up;
  return pose;
}

void CameraPose::validate() const {
  if (!finite(position_m)) throw SceneError(ErrorSubject{0, "camera.position_m", -1}, "camera.position_m = " + format_vector(position_m) + ": must be finite");
  if (!finite(look_direction) || !(look_direction.norm() > kMinDirectionLength)) {
    throw SceneError(ErrorSubject{0, "camera.look_at_m", -1}, "camera look direction " + format_vector(look_direction) +
                     ": must be finite and non-zero (the look-at point must differ from the position)");
  }
  if (!finite(up) || !(up.norm() > kMinDirectionLength)) {
    throw SceneError(ErrorSubject{0, "camera.up", -1}, "camera.up = " + format_vector(up) + ": must be finite and non-zero");
  }
  const double sine = up.normalized().cross(look_direction.normalized()).norm();
  if (!(sine > kMinUpAngleRad)) {
    throw SceneError(ErrorSubject{0, "camera.up", -1}, "camera.up = " + format_vector(up) + ": is parallel to the look direction " +
                     format_vector(look_direction) + "; give an up vector across it");
  }
}

CameraBasis CameraPose::basis() const {
  CameraBasis b;
  b.forward = look_direction.normalized();
  b.right = up.cross(b.forward).normalized();
  b.up = b.forward.cross(b.right);
  return b;
}

Eigen::Vector3d CameraPose::to_camera(const Eigen::Vector3d& world_m) const {
  const CameraBasis b = basis();
  const Eigen::Vector3d d = world_m - position_m;
  return {d.dot(b.right), d.dot(b.up), d.dot(b.forward)};
}

Eigen::Vector3d CameraPose::to_world(const Eigen::Vector3d& camera_m) const {
  const CameraBasis b = basis();
  return position_m + camera_m.x() * b.right + camera_m.y() * b.up + camera_m.z() * b.forward;
}

std::string CameraPose::to_string() const {
  return "CameraPose(position " + format_vector(position_m) + " m, look " + format_vector(look_direction) + ", up " +
         format_vector(up) + ")";
}

}  // namespace lensmith
