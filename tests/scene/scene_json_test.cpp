// The lensmith-scene reader (docs/scene-format.md): a full file read key by key, and one test per
// rule of strict reading, each checking that the error names the file, the line of the offending
// value, the key's path and what was expected.
#include "lensmith/scene/scene_json.h"

#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include "lensmith/render/image_io.h"
#include "lensmith/scene/pinhole_render.h"
#include "lensmith/scene/scene_intersection.h"

using Catch::Matchers::Contains;
using Catch::Matchers::WithinAbs;
using namespace lensmith;
namespace fs = std::filesystem;

namespace {

// A fresh directory under the system temporary folder, removed with everything in it at the end.
struct TempDir {
  fs::path path;
  TempDir() {
    std::random_device rd;
    path = fs::temp_directory_path() / ("lensmith_scene_json_test_" + std::to_string(rd()) + std::to_string(rd()));
    fs::create_directories(path);
  }
  ~TempDir() {
    std::error_code ignored;
    fs::remove_all(path, ignored);
  }
  fs::path operator/(const std::string& name) const { return path / name; }
};

// A scene file whose line 4 is `object` (the single entry of "objects").
std::string with_object(const std::string& object) {
  return "{\"format\": \"lensmith-scene\", \"version\": 1,\n"
         " \"camera\": {\"position_m\": [0, 0, 0]},\n"
         " \"objects\": [\n" +
         object +
         "\n"
         " ]}\n";
}

// Reads `text` as "scene.json" and returns the FileError it must raise.
FileError read_error(const std::string& text) {
  try {
    read_scene_json(text, "scene.json");
  } catch (const FileError& e) {
    return e;
  }
  FAIL("no FileError for:\n" << text);
  throw std::logic_error("unreachable");
}

}  // namespace

TEST_CASE("a complete scene file is read key by key", "[scene][json]") {
  const std::string text = R"({
  "format": "lensmith-scene", "version": 1, "name": "test scene", "notes": "anything",
  "camera": {"position_m": [1, 2, 3], "look_at_m": [1, 2, 13], "up": [0, 2, 0]},
  "ambient": [0.5, 0.6, 0.7], "background": 0.25,
  "objects": [
    {"type": "plane", "name": "floor", "point_m": [0, -1, 0], "normal": [0, 2, 0], "u_axis": [1, 0, 1],
     "material": {"texture": {"type": "checker", "size_m": 0.1, "colours": [[0.8, 0.8, 0.8], [0.1, 0.1, 0.1]]}}},
    {"type": "rectangle", "centre_m": [0, 0, 3], "half_u_m": [1.5, 0, 0], "half_v_m": [0, 1, 0],
     "material": {"texture": {"type": "noise", "scale_m": 0.2, "octaves": 3, "seed": 9, "colours": [0, [1, 1, 1]]}}},
    {"type": "disc", "centre_m": [0, 0, 2], "normal": [0, 0, -1], "radius_m": 0.25, "material": {"albedo": [0.3, 0.2, 0.1], "emission": 2}},
    {"type": "sphere", "centre_m": [0.2, 0.1, 5], "radius_m": 0.01, "material": {"emission": [100, 80, 60]}},
    {"type": "sphere", "centre_m": [0, 0, 9], "radius_m": 1, "material": {"texture": {"type": "constant", "colour": [0.1, 0.2, 0.3]}}}
  ]
})";
  const Scene scene = read_scene_json(text, "scene.json");
  CHECK(scene.name == "test scene");
  CHECK(scene.camera.position_m == Eigen::Vector3d(1, 2, 3));
  CHECK(scene.camera.look_direction == Eigen::Vector3d(0, 0, 10));
  CHECK(scene.camera.up == Eigen::Vector3d(0, 2, 0));
  CHECK(scene.ambient.g == 0.6);
  CHECK(scene.background.r == 0.25);
  CHECK(scene.background.b == 0.25);
  REQUIRE(scene.objects.size() == 5);

  const auto& floor = std::get<Plane>(scene.objects[0].shape);
  CHECK(scene.objects[0].name == "floor");
  CHECK(floor.normal == Eigen::Vector3d(0, 2, 0));
  REQUIRE(floor.u_axis);
  CHECK(*floor.u_axis == Eigen::Vector3d(1, 0, 1));
  CHECK(std::get<CheckerTexture>(scene.objects[0].material.albedo).size_m == 0.1);

  const auto& rect = std::get<Rectangle>(scene.objects[1].shape);
  CHECK(rect.half_u_m == Eigen::Vector3d(1.5, 0, 0));
  const auto& noise = std::get<NoiseTexture>(scene.objects[1].material.albedo);
  CHECK(noise.octaves == 3);
  CHECK(noise.seed == 9u);
  CHECK(noise.colours[0].g == 0.0);

  const auto& disc = std::get<Disc>(scene.objects[2].shape);
  CHECK(disc.radius_m == 0.25);
  CHECK(scene.objects[2].material.emission.b == 2.0);
  CHECK(std::get<ConstantTexture>(scene.objects[2].material.albedo).colour.r == 0.3);

  CHECK(std::get<Sphere>(scene.objects[3].shape).radius_m == 0.01);
  CHECK(scene.objects[3].material.emission.r == 100.0);
  CHECK(std::get<ConstantTexture>(scene.objects[3].material.albedo).colour.g == 0.0);  // no albedo: black
  CHECK(std::get<ConstantTexture>(scene.objects[4].material.albedo).colour.b == 0.3);
}

