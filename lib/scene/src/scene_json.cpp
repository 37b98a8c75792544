// The lensmith-scene format reader. Key-by-key reference: docs/scene-format.md.
#include "lensmith/scene/scene_json.h"

#include <cmath>
#include <map>
#include <memory>
#include <optional>
#include <sstream>

#include <Eigen/Geometry>

#include "lensmith/core/located_json.h"
#include "lensmith/core/text_file.h"
#include "lensmith/render/image_io.h"
#include "lensmith/scene/camera_pose.h"

namespace lensmith {

namespace {

using nlohmann::json;

constexpr const char* kFormatName = "lensmith-scene";
// Far beyond the tens of objects brute-force intersection is meant for; bounds hostile input.
constexpr std::size_t kMaxObjects = 100000;
// Shorter direction vectors carry no direction worth normalising (as shape.cpp and camera_pose.cpp).
constexpr double kMinDirectionLength = 1e-12;
// Seeds are 32-bit.
constexpr double kMaxSeed = 4294967295.0;

const std::vector<std::string> kTopKeys = {"format", "version", "name", "notes", "camera", "ambient", "background", "objects"};
const std::vector<std::string> kCameraKeys = {"position_m", "look_at_m", "look_direction", "up"};
const std::vector<std::string> kPlaneKeys = {"type", "name", "material", "point_m", "normal", "u_axis"};
const std::vector<std::string> kRectangleKeys = {"type", "name", "material", "centre_m", "half_u_m", "half_v_m"};
const std::vector<std::string> kDiscKeys = {"type", "name", "material", "centre_m", "normal", "radius_m", "u_axis"};
const std::vector<std::string> kSphereKeys = {"type", "name", "material", "centre_m", "radius_m"};
const std::vector<std::string> kMaterialKeys = {"emission", "albedo", "texture"};
const std::vector<std::string> kConstantKeys = {"type", "colour"};
const std::vector<std::string> kCheckerKeys = {"type", "size_m", "colours"};
const std::vector<std::string> kNoiseKeys = {"type", "scale_m", "octaves", "seed", "colours"};
const std::vector<std::string> kImageKeys = {"type", "file", "size_m"};

std::string number_text(double v) {
  std::ostringstream os;
  os.precision(6);
  os << v;
  return os.str();
}

[[noreturn]] void fail_at(const LocatedJson& doc, const std::string& pointer, const std::string& path, const std::string& message) {
  throw FileError(doc.where(pointer), path + ": " + message);
}

// A finite number at `pointer`.
double number_at(const LocatedJson& doc, const std::string& pointer, const std::string& path) {
  const json& v = doc.root().at(json::json_pointer(pointer));
  if (!v.is_number()) fail_at(doc, pointer, path, "expected a number, got " + json_type_phrase(v));
  const double x = v.get<double>();
  if (!std::isfinite(x)) fail_at(doc, pointer, path, "must be finite");
  return x;
}

// [x, y, z] at `pointer`: three finite numbers. `what` says what the vector is, for messages.
Eigen::Vector3d vector_at(const LocatedJson& doc, const std::string& pointer, const std::string& path, const std::string& what) {
  const json& v = doc.root().at(json::json_pointer(pointer));
  if (!v.is_array() || v.size() != 3) {
    fail_at(doc, pointer, path, "expected " + what + " [x, y, z] (3 numbers), got " +
                                    (v.is_array() ? "an array of " + std::to_string(v.size()) : json_type_phrase(v)));
  }
  Eigen::Vector3d out;
  for (int i = 0; i < 3; ++i) {
    const std::string index = std::to_string(i);
    out[i] = number_at(doc, pointer + "/" + index, path + "[" + index + "]");
  }
  return out;
}

// A colour at `pointer`: [r, g, b] or one number for grey; linear, each finite and >= 0.
Rgb colour_at(const LocatedJson& doc, const std::string& pointer, const std::string& path) {
  const json& v = doc.root().at(json::json_pointer(pointer));
  Rgb out;
  if (v.is_number()) {
    const double grey = number_at(doc, pointer, path);
    out = {grey, grey, grey};
  } else if (v.is_array() && v.size() == 3) {
    for (int c = 0; c < 3; ++c) out[c] = number_at(doc, pointer + "/" + std::to_string(c), path + "[" + std::to_string(c) + "]");
  } else {
    fail_at(doc, pointer, path, "expected a colour: [r, g, b] (3 numbers, linear) or one number for grey, got " +
                                    (v.is_array() ? "an array of " + std::to_string(v.size()) : json_type_phrase(v)));
  }
  for (int c = 0; c < 3; ++c) {
    if (out[c] < 0.0) fail_at(doc, pointer, path, "each channel must be >= 0, got " + out.to_string());
  }
  return out;
}

Eigen::Vector3d read_vector(JsonObjectReader& r, const std::string& key, const std::string& what) {
  if (!r.get(key)) r.fail("", "missing key \"" + key + "\" (" + what + " [x, y, z])");
  return vector_at(r.document(), r.child_pointer(key), r.child_path(key), what);
}

std::optional<Eigen::Vector3d> read_optional_vector(JsonObjectReader& r, const std::string& key, const std::string& what) {
  if (!r.get(key)) return std::nullopt;
  return vector_at(r.document(), r.child_pointer(key), r.child_path(key), what);
}

// A direction: a vector of non-zero length (it is normalised).
Eigen::Vector3d check_direction(JsonObjectReader& r, const std::string& key, const Eigen::Vector3d& v) {
  if (!(v.norm() > kMinDirectionLength)) {
    r.fail(key, format_vector(v) + " cannot be normalised: a direction must have a non-zero length");
  }
  return v;
}

Rgb read_colour(JsonObjectReader& r, const std::string& key) {
  r.get(key);
  return colour_at(r.document(), r.child_pointer(key), r.child_path(key));
}

std::array<Rgb, 2> read_colour_pair(JsonObjectReader& r, const std::string& key) {
  const json* v = r.get(key);
  if (!v) r.fail("", "missing key \"" + key + "\" (two colours [[r, g, b], [r, g, b]])");
  if (!v->is_array() || v->size() != 2) {
    r.fail(key, "expected two colours [[r, g, b], [r, g, b]], got " +
                    (v->is_array() ? "an array of " + std::to_string(v->size()) : json_type_phrase(*v)));
  }
  std::array<Rgb, 2> out;
  for (int i = 0; i < 2; ++i) {
    out[i] = colour_at(r.document(), r.child_pointer(key) + "/" + std::to_string(i), r.child_path(key) + "[" + std::to_string(i) + "]");
  }
  return out;
}

// A finite number > 0 (a length or size), required.
double read_positive(JsonObjectReader& r, const std::string& key, const std::string& what) {
  if (!r.has(key)) r.fail("", "missing key \"" + key + "\" (" + what + ")");
  const double v = r.get_number(key);
  if (!(std::isfinite(v) && v > 0.0)) r.fail(key, "must be finite and > 0, got " + number_text(v));
  return v;
}

// An optional integer in [lo, hi].
std::optional<double> read_optional_integer(JsonObjectReader& r, const std::string& key, double lo, double hi) {
  const auto v = r.get_optional_number(key);
  if (v && !(*v == std::floor(*v) && *v >= lo && *v <= hi)) {
    r.fail(key, "must be an integer in " + number_text(lo) + ".." + number_text(hi) + ", got " + number_text(*v));
  }
  return v;
}

// Runs a validate() of the model and reports its SceneError at the key it is about (its subject's
// field, without an index), or at the object when that is not one of the object's keys.
template <class F>
void validate_at(JsonObjectReader& r, F&& validate_fn) {
  try {
    validate_fn();
  } catch (const SceneError& e) {
    const std::string key = e.subject().field_root();
    throw FileError(r.where(r.has(key) ? key : std::string()), r.path() + "." + e.what());
  }
}

class SceneReader {
 public:
  SceneReader(const LocatedJson& doc, std::filesystem::path base_dir) : doc_(doc), base_dir_(std::move(base_dir)) {}

