// Where a pinhole camera stands in an analytic scene and which way it looks. Scene coordinates are
// metres in the scene's own world frame (not the lens frame of conventions.h, which is in mm with
// +z toward the image).
//
// Camera frame: the optical axis is the camera's local +z (forward, into the scene); the image's
// x runs to the right and its y up, as PinholeFrame's tangents do. In world coordinates
//   forward = normalise(look direction), right = normalise(up x forward), true_up = forward x right,
// with x the ordinary component formula of the cross product. The default pose (origin, looking
// along +z, +y up) therefore has right = +x, true_up = +y: camera and world coordinates coincide
// (the camera space of pbrt-v4). Drawn with x to the right and y up, world +z points away from the
// viewer: the left-handed world of pbrt and Unity. The planar depth of a point is its camera-local
// z: (point - position) . forward, in metres.
#pragma once

#include <ostream>
#include <string>

#include <Eigen/Core>

namespace lensmith {

// The orthonormal frame of a camera pose in world coordinates.
struct CameraBasis {
  Eigen::Vector3d right{1.0, 0.0, 0.0};    // image x
  Eigen::Vector3d up{0.0, 1.0, 0.0};       // image y
  Eigen::Vector3d forward{0.0, 0.0, 1.0};  // optical axis; planar depth is measured along it
};

struct CameraPose {
  Eigen::Vector3d position_m{0.0, 0.0, 0.0};     // the pinhole (perspective centre), metres
  Eigen::Vector3d look_direction{0.0, 0.0, 1.0};  // any non-zero length; normalised by basis()
  Eigen::Vector3d up{0.0, 1.0, 0.0};              // any non-zero length, not parallel to look_direction

  // A pose at `position_m` looking at `target_m` (which must differ from the position).
  static CameraPose looking_at(const Eigen::Vector3d& position_m, const Eigen::Vector3d& target_m,
                               const Eigen::Vector3d& up = {0.0, 1.0, 0.0});

  // Throws SceneError when a component is not finite, the look direction or up is (near) zero, or
  // up is within 1e-6 rad of the look direction (no image x axis can be made).
  void validate() const;
  // The camera frame (see the file comment). Assumes validate() passed.
  CameraBasis basis() const;

  // Camera-local coordinates (x right, y up, z = planar depth) of a world point, metres.
  Eigen::Vector3d to_camera(const Eigen::Vector3d& world_m) const;
  // World coordinates of a camera-local point, metres.
  Eigen::Vector3d to_world(const Eigen::Vector3d& camera_m) const;

  std::string to_string() const;  // "CameraPose(position [0, 0, 0] m, look [0, 0, 1], up [0, 1, 0])"
  friend std::ostream& operator<<(std::ostream& os, const CameraPose& p) { return os << p.to_string(); }
};

// "[x, y, z]" with up to 6 significant digits, for messages and to_string.
std::string format_vector(const Eigen::Vector3d& v);

}  // namespace lensmith