TEST_CASE("a scene file with no camera, ambient or background gets the documented defaults", "[scene][json]") {
  const Scene scene = read_scene_json(R"({"format": "lensmith-scene", "version": 1, "objects": []})", "scene.json");
  CHECK(scene.camera.position_m == Eigen::Vector3d(0, 0, 0));
  CHECK(scene.camera.look_direction == Eigen::Vector3d(0, 0, 1));
  CHECK(scene.camera.up == Eigen::Vector3d(0, 1, 0));
  CHECK(scene.ambient.r == 1.0);
  CHECK(scene.background.g == 0.0);
  CHECK(scene.objects.empty());
}

TEST_CASE("an unknown key is an error at its line naming the allowed keys", "[scene][json]") {
  const FileError e = read_error(with_object(
      R"(  {"type": "sphere", "centre_m": [0, 0, 3], "radius_m": 1, "colour": [1, 0, 0], "material": {"albedo": 0.5}})"));
  CHECK(e.where().file == "scene.json");
  CHECK(e.where().line == 4);
  CHECK_THAT(e.what(), Contains("scene.json:4:"));
  CHECK_THAT(e.what(), Contains("objects[0].colour: unknown key"));
  CHECK_THAT(e.what(), Contains("radius_m"));
}

TEST_CASE("an unknown key in a nested texture is an error at its line", "[scene][json]") {
  const FileError e = read_error(with_object(
      R"(  {"type": "sphere", "centre_m": [0, 0, 3], "radius_m": 1, "material": {"texture": {"type": "checker", "size_m": 1, "colours": [0, 1], "scale_m": 2}}})"));
  CHECK(e.where().line == 4);
  CHECK_THAT(e.what(), Contains("objects[0].material.texture.scale_m: unknown key"));
}

TEST_CASE("a value of the wrong type is an error at its line saying what was expected", "[scene][json]") {
  const FileError e = read_error(with_object(R"(  {"type": "sphere", "centre_m": [0, 0, 3], "radius_m": "1", "material": {"albedo": 0.5}})"));
  CHECK(e.where().line == 4);
  CHECK(e.where().column == 57);
  CHECK_THAT(e.what(), Contains("scene.json:4:57: objects[0].radius_m: expected a number, got a string"));
}

TEST_CASE("a vector of the wrong length is an error naming the expected form", "[scene][json]") {
  const FileError e = read_error(with_object(R"(  {"type": "sphere", "centre_m": [0, 3], "radius_m": 1, "material": {"albedo": 0.5}})"));
  CHECK(e.where().line == 4);
  CHECK_THAT(e.what(), Contains("objects[0].centre_m: expected a point in metres [x, y, z] (3 numbers), got an array of 2"));
}

TEST_CASE("a missing required key is named with the line of its object", "[scene][json]") {
  const FileError e = read_error(with_object(R"(  {"type": "sphere", "centre_m": [0, 0, 3], "material": {"albedo": 0.5}})"));
  CHECK(e.where().line == 4);
  CHECK(e.where().column == 3);
  CHECK_THAT(e.what(), Contains("objects[0]: missing key \"radius_m\""));
}

TEST_CASE("a missing material is named with the line of its object", "[scene][json]") {
  const FileError e = read_error(with_object(R"(  {"type": "sphere", "centre_m": [0, 0, 3], "radius_m": 1})"));
  CHECK(e.where().line == 4);
  CHECK_THAT(e.what(), Contains("objects[0]: missing key \"material\""));
}

TEST_CASE("a missing objects array is named at the top of the file", "[scene][json]") {
  const FileError e = read_error("{\"format\": \"lensmith-scene\",\n \"version\": 1}");
  CHECK(e.where().line == 1);
  CHECK_THAT(e.what(), Contains("missing key \"objects\""));
}

TEST_CASE("a negative radius is an error at its line", "[scene][json]") {
  const FileError e = read_error(with_object(R"(  {"type": "disc", "centre_m": [0, 0, 3], "normal": [0, 0, 1], "radius_m": -0.5, "material": {"albedo": 0.5}})"));
  CHECK(e.where().line == 4);
  CHECK_THAT(e.what(), Contains("objects[0].radius_m: must be finite and > 0, got -0.5"));
}

