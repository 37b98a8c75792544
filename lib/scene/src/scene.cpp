#include "lensmith/scene/scene.h"

#include <cmath>

namespace lensmith {

namespace {

bool usable(double v) { return std::isfinite(v) && v >= 0.0; }

}  // namespace

void validate_colour(const Rgb& colour, const std::string& what) {
  if (!(usable(colour.r) && usable(colour.g) && usable(colour.b))) {
    throw SceneError(ErrorSubject{0, what, -1}, what + " = " + colour.to_string() + ": each channel must be finite and >= 0");
  }
}

Rgb SceneMaterial::radiance(const SurfaceCoordinates& at, const Rgb& ambient) const {
  const Rgb albedo_here = evaluate(albedo, at);
  return {emission.r + albedo_here.r * ambient.r, emission.g + albedo_here.g * ambient.g, emission.b + albedo_here.b * ambient.b};
}

std::string SceneMaterial::to_string() const {
  return "material(emission " + emission.to_string() + ", albedo " + lensmith::to_string(albedo) + ")";
}

std::string SceneObject::to_string() const {
  std::string s = "SceneObject(";
  if (!name.empty()) s += "\"" + name + "\", ";
  return s + lensmith::to_string(shape) + ", " + material.to_string() + ")";
}

void Scene::validate() const {
  camera.validate();
  validate_colour(ambient, "ambient");
  validate_colour(background, "background");
  for (std::size_t i = 0; i < objects.size(); ++i) {
    const SceneObject& object = objects[i];
    std::string label = "objects[" + std::to_string(i) + "] (" + std::string(shape_type_name(object.shape));
    if (!object.name.empty()) label += " \"" + object.name + "\"";
    label += ")";
    try {
      lensmith::validate(object.shape);
    } catch (const SceneError& e) {
      throw SceneError(e.subject(), label + ": " + e.what());
    }
    try {
      validate_colour(object.material.emission, "emission");
      lensmith::validate(object.material.albedo);
    } catch (const SceneError& e) {
      throw SceneError(e.subject(), label + ": material: " + e.what());
    }
  }
}

std::string Scene::to_string() const {
  return "Scene(\"" + name + "\", " + std::to_string(objects.size()) + " objects, " + camera.to_string() + ", ambient " +
         ambient.to_string() + ", background " + background.to_string() + ")";
}

}  // namespace lensmith
