#include "lensmith/scene/scene_intersection.h"

#include <algorithm>
#include <cmath>

#include "lensmith/core/units.h"
#include "lensmith/scene/camera_pose.h"

namespace lensmith {

std::string SceneHit::to_string() const {
  return "SceneHit(object " + std::to_string(object_index) + ", distance " + std::to_string(distance_m) + " m, point " +
         format_vector(point_m) + " m, normal " + format_vector(normal) + ", radiance " + radiance.to_string() + ")";
}

std::optional<SceneHit> intersect(const Scene& scene, const SceneRay& ray) { return intersect(scene, ray, {}); }

std::optional<SceneHit> intersect(const Scene& scene, const SceneRay& ray, std::span<const std::size_t> excluded) {
  double nearest_m = kInfinity;
  std::size_t nearest_index = 0;
  for (std::size_t i = 0; i < scene.objects.size(); ++i) {
    if (std::find(excluded.begin(), excluded.end(), i) != excluded.end()) continue;
    const double t = hit_distance_m(scene.objects[i].shape, ray);
    if (t < nearest_m) {
      nearest_m = t;
      nearest_index = i;
    }
  }
  if (!std::isfinite(nearest_m)) return std::nullopt;

  // Shade only the nearest hit: texture look-ups cost more than the intersection tests.
  const SceneObject& object = scene.objects[nearest_index];
  SceneHit hit;
  hit.distance_m = nearest_m;
  hit.point_m = ray.origin_m + nearest_m * ray.direction;
  hit.normal = surface_normal(object.shape, hit.point_m);
  if (hit.normal.dot(ray.direction) > 0.0) hit.normal = -hit.normal;
  hit.radiance = object.material.radiance(surface_coordinates(object.shape, hit.point_m), scene.ambient);
  hit.object_index = nearest_index;
  return hit;
}

}  // namespace lensmith
