// `lensmith scene render` as a user runs it: the pinhole picture and its depth (the input of
// `lensmith bokeh`), the ground truth through a shipped lens, and a refused option combination.
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <string>

#include "lensmith/camera/pinhole_frame.h"
#include "lensmith/render/deep_image.h"
#include "lensmith/render/image_io.h"
#include "run_lensmith.h"

using lensmith::testing::run_lensmith;
namespace fs = std::filesystem;

namespace {

std::string metadata(const fs::path& file, const std::string& name) {
  for (const auto& [key, value] : lensmith::read_image_metadata(file)) {
    if (key == name) return value;
  }
  return {};
}

}  // namespace

TEST_CASE("lensmith scene render --pinhole writes the all-in-focus picture and its planar depth", "[cli][scene]") {
  const fs::path dir = fs::temp_directory_path() / ("lensmith_scene_cli_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string scene = std::string(LENSMITH_SOURCE_DIR) + "/examples/scenes/occluder.json";
  const auto r = run_lensmith("scene render " + scene + " --pinhole -o " + (dir / "x.exr").string() + " --depth " +
                              (dir / "d.exr").string() + " --width 64 --height 36 --quiet");
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const lensmith::Image image = lensmith::read_radiance_image(dir / "x.exr");
  CHECK(image.width == 64);
  CHECK(image.height == 36);
  CHECK(metadata(dir / "x.exr", "lensmith:model") == "pinhole");
  // The frame `lensmith bokeh` assumes: 36 mm sensor behind a 50 mm pinhole. Every pixel of the
  // occluder scene sees the wall at 3 m, the disc at 1 m, the bar at 1.2 m or a highlight at 2.9 m.
  const lensmith::PinholeFrame frame(64, 36, 50.0 / (36.0 / 64.0));
  const lensmith::DepthMap depth = lensmith::read_depth({dir / "d.exr", ""}, {}, frame);
  CHECK(depth.at(0, 0) == 3.0f);  // the checker wall, fronto-parallel
  float nearest = 1e9f;
  for (float z : depth.z_m) nearest = std::min(nearest, z);
  CHECK_THAT(nearest, Catch::Matchers::WithinAbs(1.0, 1e-6));  // the red disc's plane
  fs::remove_all(dir);
}

TEST_CASE("lensmith scene render --pinhole --layers writes a deep EXR of the hidden surfaces, which lensmith bokeh reads as layers",
          "[cli][scene][layers]") {
  const fs::path dir = fs::temp_directory_path() / ("lensmith_scene_layers_cli_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string scene = std::string(LENSMITH_SOURCE_DIR) + "/examples/scenes/occluder.json";
  const fs::path deep = dir / "layers.exr", flat = dir / "flat.exr";
  const auto r = run_lensmith("scene render " + scene + " --pinhole --layers 3 -o " + deep.string() + " --width 64 --height 36");
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  REQUIRE(run_lensmith("scene render " + scene + " --pinhole -o " + flat.string() + " --width 64 --height 36 --quiet").exit_code == 0);
  CHECK(metadata(deep, "lensmith:focal_length_mm") == "50");
  CHECK(metadata(deep, "lensmith:layers") == "3");
  const lensmith::PinholeFrame frame(64, 36, 50.0 / (36.0 / 64.0));
  const lensmith::DeepImage layers = lensmith::read_deep_image(deep, {}, frame);
  // Behind the red disc (at 1 m, left of centre) the checker wall at 3 m is in the file.
  const auto behind_disc = layers.pixel(28, 18);
  REQUIRE(behind_disc.size() >= 2);
  CHECK_THAT(behind_disc.front().z_m, Catch::Matchers::WithinAbs(1.0, 1e-5));
  CHECK_THAT(behind_disc.back().z_m, Catch::Matchers::WithinAbs(3.0, 1e-5));
  // Flattened, it is the pinhole picture, but where the textured wall behind an edge differs from
  // its visible part (edge pixels: 3 % of the values at this small size, 0.03 % at 640 x 360).
  const lensmith::Image composite = layers.flatten(), picture = lensmith::read_radiance_image(flat);
  int differing = 0;
  for (int y = 0; y < 36; ++y) {
    for (int x = 0; x < 64; ++x) {
      for (int c = 0; c < 3; ++c) differing += std::abs(composite.at(x, y, c) - picture.at(x, y, c)) > 1e-5f ? 1 : 0;
    }
  }
  CHECK(differing < 64 * 36 * 3 * 5 / 100);
  // lensmith bokeh reads it as layered input, with its framing from the file.
  const auto b = run_lensmith("bokeh --image " + deep.string() + " --thin-lens --focal-length 50 --fstop 2 --focus 1 -o " +
                              (dir / "bokeh.exr").string());
  INFO(b.err);
  CHECK(b.exit_code == 0);
  CHECK(b.err.find("layered input") != std::string::npos);
  CHECK(b.err.find("pinhole focal length 50 mm") != std::string::npos);
  // A deep file is OpenEXR only, and carries its depth.
  const auto png = run_lensmith("scene render " + scene + " --pinhole --layers 2 -o " + (dir / "x.png").string());
  CHECK(png.exit_code == 2);
  CHECK(png.err.find("--layers writes a deep OpenEXR") != std::string::npos);
  CHECK(run_lensmith("scene render " + scene + " --pinhole --layers 2 --depth " + (dir / "z.exr").string() + " -o " + deep.string())
            .exit_code == 2);
  fs::remove_all(dir);
}

TEST_CASE("lensmith scene render --lens renders the ground truth through a shipped lens", "[cli][scene]") {
  const fs::path dir = fs::temp_directory_path() / ("lensmith_scene_cli_lens_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string scene = std::string(LENSMITH_SOURCE_DIR) + "/examples/scenes/occluder.json";
  const fs::path out = dir / "truth.exr";
  const auto r = run_lensmith("scene render " + scene + " --lens sasian-triplet --fstop 8 --focus 3 --spp 4 --width 64 --height 36 -o " +
                              out.string() + " --quiet");
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  // --quiet: nothing on stderr but errors; what was done is in the file's metadata.
  CHECK(r.err.empty());
  bool spp_recorded = false;
  for (const auto& [key, value] : lensmith::read_image_metadata(out)) spp_recorded = spp_recorded || (key.find("spp") != std::string::npos && value == "4");
  CHECK(spp_recorded);
  const lensmith::Image image = lensmith::read_radiance_image(out);
  CHECK(image.width == 64);
  CHECK(image.height == 36);
  CHECK(image.mean(1) > 0.0);
  CHECK(metadata(out, "lensmith:model") == "exact trace ground truth");
  CHECK(metadata(out, "lensmith:spp") == "4");
  fs::remove_all(dir);
}

TEST_CASE("lensmith scene render refuses --pinhole with --lens, a lens render without --focus, and overwriting the scene",
          "[cli][scene]") {
  const std::string scene = std::string(LENSMITH_SOURCE_DIR) + "/examples/scenes/occluder.json";
  const fs::path out = fs::temp_directory_path() / ("lensmith_scene_cli_bad_" + std::to_string(::getpid()) + ".exr");
  const auto both = run_lensmith("scene render " + scene + " --pinhole --lens sasian-triplet -o " + out.string());
  CHECK(both.exit_code == 2);
  CHECK(both.err.find("--pinhole excludes --lens") != std::string::npos);
  const auto no_focus = run_lensmith("scene render " + scene + " --lens sasian-triplet -o " + out.string());
  CHECK(no_focus.exit_code == 2);
  CHECK(no_focus.err.find("--focus") != std::string::npos);
  const auto none = run_lensmith("scene render " + scene + " -o " + out.string());
  CHECK(none.exit_code == 2);
  CHECK(none.err.find("--pinhole, --lens LENS or --thin-lens") != std::string::npos);
  const auto overwrite = run_lensmith("scene render " + scene + " --pinhole -o " + scene);
  CHECK(overwrite.exit_code == 2);
  CHECK(overwrite.err.find("never overwrites its inputs") != std::string::npos);
  CHECK_FALSE(fs::exists(out));
}
