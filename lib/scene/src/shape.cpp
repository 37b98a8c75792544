#include "lensmith/core/number_parsing.h"
#include "lensmith/scene/shape.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <Eigen/Geometry>

#include "lensmith/core/units.h"
#include "lensmith/scene/camera_pose.h"
#include "lensmith/scene/scene_error.h"

namespace lensmith {

namespace {

// Shorter normals and half-edges carry no direction worth normalising.
constexpr double kMinLength = 1e-12;
// Hand-written rotated rectangles round their half-edges to ~7 digits; a larger cosine is a mistake.
constexpr double kMaxHalfEdgeCosine = 1e-6;
// A u_axis whose component across the normal is below this fraction of its length is along the normal.
constexpr double kMinUAxisSine = 1e-6;

template <class... Ts>
struct Overloaded : Ts... {
  using Ts::operator()...;
};
template <class... Ts>
Overloaded(Ts...) -> Overloaded<Ts...>;

bool finite(const Eigen::Vector3d& v) { return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z()); }

void require_finite(const Eigen::Vector3d& v, const char* field) {
  if (!finite(v)) throw SceneError(ErrorSubject{0, field, -1}, std::string(field) + " = " + format_vector(v) + ": must be finite");
}

void require_direction(const Eigen::Vector3d& v, const char* field) {
  require_finite(v, field);
  if (!(v.norm() > kMinLength)) {
    throw SceneError(ErrorSubject{0, field, -1}, std::string(field) + " = " + format_vector(v) + ": must have a non-zero length (it is normalised)");
  }
}

void require_radius(double radius_m) {
  if (!(std::isfinite(radius_m) && radius_m > 0.0)) throw SceneError(ErrorSubject{0, "radius_m", -1}, "radius_m = " + format_rounded(radius_m, 6) + ": must be finite and > 0");
}

void require_u_axis(const std::optional<Eigen::Vector3d>& u_axis, const Eigen::Vector3d& normal) {
  if (!u_axis) return;
  require_direction(*u_axis, "u_axis");
  const Eigen::Vector3d n = normal.normalized();
  const Eigen::Vector3d across = *u_axis - u_axis->dot(n) * n;
  if (!(across.norm() > kMinUAxisSine * u_axis->norm())) {
    throw SceneError(ErrorSubject{0, "u_axis", -1}, "u_axis = " + format_vector(*u_axis) + ": is parallel to the normal " + format_vector(normal) +
                     "; give a direction in the surface");
  }
}

// Distance along `ray` to the plane through `point` with normal `n` (any length), or +inf.
double plane_distance_m(const Eigen::Vector3d& point, const Eigen::Vector3d& n, const SceneRay& ray) {
  const double denominator = ray.direction.dot(n);
  if (denominator == 0.0) return kInfinity;
  const double t = (point - ray.origin_m).dot(n) / denominator;
  return t > 0.0 && std::isfinite(t) ? t : kInfinity;
}

// The in-surface unit axes (u, v = u x n) of a plane or disc.
void flat_axes(const Eigen::Vector3d& normal, const std::optional<Eigen::Vector3d>& u_axis, Eigen::Vector3d* u,
               Eigen::Vector3d* v) {
  const Eigen::Vector3d n = normal.normalized();
  if (u_axis) {
    *u = (*u_axis - u_axis->dot(n) * n).normalized();
  } else {
    *u = default_u_axis(normal);
  }
  *v = u->cross(n);
}

SurfaceCoordinates flat_coordinates(const Eigen::Vector3d& origin, const Eigen::Vector3d& u, const Eigen::Vector3d& v,
                                    const Eigen::Vector3d& point_m) {
  const Eigen::Vector3d d = point_m - origin;
  return {d.dot(u), d.dot(v)};
}

}  // namespace

std::string SceneRay::to_string() const {
  return "SceneRay(origin " + format_vector(origin_m) + " m, direction " + format_vector(direction) + ")";
}

std::string_view shape_type_name(const SceneShape& shape) {
  return std::visit(Overloaded{[](const Plane&) { return std::string_view("plane"); },
                               [](const Rectangle&) { return std::string_view("rectangle"); },
                               [](const Disc&) { return std::string_view("disc"); },
                               [](const Sphere&) { return std::string_view("sphere"); }},
                    shape);
}

void validate(const SceneShape& shape) {
  std::visit(Overloaded{[](const Plane& p) {
                          require_finite(p.point_m, "point_m");
                          require_direction(p.normal, "normal");
                          require_u_axis(p.u_axis, p.normal);
                        },
                        [](const Rectangle& r) {
                          require_finite(r.centre_m, "centre_m");
                          require_direction(r.half_u_m, "half_u_m");
                          require_direction(r.half_v_m, "half_v_m");
                          const double cosine = r.half_u_m.dot(r.half_v_m) / (r.half_u_m.norm() * r.half_v_m.norm());
                          if (!(std::abs(cosine) <= kMaxHalfEdgeCosine)) {
                            throw SceneError(ErrorSubject{0, "half_u_m", -1}, "half_u_m = " + format_vector(r.half_u_m) + " and half_v_m = " +
                                             format_vector(r.half_v_m) + ": must be perpendicular (cosine " + format_rounded(cosine, 6) +
                                             ", allowed 1e-6)");
                          }
                        },
                        [](const Disc& d) {
                          require_finite(d.centre_m, "centre_m");
                          require_direction(d.normal, "normal");
                          require_radius(d.radius_m);
                          require_u_axis(d.u_axis, d.normal);
                        },
                        [](const Sphere& s) {
                          require_finite(s.centre_m, "centre_m");
                          require_radius(s.radius_m);
                        }},
             shape);
}

