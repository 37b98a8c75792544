// Ray-scene intersection: the nearest surface a ray meets and the radiance it sends back along the
// ray (scene.h's shading model). Brute force over the objects, which is what scenes of tens of
// objects need; no acceleration structure. Double precision, no allocation, and const, so any
// number of threads may intersect the same scene at once.
#pragma once

#include <cstddef>
#include <optional>
#include <span>
#include <ostream>
#include <string>

#include <Eigen/Core>

#include "lensmith/color/rgb.h"
#include "lensmith/scene/scene.h"
#include "lensmith/scene/shape.h"

namespace lensmith {

struct SceneHit {
  double distance_m = 0.0;                   // from the ray's origin along its unit direction, > 0
  Eigen::Vector3d point_m{0.0, 0.0, 0.0};    // origin + distance * direction
  Eigen::Vector3d normal{0.0, 0.0, -1.0};    // unit surface normal, turned to face the ray's origin
  Rgb radiance{0.0, 0.0, 0.0};               // emission + albedo x ambient at the point
  std::size_t object_index = 0;              // into Scene::objects

  std::string to_string() const;
  friend std::ostream& operator<<(std::ostream& os, const SceneHit& h) { return os << h.to_string(); }
};

// The nearest intersection at distance > 0 of `ray` (unit direction) with the scene's objects, or
// nothing when the ray escapes to the background. Of two objects at exactly the same distance the
// one listed first wins. Assumes scene.validate() passed.
std::optional<SceneHit> intersect(const Scene& scene, const SceneRay& ray);
// The same, ignoring the objects listed in `excluded` (indices into Scene::objects): the nearest
// surface behind those, which is how depth peeling finds a ray's next layer (every shape is convex
// or flat, so an object is met at most once from the outside).
std::optional<SceneHit> intersect(const Scene& scene, const SceneRay& ray, std::span<const std::size_t> excluded);

}  // namespace lensmith
