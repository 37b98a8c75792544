// The analytic shapes of a scene (infinite plane, rectangle, disc, sphere), their exact ray
// intersections in double precision, and the 2D surface coordinates (s, t) in metres on which
// textures are laid. Ray-plane and ray-sphere formulas: pbrt-v4 (Pharr, Jakob, Humphreys,
// "Physically Based Rendering", 4th ed.), sections 6.2.2 and 6.3.2; the sphere uses the
// cancellation-free discriminant of Haines et al., "Ray Tracing Gems" (2019), chapter 7.
//
// Every shape is two-sided: a ray hits it from either side. Surface coordinates: for the flat
// shapes (s, t) = ((p - origin) . u, (p - origin) . v) with u, v unit vectors in the surface and
// v = u x normal, so that seen from the side the normal points to, u runs right and v up (an image
// texture reads the right way round from there). For a sphere, (s, t) = (r phi, r lambda): arc
// lengths along the equator and a meridian, with longitude phi = atan2(d.x, -d.z) in (-pi, pi] and
// latitude lambda = asin(d.y) for the unit vector d from the centre, so the seam faces +z (away
// from the default camera) and s grows to the right, t upward, on the side facing it.
#pragma once

#include <optional>
#include <ostream>
#include <string>
#include <string_view>
#include <variant>

#include <Eigen/Core>

namespace lensmith {

// A ray in scene coordinates: origin in metres, direction a unit vector.
struct SceneRay {
  Eigen::Vector3d origin_m{0.0, 0.0, 0.0};
  Eigen::Vector3d direction{0.0, 0.0, 1.0};

  std::string to_string() const;
  friend std::ostream& operator<<(std::ostream& os, const SceneRay& r) { return os << r.to_string(); }
};

// Texture coordinates of a surface point, metres (see the file comment).
struct SurfaceCoordinates {
  double s_m = 0.0;
  double t_m = 0.0;
};

// An infinite plane through point_m with the given normal (any non-zero length).
struct Plane {
  Eigen::Vector3d point_m{0.0, 0.0, 0.0};  // also the origin of (s, t)
  Eigen::Vector3d normal{0.0, 0.0, -1.0};
  // Direction of the texture's s axis: its component along the normal is removed. Empty =
  // default_u_axis(normal).
  std::optional<Eigen::Vector3d> u_axis;
};

// A rectangle: centre +- half_u_m +- half_v_m; the two half-edges must be perpendicular (to 1e-6
// of their lengths' product). Its normal is normalise(half_v x half_u), the side from which
// half_u points right and half_v up; (s, t) run along half_u and half_v from the centre.
struct Rectangle {
  Eigen::Vector3d centre_m{0.0, 0.0, 0.0};
  Eigen::Vector3d half_u_m{0.5, 0.0, 0.0};
  Eigen::Vector3d half_v_m{0.0, 0.5, 0.0};
};

// A flat disc of radius_m around centre_m (the origin of (s, t)).
struct Disc {
  Eigen::Vector3d centre_m{0.0, 0.0, 0.0};
  Eigen::Vector3d normal{0.0, 0.0, -1.0};  // any non-zero length
  double radius_m = 1.0;                   // > 0
  std::optional<Eigen::Vector3d> u_axis;  // as for Plane
};

struct Sphere {
  Eigen::Vector3d centre_m{0.0, 0.0, 0.0};
  double radius_m = 1.0;  // > 0
};

using SceneShape = std::variant<Plane, Rectangle, Disc, Sphere>;

// "plane", "rectangle", "disc", "sphere" (the scene file's spelling).
std::string_view shape_type_name(const SceneShape& shape);

// Throws SceneError naming the field and the violated rule: a non-finite component, a radius
// not > 0, a normal or half-edge of (near) zero length (below 1e-12 m or 1e-12), half-edges that
// are not perpendicular, a u_axis parallel to the normal.
void validate(const SceneShape& shape);

// Distance (metres, along the unit direction) to the nearest intersection with t > 0, or +inf when
// the ray misses. Rays in the surface of a flat shape miss it. Assumes validate() passed.
double hit_distance_m(const SceneShape& shape, const SceneRay& ray);

// Unit normal of the shape at a point on it: the plane's or disc's normal as given (normalised), a
// rectangle's normalise(half_v x half_u), a sphere's outward normal.
Eigen::Vector3d surface_normal(const SceneShape& shape, const Eigen::Vector3d& point_m);

// Texture coordinates of a point on the shape (see the file comment).
SurfaceCoordinates surface_coordinates(const SceneShape& shape, const Eigen::Vector3d& point_m);

// The texture s axis of a plane or disc with no u_axis: normalise(n x (0, 1, 0)) (for a wall facing
// the default camera, +x), or normalise of +x with its normal component removed when n is within
// 1e-6 of the y axis (a floor or ceiling). `normal` need not be unit.
Eigen::Vector3d default_u_axis(const Eigen::Vector3d& normal);

std::string to_string(const SceneShape& shape);  // "sphere(centre [0, 0, 3] m, radius 0.5 m)"

}  // namespace lensmith