TEST_CASE("a normal that cannot be normalised is an error at its line", "[scene][json]") {
  const FileError e = read_error(with_object(R"(  {"type": "plane", "point_m": [0, 0, 3], "normal": [0, 0, 0], "material": {"albedo": 0.5}})"));
  CHECK(e.where().line == 4);
  CHECK_THAT(e.what(), Contains("objects[0].normal: [0, 0, 0] cannot be normalised"));
}

TEST_CASE("a u_axis along the normal is an error at the u_axis", "[scene][json]") {
  const FileError e = read_error(with_object(
      R"(  {"type": "plane", "point_m": [0, 0, 3], "normal": [0, 0, -1], "u_axis": [0, 0, 2], "material": {"albedo": 0.5}})"));
  CHECK(e.where().line == 4);
  CHECK(e.where().column == 75);
  CHECK_THAT(e.what(), Contains("objects[0].u_axis = [0, 0, 2]: is parallel to the normal"));
}

TEST_CASE("rectangle half-edges that are not perpendicular are an error naming both", "[scene][json]") {
  const FileError e = read_error(with_object(
      R"(  {"type": "rectangle", "centre_m": [0, 0, 3], "half_u_m": [1, 0, 0], "half_v_m": [0.1, 1, 0], "material": {"albedo": 0.5}})"));
  CHECK(e.where().line == 4);
  CHECK_THAT(e.what(), Contains("must be perpendicular"));
  CHECK_THAT(e.what(), Contains("half_v_m = [0.1, 1, 0]"));
}

TEST_CASE("an unknown object type is an error listing the known ones", "[scene][json]") {
  const FileError e = read_error(with_object(R"(  {"type": "cube", "centre_m": [0, 0, 3], "material": {"albedo": 0.5}})"));
  CHECK(e.where().line == 4);
  CHECK_THAT(e.what(), Contains("unknown object type \"cube\"; expected \"plane\", \"rectangle\", \"disc\" or \"sphere\""));
}

TEST_CASE("an unknown texture type is an error listing the known ones", "[scene][json]") {
  const FileError e = read_error(with_object(
      R"(  {"type": "sphere", "centre_m": [0, 0, 3], "radius_m": 1, "material": {"texture": {"type": "marble"}}})"));
  CHECK(e.where().line == 4);
  CHECK_THAT(e.what(), Contains("objects[0].material.texture.type: unknown texture type \"marble\""));
}

TEST_CASE("a material with both albedo and texture is an error", "[scene][json]") {
  const FileError e = read_error(with_object(
      R"(  {"type": "sphere", "centre_m": [0, 0, 3], "radius_m": 1, "material": {"albedo": 0.5, "texture": {"type": "constant", "colour": 1}}})"));
  CHECK_THAT(e.what(), Contains("objects[0].material.texture: give albedo (a colour) or texture, not both"));
}

TEST_CASE("an empty material is an error naming what it needs", "[scene][json]") {
  const FileError e = read_error(with_object(R"(  {"type": "sphere", "centre_m": [0, 0, 3], "radius_m": 1, "material": {}})"));
  CHECK_THAT(e.what(), Contains("objects[0].material: a material needs at least one of emission, albedo, texture"));
}

TEST_CASE("a negative colour channel is an error at the colour", "[scene][json]") {
  const FileError e = read_error(with_object(
      R"(  {"type": "sphere", "centre_m": [0, 0, 3], "radius_m": 1, "material": {"emission": [1, -2, 3]}})"));
  CHECK(e.where().line == 4);
  CHECK_THAT(e.what(), Contains("objects[0].material.emission: each channel must be >= 0"));
}

TEST_CASE("a noise texture's octaves must be an integer in 1 to 16", "[scene][json]") {
  const FileError e = read_error(with_object(
      R"(  {"type": "sphere", "centre_m": [0, 0, 3], "radius_m": 1, "material": {"texture": {"type": "noise", "scale_m": 1, "octaves": 2.5, "colours": [0, 1]}}})"));
  CHECK_THAT(e.what(), Contains("objects[0].material.texture.octaves: must be an integer in 1..16, got 2.5"));
}

TEST_CASE("a checker needs exactly two colours", "[scene][json]") {
  const FileError e = read_error(with_object(
      R"(  {"type": "sphere", "centre_m": [0, 0, 3], "radius_m": 1, "material": {"texture": {"type": "checker", "size_m": 1, "colours": [0, 1, 0.5]}}})"));
  CHECK_THAT(e.what(), Contains("objects[0].material.texture.colours: expected two colours"));
}