  Scene read() {
    JsonObjectReader top(doc_, "", "");
    Scene scene;
    const std::string format = top.get_string("format");
    if (format != kFormatName) top.fail("format", "expected \"" + std::string(kFormatName) + "\", got \"" + format + "\"");
    if (!top.has("version")) top.fail("", "missing key \"version\" (the format version, " + std::to_string(kSceneFormatVersion) + ")");
    const double version = top.get_number("version");
    if (version != std::floor(version) || version < 1 || version > kSceneFormatVersion) {
      top.fail("version", "this build reads version " + std::to_string(kSceneFormatVersion) + ", got " + number_text(version));
    }
    scene.name = top.get_optional_string("name").value_or("");
    top.get_optional_string("notes");
    if (top.has("camera")) scene.camera = read_camera(top);
    if (top.has("ambient")) scene.ambient = read_colour(top, "ambient");
    if (top.has("background")) scene.background = read_colour(top, "background");

    if (!top.has("objects")) top.fail("", "missing key \"objects\" (an array of plane, rectangle, disc and sphere objects)");
    const std::size_t count = top.get_array_size("objects");
    if (count > kMaxObjects) top.fail("objects", "more than 100000 objects");
    for (std::size_t i = 0; i < count; ++i) scene.objects.push_back(read_object(i));
    top.finish(kTopKeys);

    try {
      scene.validate();
    } catch (const SceneError& e) {  // every rule is checked at its key above; this is a backstop
      throw FileError(doc_.where(""), e.what());
    }
    return scene;
  }

