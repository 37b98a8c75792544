// lensmith bokeh --frames: a shot rendered frame by frame (docs/sequences.md).
#include <catch2/catch.hpp>

#include <filesystem>
#include <string>
#include <vector>

#include "lensmith/render/image.h"
#include "lensmith/render/image_io.h"
#include "run_lensmith.h"

namespace fs = std::filesystem;
using lensmith::testing::run_lensmith;

namespace {

const std::string kScene = std::string(LENSMITH_SOURCE_DIR) + "/examples/bokeh-scene.exr";
// A quick camera: an ideal thin lens, no spectral colour (each frame ~0.1 s).
const std::string kCamera = " --thin-lens --focal-length 50 --fstop 2.8 --no-spectral --quiet";

// A folder holding frames 1001-1004 of a "shot": copies of the bundled scene.
struct Shot {
  lensmith::testing::ScratchFolder folder{"lensmith_sequence_cli_"};
  Shot() {
    for (int frame = 1001; frame <= 1004; ++frame) fs::copy_file(kScene, folder.dir / ("in." + std::to_string(frame) + ".exr"));
  }
  std::string path(const std::string& name) const { return (folder.dir / name).string(); }
};

bool same_pixels(const std::string& a, const std::string& b) {
  return lensmith::read_radiance_image(a).data == lensmith::read_radiance_image(b).data;
}

std::string meta(const std::string& file, const std::string& key) {
  for (const auto& [k, v] : lensmith::read_image_metadata(file)) {
    if (k == key) return v;
  }
  return "";
}

}  // namespace

TEST_CASE("a focus pull keyed in a curve file renders each frame as a single run at the interpolated focus", "[cli][sequence]") {
  const Shot shot;
  // 1.2 + (1/3) (4.2 - 1.2) in double, a few ulps; lensmith:focus_m is a double attribute, read back exactly.
  constexpr double kLerpRounding = 1e-12;
  // Keys at 1001 (1.2 m) and 1004 (4.2 m): frame 1002 is at 2.2 m by linear interpolation.
  const std::string curves = shot.folder.file("pull.csv", "# a focus pull\nframe,focus_m\n1001,1.2\n1004,4.2\n");
  const auto r = run_lensmith("bokeh --image " + shot.path("in.####.exr") + " -o " + shot.path("out.%04d.exr") +
                              " --frames 1001-1004 --curves " + curves + kCamera);
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  for (int frame = 1001; frame <= 1004; ++frame) REQUIRE(fs::exists(shot.path("out." + std::to_string(frame) + ".exr")));
  CHECK(std::stod(meta(shot.path("out.1002.exr"), "lensmith:focus_m")) == Approx(2.2).epsilon(kLerpRounding));
  const auto single = run_lensmith("bokeh --image " + shot.path("in.1002.exr") + " -o " + shot.path("single.exr") + " --focus 2.2" + kCamera);
  REQUIRE(single.exit_code == 0);
  CHECK(same_pixels(shot.path("out.1002.exr"), shot.path("single.exr")));
  CHECK_FALSE(same_pixels(shot.path("out.1001.exr"), shot.path("out.1004.exr")));  // the focus moved
}

TEST_CASE("chunks of a shot render the same frames as the whole shot, bit for bit", "[cli][sequence]") {
  const Shot shot;
  const std::string common = " --frames 1001-1004 --focus 2" + kCamera;
  REQUIRE(run_lensmith("bokeh --image " + shot.path("in.####.exr") + " -o " + shot.path("whole.####.exr") + common).exit_code == 0);
  for (const char* chunk : {"0/2", "1/2"}) {
    REQUIRE(run_lensmith("bokeh --image " + shot.path("in.####.exr") + " -o " + shot.path("chunk.@@@@.exr") + common + " --chunk " + chunk)
                .exit_code == 0);
  }
  for (int frame = 1001; frame <= 1004; ++frame) {
    CHECK(same_pixels(shot.path("whole." + std::to_string(frame) + ".exr"), shot.path("chunk." + std::to_string(frame) + ".exr")));
  }
  // Chunk 1 of 2 is frames 1003 and 1004 only.
  const Shot other;
  REQUIRE(run_lensmith("bokeh --image " + other.path("in.####.exr") + " -o " + other.path("c.####.exr") + common + " --chunk 1/2").exit_code == 0);
  CHECK_FALSE(fs::exists(other.path("c.1002.exr")));
  CHECK(fs::exists(other.path("c.1003.exr")));
}

