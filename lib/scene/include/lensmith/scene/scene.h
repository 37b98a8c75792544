// An analytic scene: a camera pose, objects (shape + material), an ambient light and a background
// (docs/scene-format.md). Lengths are metres.
//
// Shading is deliberately simple, so that renders are fast and exactly reproducible: a surface
// point seen by a ray has the radiance
//     L = emission + albedo(s, t) x ambient        (per RGB channel)
// whatever its orientation and whatever lies between it and any light: an unshadowed "self-lit"
// model with no light transport between objects. Emission carries HDR highlights (values far above
// 1, e.g. 200). A ray that hits nothing sees `background`, at infinite depth.
#pragma once

#include <cstddef>
#include <ostream>
#include <string>
#include <vector>

#include "lensmith/color/rgb.h"
#include "lensmith/scene/camera_pose.h"
#include "lensmith/scene/scene_error.h"
#include "lensmith/scene/shape.h"
#include "lensmith/scene/texture.h"

namespace lensmith {

struct SceneMaterial {
  Rgb emission{0.0, 0.0, 0.0};               // emitted radiance, linear RGB, each finite and >= 0
  Texture albedo = ConstantTexture{};        // reflectance under the ambient light, >= 0 (default black)

  // Radiance of the surface at (s, t) under `ambient`: emission + albedo x ambient.
  Rgb radiance(const SurfaceCoordinates& at, const Rgb& ambient) const;
  std::string to_string() const;  // "material(emission RGB(...), albedo constant(RGB(...)))"
};

struct SceneObject {
  std::string name;  // optional, for messages
  SceneShape shape = Sphere{};
  SceneMaterial material;

  std::string to_string() const;
  friend std::ostream& operator<<(std::ostream& os, const SceneObject& o) { return os << o.to_string(); }
};

struct Scene {
  std::string name;
  CameraPose camera;
  Rgb ambient{1.0, 1.0, 1.0};     // light that every albedo reflects, linear RGB, each finite and >= 0
  Rgb background{0.0, 0.0, 0.0};  // radiance of rays that hit nothing (at infinite depth), >= 0
  std::vector<SceneObject> objects;

  // Throws SceneError naming the object ("objects[2] (sphere \"lamp\"): radius_m = -1: must be > 0"),
  // the camera or the colour that breaks a rule of shape.h, texture.h or camera_pose.h.
  void validate() const;

  std::string to_string() const;  // "Scene(\"name\", 5 objects, camera ..., ambient ..., background ...)"
  friend std::ostream& operator<<(std::ostream& os, const Scene& s) { return os << s.to_string(); }
};

// Throws SceneError("<what>: must be finite and >= 0, got RGB(...)") for a colour that is not.
void validate_colour(const Rgb& colour, const std::string& what);

}  // namespace lensmith