double hit_distance_m(const SceneShape& shape, const SceneRay& ray) {
  return std::visit(
      Overloaded{[&](const Plane& p) { return plane_distance_m(p.point_m, p.normal, ray); },
                 [&](const Rectangle& r) {
                   const double t = plane_distance_m(r.centre_m, r.half_v_m.cross(r.half_u_m), ray);
                   if (!std::isfinite(t)) return kInfinity;
                   const Eigen::Vector3d local = ray.origin_m + t * ray.direction - r.centre_m;
                   // |local . h| <= |h|^2 is |coordinate along h| <= 1 half-edge, without a division.
                   const bool inside = std::abs(local.dot(r.half_u_m)) <= r.half_u_m.squaredNorm() &&
                                       std::abs(local.dot(r.half_v_m)) <= r.half_v_m.squaredNorm();
                   return inside ? t : kInfinity;
                 },
                 [&](const Disc& d) {
                   const double t = plane_distance_m(d.centre_m, d.normal, ray);
                   if (!std::isfinite(t)) return kInfinity;
                   const Eigen::Vector3d local = ray.origin_m + t * ray.direction - d.centre_m;
                   return local.squaredNorm() <= d.radius_m * d.radius_m ? t : kInfinity;
                 },
                 [&](const Sphere& s) {
                   // t^2 + 2 b t + c = 0 with b = oc . d, c = |oc|^2 - r^2; the discriminant b^2 - c is
                   // computed as r^2 - |oc - b d|^2, which does not cancel for small spheres far away.
                   const Eigen::Vector3d oc = ray.origin_m - s.centre_m;
                   const double b = oc.dot(ray.direction);
                   const Eigen::Vector3d closest = oc - b * ray.direction;
                   const double h = s.radius_m * s.radius_m - closest.squaredNorm();
                   if (h < 0.0) return kInfinity;
                   const double c = oc.squaredNorm() - s.radius_m * s.radius_m;
                   const double q = -b - std::copysign(std::sqrt(h), b);
                   if (q == 0.0) return kInfinity;  // both roots 0: the origin is on the sphere, looking along it
                   const double t0 = std::min(c / q, q);
                   const double t1 = std::max(c / q, q);
                   if (t0 > 0.0) return t0;
                   return t1 > 0.0 ? t1 : kInfinity;
                 }},
      shape);
}

Eigen::Vector3d surface_normal(const SceneShape& shape, const Eigen::Vector3d& point_m) {
  return std::visit(Overloaded{[](const Plane& p) -> Eigen::Vector3d { return p.normal.normalized(); },
                               [](const Rectangle& r) -> Eigen::Vector3d { return r.half_v_m.cross(r.half_u_m).normalized(); },
                               [](const Disc& d) -> Eigen::Vector3d { return d.normal.normalized(); },
                               [&](const Sphere& s) -> Eigen::Vector3d { return (point_m - s.centre_m).normalized(); }},
                    shape);
}

SurfaceCoordinates surface_coordinates(const SceneShape& shape, const Eigen::Vector3d& point_m) {
  return std::visit(Overloaded{[&](const Plane& p) {
                                 Eigen::Vector3d u, v;
                                 flat_axes(p.normal, p.u_axis, &u, &v);
                                 return flat_coordinates(p.point_m, u, v, point_m);
                               },
                               [&](const Rectangle& r) {
                                 return flat_coordinates(r.centre_m, r.half_u_m.normalized(), r.half_v_m.normalized(), point_m);
                               },
                               [&](const Disc& d) {
                                 Eigen::Vector3d u, v;
                                 flat_axes(d.normal, d.u_axis, &u, &v);
                                 return flat_coordinates(d.centre_m, u, v, point_m);
                               },
                               [&](const Sphere& s) {
                                 const Eigen::Vector3d d = (point_m - s.centre_m).normalized();
                                 const double longitude = std::atan2(d.x(), -d.z());
                                 const double latitude = std::asin(std::clamp(d.y(), -1.0, 1.0));
                                 return SurfaceCoordinates{s.radius_m * longitude, s.radius_m * latitude};
                               }},
                    shape);
}

Eigen::Vector3d default_u_axis(const Eigen::Vector3d& normal) {
  const Eigen::Vector3d n = normal.normalized();
  const Eigen::Vector3d across = n.cross(Eigen::Vector3d::UnitY());
  if (across.norm() > kMinUAxisSine) return across.normalized();
  const Eigen::Vector3d x = Eigen::Vector3d::UnitX();
  return (x - x.dot(n) * n).normalized();
}

std::string to_string(const SceneShape& shape) {
  return std::visit(Overloaded{[](const Plane& p) {
                                 std::string s = "plane(point " + format_vector(p.point_m) + " m, normal " + format_vector(p.normal);
                                 if (p.u_axis) s += ", u_axis " + format_vector(*p.u_axis);
                                 return s + ")";
                               },
                               [](const Rectangle& r) {
                                 return "rectangle(centre " + format_vector(r.centre_m) + " m, half_u " + format_vector(r.half_u_m) +
                                        " m, half_v " + format_vector(r.half_v_m) + " m)";
                               },
                               [](const Disc& d) {
                                 std::string s = "disc(centre " + format_vector(d.centre_m) + " m, normal " + format_vector(d.normal) +
                                                 ", radius " + format_rounded(d.radius_m, 6) + " m";
                                 if (d.u_axis) s += ", u_axis " + format_vector(*d.u_axis);
                                 return s + ")";
                               },
                               [](const Sphere& s) {
                                 return "sphere(centre " + format_vector(s.centre_m) + " m, radius " + format_rounded(s.radius_m, 6) + " m)";
                               }},
                    shape);
}

}  // namespace lensmith
