// `lensmith scene render` as a user runs it: the pinhole picture and its depth (the input of
// `lensmith bokeh`), the ground truth through a shipped lens, and a refused option combination.
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <string>

#include "lensmith/camera/pinhole_frame.h"
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