TEST_CASE("a failing frame is named, leaves no file, and the others are written, and the exit code says some failed", "[cli][sequence]") {
  const Shot shot;
  fs::resize_file(shot.path("in.1003.exr"), 100);  // a truncated frame
  const auto r = run_lensmith("bokeh --image " + shot.path("in.####.exr") + " -o " + shot.path("out.####.exr") + " --frames 1001-1004 --focus 2" +
                              " --thin-lens --focal-length 50 --fstop 2.8 --no-spectral");
  INFO(r.err);
  CHECK(r.exit_code == 7);
  CHECK(r.err.find("frame 1003: error:") != std::string::npos);
  CHECK(r.err.find("3 written, 0 skipped (output exists), 1 failed (frames 1003)") != std::string::npos);
  CHECK(fs::exists(shot.path("out.1004.exr")));
  CHECK_FALSE(fs::exists(shot.path("out.1003.exr")));
  // Nothing half-written beside the outputs: only the inputs and the three frames.
  std::size_t files = 0;
  for (const auto& entry : fs::directory_iterator(shot.folder.dir)) files += entry.is_regular_file();
  CHECK(files == 4 + 3);

  // Resumed with --skip-existing once the frame is repaired: only 1003 is rendered.
  fs::copy_file(kScene, shot.path("in.1003.exr"), fs::copy_options::overwrite_existing);
  const auto before = fs::last_write_time(shot.path("out.1001.exr"));
  const auto again = run_lensmith("bokeh --image " + shot.path("in.####.exr") + " -o " + shot.path("out.####.exr") + " --frames 1001-1004 --focus 2" +
                                  " --thin-lens --focal-length 50 --fstop 2.8 --no-spectral --skip-existing");
  INFO(again.err);
  CHECK(again.exit_code == 0);
  CHECK(again.err.find("1 written, 3 skipped") != std::string::npos);
  CHECK(fs::last_write_time(shot.path("out.1001.exr")) == before);
  CHECK(fs::exists(shot.path("out.1003.exr")));
}

TEST_CASE("a shot's command line is checked before any frame is rendered", "[cli][sequence]") {
  const Shot shot;
  const std::string in = shot.path("in.####.exr");
  auto r = run_lensmith("bokeh --image " + shot.path("in.1001.exr") + " -o " + shot.path("o.####.exr") + " --frames 1001-1002 --focus 2" + kCamera);
  CHECK(r.exit_code == 2);
  CHECK(r.err.find("names one file") != std::string::npos);
  r = run_lensmith("bokeh --image " + in + " -o " + shot.path("o.exr") + " --frames 1001-1002 --focus 2" + kCamera);
  CHECK(r.exit_code == 2);
  r = run_lensmith("bokeh --image " + in + " -o " + shot.path("o.####.exr") + " --frames 1004-1001 --focus 2" + kCamera);
  CHECK(r.exit_code == 2);
  CHECK(r.err.find("runs backwards") != std::string::npos);
  const std::string curves = shot.folder.file("c.json", "{\"focus_m\": [[1001, 2.0]], \"zoom\": [[1001, 1]]}");
  r = run_lensmith("bokeh --image " + in + " -o " + shot.path("o.####.exr") + " --frames 1001-1002 --curves " + curves + kCamera);
  CHECK(r.exit_code == 3);
  CHECK(r.err.find("c.json:1:") != std::string::npos);
  CHECK(r.err.find("unknown curve \"zoom\"") != std::string::npos);
  r = run_lensmith("bokeh --image " + in + " -o " + shot.path("o.####.exr") + " --frames 1001-1002 --focus 2 --chunk 2/2" + kCamera);
  CHECK(r.exit_code == 2);
  r = run_lensmith("bokeh --image " + in + " -o " + shot.path("o.####.exr") + " --focus 2" + kCamera);  // a pattern, no --frames
  CHECK(r.exit_code == 2);
  CHECK(r.err.find("--frames") != std::string::npos);
  CHECK_FALSE(fs::exists(shot.path("o.1001.exr")));
}

TEST_CASE("listing frames (--list-frames) prints the frames a chunk would render, one per line, and renders nothing", "[cli][sequence]") {
  const Shot shot;
  // 1001-1010x3 is 1001, 1004, 1007, 1010; chunk 1 of 2 is the last two.
  const auto r = run_lensmith("bokeh --image " + shot.path("in.####.exr") + " -o " + shot.path("out.####.exr") +
                              " --frames 1001-1010x3 --chunk 1/2 --list-frames" + kCamera);
  REQUIRE(r.exit_code == 0);
  CHECK(r.out == "1007\n1010\n");
  CHECK_FALSE(fs::exists(shot.path("out.1007.exr")));
  // It checks what a farm script would submit: a bad frame list is a usage error.
  CHECK(run_lensmith("bokeh --image " + shot.path("in.####.exr") + " -o " + shot.path("out.####.exr") + " --frames 1001- --list-frames" + kCamera)
            .exit_code == 2);
}