 private:
  CameraPose read_camera(JsonObjectReader& top) {
    top.get("camera");
    JsonObjectReader r(doc_, top.child_pointer("camera"), "camera");
    CameraPose pose;
    pose.position_m = read_optional_vector(r, "position_m", "a position in metres").value_or(pose.position_m);
    if (r.has("look_at_m") && r.has("look_direction")) r.fail("look_direction", "give look_at_m or look_direction, not both");
    if (auto target = read_optional_vector(r, "look_at_m", "a point in metres")) {
      pose.look_direction = *target - pose.position_m;
      if (!(pose.look_direction.norm() > kMinDirectionLength)) r.fail("look_at_m", "must differ from position_m");
    }
    if (auto direction = read_optional_vector(r, "look_direction", "a direction")) {
      pose.look_direction = check_direction(r, "look_direction", *direction);
    }
    if (auto up = read_optional_vector(r, "up", "a direction")) pose.up = check_direction(r, "up", *up);
    r.finish(kCameraKeys);
    if (pose.up.normalized().cross(pose.look_direction.normalized()).norm() <= 1e-6) {
      r.fail(r.has("up") ? "up" : "", "up " + format_vector(pose.up) + " is parallel to the look direction " +
                                          format_vector(pose.look_direction) + "; give an up vector across it");
    }
    return pose;
  }

  SceneObject read_object(std::size_t index) {
    const std::string pointer = "/objects/" + std::to_string(index);
    JsonObjectReader r(doc_, pointer, "objects[" + std::to_string(index) + "]");
    SceneObject object;
    if (!r.has("type")) r.fail("", "missing key \"type\" (\"plane\", \"rectangle\", \"disc\" or \"sphere\")");
    const std::string type = r.get_string("type");
    object.name = r.get_optional_string("name").value_or("");
    const std::vector<std::string>* keys = nullptr;
    if (type == "plane") {
      Plane p;
      p.point_m = read_vector(r, "point_m", "a point in metres");
      p.normal = check_direction(r, "normal", read_vector(r, "normal", "a normal direction"));
      if (auto u = read_optional_vector(r, "u_axis", "a direction")) p.u_axis = check_direction(r, "u_axis", *u);
      object.shape = p;
      keys = &kPlaneKeys;
    } else if (type == "rectangle") {
      Rectangle rect;
      rect.centre_m = read_vector(r, "centre_m", "a point in metres");
      rect.half_u_m = check_direction(r, "half_u_m", read_vector(r, "half_u_m", "a half-edge in metres"));
      rect.half_v_m = check_direction(r, "half_v_m", read_vector(r, "half_v_m", "a half-edge in metres"));
      object.shape = rect;
      keys = &kRectangleKeys;
    } else if (type == "disc") {
      Disc d;
      d.centre_m = read_vector(r, "centre_m", "a point in metres");
      d.normal = check_direction(r, "normal", read_vector(r, "normal", "a normal direction"));
      d.radius_m = read_positive(r, "radius_m", "the radius in metres");
      if (auto u = read_optional_vector(r, "u_axis", "a direction")) d.u_axis = check_direction(r, "u_axis", *u);
      object.shape = d;
      keys = &kDiscKeys;
    } else if (type == "sphere") {
      Sphere s;
      s.centre_m = read_vector(r, "centre_m", "a point in metres");
      s.radius_m = read_positive(r, "radius_m", "the radius in metres");
      object.shape = s;
      keys = &kSphereKeys;
    } else {
      r.fail("type", "unknown object type \"" + type + "\"; expected \"plane\", \"rectangle\", \"disc\" or \"sphere\"");
    }
    validate_at(r, [&] { lensmith::validate(object.shape); });

    if (!r.has("material")) r.fail("", "missing key \"material\" (an object with emission, albedo or texture)");
    r.get("material");
    object.material = read_material(r.child_pointer("material"), r.child_path("material"), object.shape);
    r.finish(*keys);
    return object;
  }