TEST_CASE("the format name and version are checked", "[scene][json]") {
  CHECK_THAT(read_error(R"({"format": "lensmith-lens", "version": 1, "objects": []})").what(),
             Contains("format: expected \"lensmith-scene\", got \"lensmith-lens\""));
  CHECK_THAT(read_error(R"({"format": "lensmith-scene", "version": 2, "objects": []})").what(),
             Contains("version: this build reads version 1, got 2"));
}

TEST_CASE("a JSON syntax error names its line", "[scene][json]") {
  const FileError e = read_error("{\"format\": \"lensmith-scene\",\n \"version\": 1,\n \"objects\": [,]}");
  CHECK(e.where().line == 3);
}

TEST_CASE("a camera whose up vector is along its look direction is an error at up", "[scene][json]") {
  const FileError e = read_error(
      "{\"format\": \"lensmith-scene\", \"version\": 1,\n \"camera\": {\"look_at_m\": [0, 0, 5],\n \"up\": [0, 0, 1]},\n \"objects\": []}");
  CHECK(e.where().line == 3);
  CHECK_THAT(e.what(), Contains("camera.up: up [0, 0, 1] is parallel to the look direction"));
}

TEST_CASE("a camera looking at its own position is an error at look_at_m", "[scene][json]") {
  const FileError e = read_error(
      "{\"format\": \"lensmith-scene\", \"version\": 1,\n \"camera\": {\"position_m\": [1, 1, 1], \"look_at_m\": [1, 1, 1]},\n \"objects\": []}");
  CHECK(e.where().line == 2);
  CHECK_THAT(e.what(), Contains("camera.look_at_m: must differ from position_m"));
}

TEST_CASE("an image texture that cannot be read is an error at its file key quoting the path", "[scene][json]") {
  const FileError e = read_error(with_object(
      R"(  {"type": "rectangle", "centre_m": [0, 0, 3], "half_u_m": [1, 0, 0], "half_v_m": [0, 1, 0], "material": {"texture": {"type": "image", "file": "no-such-picture.exr"}}})"));
  CHECK(e.where().line == 4);
  CHECK_THAT(e.what(), Contains("objects[0].material.texture.file: cannot use the picture no-such-picture.exr"));
}

TEST_CASE("an image texture on a sphere needs an explicit size", "[scene][json]") {
  const FileError e = read_error(with_object(
      R"(  {"type": "sphere", "centre_m": [0, 0, 3], "radius_m": 1, "material": {"texture": {"type": "image", "file": "x.exr"}}})"));
  CHECK_THAT(e.what(), Contains("objects[0].material.texture: missing key \"size_m\""));
}

TEST_CASE("a scene file that cannot be opened is an IoError naming it", "[scene][json]") {
  CHECK_THROWS_AS(load_scene("/nonexistent/folder/scene.json"), IoError);
  CHECK_THROWS_WITH(load_scene("/nonexistent/folder/scene.json"), Contains("/nonexistent/folder/scene.json"));
}

TEST_CASE("an image texture on a rectangle that fills the frame reproduces the picture pixel for pixel", "[scene][json]") {
  // A 4 x 2 picture with a different colour in every pixel, read relative to the scene file's folder.
  TempDir dir;
  Image picture(4, 2, 3);
  for (int y = 0; y < 2; ++y) {
    for (int x = 0; x < 4; ++x) {
      for (int c = 0; c < 3; ++c) picture.at(x, y, c) = 0.1f * static_cast<float>(1 + x + 4 * y) + 0.01f * static_cast<float>(c);
    }
  }
  write_float_exr(dir / "picture.exr", picture, {"R", "G", "B"});
  {
    std::ofstream out(dir / "scene.json");
    // f = 4 px at z = 2 m: the 4 x 2 frame spans x in [-1, 1] m and y in [-0.5, 0.5] m.
    out << R"({"format": "lensmith-scene", "version": 1, "objects": [
      {"type": "rectangle", "centre_m": [0, 0, 2], "half_u_m": [1, 0, 0], "half_v_m": [0, 0.5, 0],
       "material": {"texture": {"type": "image", "file": "picture.exr"}}}]})";
  }
  const Scene scene = load_scene(dir / "scene.json");
  const auto& texture = std::get<ImageTexture>(scene.objects[0].material.albedo);
  CHECK(texture.width_m == 2.0);   // the rectangle's own size by default
  CHECK(texture.height_m == 1.0);
  const PinholeRender out = render_pinhole(scene, PinholeFrame(4, 2, 4.0), {1, 0});
  // Pixel centres fall on texel centres: bilinear interpolation returns each texel, so only the
  // double arithmetic of the mapping (~1e-16) separates them.
  for (int y = 0; y < 2; ++y) {
    for (int x = 0; x < 4; ++x) {
      for (int c = 0; c < 3; ++c) {
        INFO("pixel (" << x << ", " << y << "), channel " << c);
        CHECK_THAT(out.rgb.at(x, y, c), WithinAbs(picture.at(x, y, c), 1e-6));
      }
    }
  }
}
