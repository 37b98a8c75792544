// A geometric ray and the reasons a ray can die in a sequential system. Positions are in the
// global lens frame of `lensmith info --json` (mm, z = 0 at the vertex of surface 1, +z toward the
// image); directions are unit vectors of direction cosines (l, m, n).
#pragma once

#include <cstdint>
#include <ostream>
#include <string>
#include <string_view>

#include <Eigen/Core>

namespace lensmith {

struct Ray {
  Eigen::Vector3d position_mm{0.0, 0.0, 0.0};
  Eigen::Vector3d direction{0.0, 0.0, 1.0};  // unit length
  double wavelength_nm = 587.5618;

  std::string to_string() const;
  friend std::ostream& operator<<(std::ostream& os, const Ray& r) { return os << r.to_string(); }
};

// Why a ray stopped. A ray that dies is never counted as a silent zero: callers get the status and
// the surface.
enum class RayStatus : std::uint8_t {
  Ok = 0,
  Missed = 1,                   // no intersection with the surface (or outside the domain of its sag)
  Vignetted = 2,                // hit the surface outside its clear semi-diameter (or the stop's)
  TotalInternalReflection = 3,  // no refracted ray exists
  NotConverged = 4,             // aspheric intersection or ray aiming failed to converge
  InvalidInput = 5,             // NaN or zero direction given
};

// "ok", "missed", "vignetted", "tir", "not_converged", "invalid_input" (the --json spelling).
std::string_view to_string(RayStatus status);

enum class TraceDirection {
  Forward,   // object space -> image space (+z)
  Backward,  // image space -> object space: a ray from the sensor travelling toward -z
};

}  // namespace lensmith