  SceneMaterial read_material(const std::string& pointer, const std::string& path, const SceneShape& shape) {
    JsonObjectReader r(doc_, pointer, path);
    SceneMaterial m;
    if (!r.has("emission") && !r.has("albedo") && !r.has("texture")) {
      r.fail("", "a material needs at least one of emission, albedo, texture");
    }
    if (r.has("albedo") && r.has("texture")) r.fail("texture", "give albedo (a colour) or texture, not both");
    if (r.has("emission")) m.emission = read_colour(r, "emission");
    if (r.has("albedo")) m.albedo = ConstantTexture{read_colour(r, "albedo")};
    if (r.has("texture")) {
      r.get("texture");
      m.albedo = read_texture(r.child_pointer("texture"), r.child_path("texture"), shape);
    }
    r.finish(kMaterialKeys);
    return m;
  }

  Texture read_texture(const std::string& pointer, const std::string& path, const SceneShape& shape) {
    JsonObjectReader r(doc_, pointer, path);
    if (!r.has("type")) r.fail("", "missing key \"type\" (\"constant\", \"checker\", \"noise\" or \"image\")");
    const std::string type = r.get_string("type");
    Texture texture;
    if (type == "constant") {
      if (!r.has("colour")) r.fail("", "missing key \"colour\" ([r, g, b])");
      texture = ConstantTexture{read_colour(r, "colour")};
      r.finish(kConstantKeys);
    } else if (type == "checker") {
      CheckerTexture t;
      t.size_m = read_positive(r, "size_m", "the side of a square in metres");
      t.colours = read_colour_pair(r, "colours");
      texture = t;
      r.finish(kCheckerKeys);
    } else if (type == "noise") {
      NoiseTexture t;
      t.scale_m = read_positive(r, "scale_m", "the lattice spacing of the first octave in metres");
      t.octaves = static_cast<int>(read_optional_integer(r, "octaves", 1, 16).value_or(t.octaves));
      t.seed = static_cast<std::uint32_t>(read_optional_integer(r, "seed", 0, kMaxSeed).value_or(0.0));
      t.colours = read_colour_pair(r, "colours");
      texture = t;
      r.finish(kNoiseKeys);
    } else if (type == "image") {
      texture = read_image_texture(r, shape);
      r.finish(kImageKeys);
    } else {
      r.fail("type", "unknown texture type \"" + type + "\"; expected \"constant\", \"checker\", \"noise\" or \"image\"");
    }
    validate_at(r, [&] { lensmith::validate(texture); });
    return texture;
  }

  ImageTexture read_image_texture(JsonObjectReader& r, const SceneShape& shape) {
    ImageTexture t;
    if (!r.has("file")) r.fail("", "missing key \"file\" (a picture, relative to the scene file's folder)");
    const std::string file = r.get_string("file");
    if (file.empty()) r.fail("file", "empty file name");
    t.file = file;
    if (r.has("size_m")) {
      const json* v = r.get("size_m");
      if (!v->is_array() || v->size() != 2) {
        r.fail("size_m", "expected [width, height] in metres, got " +
                             (v->is_array() ? "an array of " + std::to_string(v->size()) : json_type_phrase(*v)));
      }
      t.width_m = number_at(doc_, r.child_pointer("size_m") + "/0", r.child_path("size_m") + "[0]");
      t.height_m = number_at(doc_, r.child_pointer("size_m") + "/1", r.child_path("size_m") + "[1]");
      if (!(t.width_m > 0.0 && t.height_m > 0.0)) r.fail("size_m", "width and height must be > 0");
    } else if (const Rectangle* rect = std::get_if<Rectangle>(&shape)) {
      t.width_m = 2.0 * rect->half_u_m.norm();
      t.height_m = 2.0 * rect->half_v_m.norm();
    } else {
      r.fail("", "missing key \"size_m\" ([width, height] in metres; only a rectangle defaults to its own size)");
    }
    const std::filesystem::path path = t.file.is_absolute() || base_dir_.empty() ? t.file : base_dir_ / t.file;
    auto cached = images_.find(path.string());
    if (cached != images_.end()) {
      t.image = cached->second;
    } else {
      try {
        t.image = std::make_shared<const Image>(read_radiance_image(path));
      } catch (const Error& e) {
        r.fail("file", "cannot use the picture " + path.string() + ": " + e.what());
      }
      images_.emplace(path.string(), t.image);
    }
    return t;
  }

  const LocatedJson& doc_;
  std::filesystem::path base_dir_;
  std::map<std::string, std::shared_ptr<const Image>> images_;  // each picture is read once
};

}  // namespace

Scene read_scene_json(std::string_view text, const std::string& file_name, const std::filesystem::path& base_dir) {
  const LocatedJson doc = LocatedJson::parse(text, file_name);
  return SceneReader(doc, base_dir).read();
}

Scene load_scene(const std::filesystem::path& path) {
  const std::string name = path.string();
  const std::string bytes = read_file_bytes(name);
  return read_scene_json(decode_text(bytes, name), name, path.parent_path());
}

}  // namespace lensmith
