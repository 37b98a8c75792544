// `lensmith bokeh` as a user runs it: outputs and their metadata, and clear errors for bad input.
#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "deep_exr_writer.h"
#include "lensmith/render/image_io.h"
#include "run_lensmith.h"

using lensmith::testing::run_lensmith;
namespace fs = std::filesystem;

namespace {

const std::string kScene = std::string(LENSMITH_SOURCE_DIR) + "/examples/bokeh-scene.exr";

// A file in this test process's scratch folder (removed when the process ends).
fs::path scratch(const std::string& name) {
  static const lensmith::testing::ScratchFolder folder("lensmith_bokeh_cli_");
  return folder.dir / name;
}

std::string value_of(const std::vector<std::pair<std::string, std::string>>& meta, const std::string& key) {
  for (const auto& [k, v] : meta) {
    if (k == key) return v;
  }
  return "";
}

// The scatter keeps each source's coverage exactly and nothing reaches the frame's edge: the multiview bound, not derived here.
constexpr double kScatterCoverage = 0.02;
// The frame's corner lies more than 12 px beyond the blurred square's reach: 0 (Approx(0) needs a margin), float-sized.
constexpr double kUntouchedAlpha = 1e-4;
// The element's premultiplied 0.5 goes with the coverage that alpha carries (thin lens: one colour group); headroom, not derived.
constexpr double kScatterColour = 0.01;

// A CG element over nothing as a deep image (as renderers write one): one opaque sample per pixel
// of a 16 x 16 square at 2 m, colour 0.5, no samples elsewhere; 64 x 48 pixels.
constexpr int kElementWidth = 64, kElementHeight = 48;
fs::path write_deep_element(const std::string& name) {
  std::vector<std::vector<std::vector<float>>> pixels(static_cast<std::size_t>(kElementWidth * kElementHeight));
  for (int y = 16; y < 32; ++y) {
    for (int x = 24; x < 40; ++x) pixels[static_cast<std::size_t>(y * kElementWidth + x)] = {{1.0f, 0.5f, 0.5f, 0.5f, 2.0f}};  // A, B, G, R, Z
  }
  const fs::path path = scratch(name);
  lensmith::testing::write_deep_exr(path, kElementWidth, kElementHeight, {"A", "B", "G", "R", "Z"}, pixels);
  return path;
}

}  // namespace

TEST_CASE("lensmith bokeh renders the bundled scene to an EXR that says how it was made, and to a PNG", "[cli][bokeh]") {
  const fs::path exr = scratch("out.exr"), png = scratch("out.png");
  const auto r = run_lensmith("bokeh --image " + kScene + " --lens sasian-triplet --fstop 4 --focus 3 --model paraxial -o " +
                              exr.string() + " --quiet");
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  CHECK(r.err.empty());  // --quiet: no progress bar, no warnings
  const lensmith::Image out = lensmith::read_radiance_image(exr);
  CHECK(out.width == 640);
  CHECK(out.height == 360);
  const auto meta = lensmith::read_image_metadata(exr);
  CHECK(value_of(meta, "lensmith:model") == "paraxial");
  CHECK(value_of(meta, "lensmith:lens").find("Sasian") != std::string::npos);
  CHECK(std::stod(value_of(meta, "lensmith:f_number")) == Approx(4.0));
  CHECK(std::stod(value_of(meta, "lensmith:focus_m")) == Approx(3.0));
  CHECK_FALSE(value_of(meta, "lensmith:version").empty());
  const auto p = run_lensmith("bokeh --image " + kScene + " --thin-lens --focal-length 50 --fstop 2 --focus 1.2 -o " +
                              png.string() + " --quiet");
  CHECK(p.exit_code == 0);
  CHECK(fs::file_size(png) > 1000);
}

TEST_CASE("lensmith bokeh --timings says where its time went, also with --quiet, within the process's own wall time", "[cli][bokeh]") {
  const fs::path out = scratch("timed.exr");
  const auto started = std::chrono::steady_clock::now();
  const auto r = run_lensmith("bokeh --image " + kScene + " --thin-lens --focal-length 50 --fstop 2 --focus 1.2 -o " + out.string() +
                              " --quiet --timings");
  const double wall_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - started).count();
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  REQUIRE(r.err.rfind("timings: ", 0) == 0);
  // The command's own stages and the renderer's, in the order they ran.
  std::size_t at = 0;
  for (const char* stage : {"reading the picture", "sources", "edge split", "layering", "hidden surfaces", "deposit", "finishing", "writing"}) {
    INFO(stage);
    const std::size_t found = r.err.find(std::string(stage) + " ", at);
    REQUIRE(found != std::string::npos);
    at = found;
  }
  // The stages' sum is measured inside the process: it cannot exceed the test's clock around it.
  const std::size_t total = r.err.find("total ");
  REQUIRE(total != std::string::npos);
  const double total_ms = std::stod(r.err.substr(total + 6));
  CHECK(total_ms > 0.0);
  CHECK(total_ms < wall_ms);
  // A scatter-only option.
  const auto gather = run_lensmith("bokeh --image " + kScene + " --thin-lens --focal-length 50 --fstop 2 --focus 1.2 -o " + out.string() +
                                   " --method gather --timings");
  CHECK(gather.exit_code == 2);
  CHECK(gather.err.find("--timings is an option of --method scatter") != std::string::npos);
}

TEST_CASE("lensmith bokeh refuses to overwrite its input and leaves it as it was", "[cli][bokeh]") {
  const fs::path copy = scratch("scene.exr");
  fs::copy_file(kScene, copy, fs::copy_options::overwrite_existing);
  const auto size = fs::file_size(copy);
  const auto r = run_lensmith("bokeh --image " + copy.string() + " --thin-lens --focal-length 50 --fstop 2 --focus 3 -o " +
                              copy.string());
  CHECK(r.exit_code == 2);  // the command line's fault (docs/cli.md)
  CHECK(r.err.find("input") != std::string::npos);
  CHECK(fs::file_size(copy) == size);
}

TEST_CASE("lensmith bokeh names the pixel of a NaN depth, and --invalid-depth far accepts it", "[cli][bokeh]") {
  lensmith::Image depth(640, 360, 1, 3.0f);
  depth.at(17, 5, 0) = std::numeric_limits<float>::quiet_NaN();
  const fs::path depth_file = scratch("depth-nan.exr"), out = scratch("nan.exr");
  lensmith::write_float_exr(depth_file, depth, {"Z"});
  const std::string common = "bokeh --image " + kScene + " --depth " + depth_file.string() +
                             " --thin-lens --focal-length 50 --fstop 2 --focus 3 --quiet -o " + out.string();
  const auto r = run_lensmith(common);
  CHECK(r.exit_code == 3);
  CHECK(r.err.find("(17, 5)") != std::string::npos);
  CHECK(run_lensmith(common + " --invalid-depth far").exit_code == 0);
}

TEST_CASE("lensmith bokeh rejects a depth map of another size and a thin lens without a focal length", "[cli][bokeh]") {
  const fs::path depth_file = scratch("depth-small.exr"), out = scratch("x.exr");
  lensmith::write_float_exr(depth_file, lensmith::Image(320, 180, 1, 2.0f), {"Z"});
  const auto r = run_lensmith("bokeh --image " + kScene + " --depth " + depth_file.string() +
                              " --lens sasian-triplet --focus 3 -o " + out.string());
  CHECK(r.exit_code == 3);
  CHECK(r.err.find("320") != std::string::npos);
  const auto t = run_lensmith("bokeh --image " + kScene + " --thin-lens --fstop 2 --focus 3 -o " + out.string());
  CHECK(t.exit_code == 2);  // a missing required option
  CHECK(t.err.find("--focal-length") != std::string::npos);
  CHECK_FALSE(fs::exists(out));
}

TEST_CASE("lensmith bokeh --focus-pixel focuses on the depth under that pixel, and the EXR's own framing is used", "[cli][bokeh]") {
  // examples/README.md: the checker target hangs on the wall at 3 m (x 459-548, y 165-224); the
  // scene was rendered with a 50 mm pinhole on a 36 mm sensor and says so in its attributes.
  const fs::path exr = scratch("focus-pixel.exr");
  const auto r = run_lensmith("bokeh --image " + kScene + " --thin-lens --focal-length 85 --fstop 2 --focus-pixel 500,190 -o " +
                              exr.string());
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  CHECK(std::stod(value_of(lensmith::read_image_metadata(exr), "lensmith:focus_m")) == Approx(3.0));
  CHECK(r.err.find("framing from") != std::string::npos);
  CHECK(r.err.find("pinhole focal length 50 mm") != std::string::npos);
  // Outside the image, malformed, or together with --focus: the command line's fault.
  CHECK(run_lensmith("bokeh --image " + kScene + " --thin-lens --focal-length 85 --focus-pixel 640,10 -o " + exr.string()).exit_code == 2);
  CHECK(run_lensmith("bokeh --image " + kScene + " --thin-lens --focal-length 85 --focus-pixel 5 -o " + exr.string()).exit_code == 2);
  CHECK(run_lensmith("bokeh --image " + kScene + " --thin-lens --focal-length 85 --focus 3 --focus-pixel 5,5 -o " + exr.string()).exit_code == 2);
  CHECK(run_lensmith("bokeh --image " + kScene + " --thin-lens --focal-length 85 -o " + exr.string()).exit_code == 2);
}

TEST_CASE("lensmith bokeh keeps an RGBA input's alpha, defocused with its colour, in an RGBA OpenEXR", "[cli][bokeh][alpha]") {
  // A CG element over nothing: an opaque 16 x 16 square (premultiplied colour 0.5) in a transparent
  // 64 x 48 frame, all at 2 m. Focused there it stays as it is; focused at 0.5 m (a 4.8 px blur at
  // f/1.4) its alpha spreads
  // like its colour and keeps its total (the scatter conserves energy; nothing reaches the frame's
  // edge), transparent corners stay transparent.
  // In focus each pixel lands on itself (the tent keeps a pixel-centre point in its pixel): 1 up to rounding; headroom.
  constexpr double kInFocusAlpha = 1e-3;
  // The middle lies 8 px inside the square, past its 2.4 px blur radius and the 1 px tent: covered; headroom, not derived.
  constexpr double kMiddleAlpha = 0.01;
  const int w = 64, h = 48;
  lensmith::Image rgbaz(w, h, 5, 0.0f);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const bool inside = x >= 24 && x < 40 && y >= 16 && y < 32;
      for (int c = 0; c < 3; ++c) rgbaz.at(x, y, c) = inside ? 0.5f : 0.0f;
      rgbaz.at(x, y, 3) = inside ? 1.0f : 0.0f;
      rgbaz.at(x, y, 4) = 2.0f;
    }
  }
  const fs::path in = scratch("element.exr");
  lensmith::write_float_exr(in, rgbaz, {"R", "G", "B", "A", "Z"});
  for (const double focus : {2.0, 0.5}) {
    const fs::path out = scratch("element-out.exr");
    const auto r = run_lensmith("bokeh --image " + in.string() + " --thin-lens --focal-length 50 --fstop 1.4 --focus " +
                                std::to_string(focus) + " -o " + out.string() + " --quiet");
    INFO("focus " << focus << " m: " << r.err);
    REQUIRE(r.exit_code == 0);
    const auto alpha = lensmith::read_alpha(out);
    REQUIRE(alpha.has_value());
    double total = 0.0;
    for (float a : *alpha) total += a;
    CHECK(total == Approx(256.0).epsilon(kScatterCoverage));
    CHECK((*alpha)[0] == Approx(0.0).margin(kUntouchedAlpha));
    if (focus == 2.0) {
      CHECK((*alpha)[static_cast<std::size_t>(24 * w + 32)] == Approx(1.0).margin(kInFocusAlpha));
    } else {
      CHECK((*alpha)[static_cast<std::size_t>(24 * w + 32)] == Approx(1.0).margin(kMiddleAlpha));  // the middle of the square
      CHECK((*alpha)[static_cast<std::size_t>(24 * w + 22)] > 0.05);                                 // spread 2 px beyond its edge
    }
  }
  // --keep-depth adds the input's depth as Z beside R, G, B, A.
  const fs::path with_z = scratch("element-z.exr");
  REQUIRE(run_lensmith("bokeh --image " + in.string() + " --thin-lens --focal-length 50 --fstop 1.4 --focus 0.5 --keep-depth -o " +
                       with_z.string() + " --quiet").exit_code == 0);
  const lensmith::DepthMap z = lensmith::read_depth(lensmith::DepthSource::parse(with_z.string() + ":Z"), {},
                                                    lensmith::PinholeFrame(w, h, 1.0));
  CHECK(z.z_m.front() == Approx(2.0));
  CHECK(lensmith::read_alpha(with_z).has_value());
  CHECK(run_lensmith("bokeh --image " + in.string() + " --thin-lens --focal-length 50 --focus 2 --keep-depth -o " +
                     scratch("z.png").string()).exit_code == 2);
  // A PNG cannot hold alpha: RGB with a note.
  const auto png = run_lensmith("bokeh --image " + in.string() + " --thin-lens --focal-length 50 --fstop 2 --focus 2 -o " +
                                scratch("element.png").string());
  CHECK(png.exit_code == 0);
  CHECK(png.err.find("only an OpenEXR output") != std::string::npos);
}

TEST_CASE("lensmith bokeh reads a deep OpenEXR as layered input: a CG element over nothing keeps its alpha, empty pixels stay empty",
          "[cli][bokeh][deep]") {
  // The element of the test above as a deep image: one opaque sample per pixel of the square, no
  // samples elsewhere (as renderers write an element over nothing).
  const int w = kElementWidth;
  const fs::path in = write_deep_element("element-deep.exr");
  const fs::path out = scratch("element-deep-out.exr");
  const auto r = run_lensmith("bokeh --image " + in.string() + " --thin-lens --focal-length 50 --fstop 1.4 --focus 0.5 -o " + out.string());
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  CHECK(r.err.find("layered input: 256 deep samples") != std::string::npos);
  const auto alpha = lensmith::read_alpha(out);
  REQUIRE(alpha.has_value());
  double total = 0.0;
  for (float a : *alpha) total += a;
  CHECK(total == Approx(256.0).epsilon(kScatterCoverage));  // the scatter keeps the coverage; nothing reaches the frame's edge
  CHECK((*alpha)[0] == Approx(0.0).margin(kUntouchedAlpha));
  CHECK((*alpha)[static_cast<std::size_t>(24 * w + 22)] > 0.05);  // spread 2 px beyond the square's edge
  // The colour is the flat element's, premultiplied over black: 0.5 inside, alpha times 0.5 at the rim.
  const lensmith::Image rgb = lensmith::read_radiance_image(out);
  CHECK(rgb.at(32, 24, 0) == Approx(0.5).margin(kScatterColour));
  CHECK(rgb.at(22, 24, 0) == Approx(0.5 * (*alpha)[static_cast<std::size_t>(24 * w + 22)]).margin(kScatterColour));
  // A PNG cannot hold the element's alpha: RGB over black, with a note.
  const auto png = run_lensmith("bokeh --image " + in.string() + " --thin-lens --focal-length 50 --fstop 1.4 --focus 0.5 -o " +
                                scratch("element-deep.png").string());
  CHECK(png.exit_code == 0);
  CHECK(png.err.find("only an OpenEXR output (.exr) keeps its alpha") != std::string::npos);
  // A deep image carries its own depth.
  const auto with_depth = run_lensmith("bokeh --image " + in.string() + " --depth " + in.string() +
                                       " --thin-lens --focal-length 50 --focus 2 -o " + scratch("x.exr").string());
  CHECK(with_depth.exit_code == 2);
  CHECK(with_depth.err.find("is a deep image, whose samples carry their own Z") != std::string::npos);
}

TEST_CASE("lensmith bokeh passes an EXR's other channels through: kept in focus, defocused with the picture, or dropped",
          "[cli][bokeh][aovs]") {
  // Render passes beside the beauty: a light pass (diffuse.R/G/B, here equal to R, G, B) and a data
  // pass (N.x, constant). Half the frame at the focus distance, half nearer (blurred).
  const int w = 64, h = 48;
  lensmith::Image in_img(w, h, 8, 0.0f);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const float v = ((x / 6 + y / 6) % 2 == 0) ? 0.8f : 0.1f;
      const float rgb[3] = {v, 0.5f * v, 0.25f + 0.5f * v};
      for (int c = 0; c < 3; ++c) in_img.at(x, y, c) = in_img.at(x, y, 4 + c) = rgb[c];
      in_img.at(x, y, 3) = x < w / 2 ? 2.0f : 0.8f;  // Z, m
      in_img.at(x, y, 7) = 0.3f;                     // N.x
    }
  }
  const fs::path in = scratch("passes.exr");
  lensmith::write_float_exr(in, in_img, {"R", "G", "B", "Z", "diffuse.R", "diffuse.G", "diffuse.B", "N.x"});
  const std::string base = "bokeh --image " + in.string() + " --thin-lens --focal-length 50 --fstop 1.4 --focus 2 --no-spectral -o ";
  // keep (default): every pass as it was, with a note saying so.
  const fs::path kept = scratch("passes-keep.exr");
  const auto kr = run_lensmith(base + kept.string());
  REQUIRE(kr.exit_code == 0);
  CHECK(kr.err.find("kept unchanged") != std::string::npos);
  // OpenEXR stores channels sorted by name: look them up.
  const std::vector<std::string> names{"diffuse.R", "diffuse.G", "diffuse.B", "N.x"};
  auto column = [&names](const lensmith::OtherChannels& o, int k) {
    const auto it = std::find(o.names.begin(), o.names.end(), names[static_cast<std::size_t>(k)]);
    REQUIRE(it != o.names.end());
    return static_cast<std::size_t>(it - o.names.begin());
  };
  const lensmith::OtherChannels kp = lensmith::read_other_channels(kept);
  REQUIRE(kp.names.size() == 4);
  for (int k = 0; k < 4; ++k) {
    const std::size_t col = column(kp, k);
    for (int i = 0; i < w * h; ++i) REQUIRE(kp.samples[static_cast<std::size_t>(i) * 4 + col] == in_img.data[static_cast<std::size_t>(i * 8 + 4 + k)]);
  }
  // defocus: through the same rays as the picture, so a pass equal to the beauty comes out equal to
  // the defocused beauty (to float rounding), and a constant pass stays constant where the frame is
  // covered.
  const fs::path blurred = scratch("passes-defocus.exr");
  REQUIRE(run_lensmith(base + blurred.string() + " --other-channels defocus --quiet").exit_code == 0);
  const lensmith::Image beauty = lensmith::read_radiance_image(blurred);
  const lensmith::OtherChannels df = lensmith::read_other_channels(blurred);
  REQUIRE(df.names.size() == 4);
  double worst = 0.0, n_worst = 0.0;
  const std::size_t n_col = column(df, 3);
  for (int i = 0; i < w * h; ++i) {
    for (int c = 0; c < 3; ++c) {
      worst = std::max(worst, static_cast<double>(std::abs(df.samples[static_cast<std::size_t>(i) * 4 + column(df, c)] -
                                                           beauty.data[static_cast<std::size_t>(i * 3 + c)])));
    }
    n_worst = std::max(n_worst, static_cast<double>(std::abs(df.samples[static_cast<std::size_t>(i) * 4 + n_col] - 0.3f)));
  }
  CHECK(worst < 1e-5);
  CHECK(n_worst < 1e-3);
  // The blurred half really is blurred: the pass differs from the input there.
  CHECK(std::abs(df.samples[static_cast<std::size_t>(24 * w + 50) * 4 + column(df, 0)] - in_img.at(50, 24, 4)) > 1e-3);
  // drop: RGB (and Z when asked) only.
  const fs::path dropped = scratch("passes-drop.exr");
  REQUIRE(run_lensmith(base + dropped.string() + " --other-channels drop --quiet").exit_code == 0);
  CHECK(lensmith::read_other_channels(dropped).names.empty());
  // A PNG cannot hold them: RGB with a note. A pass with NaN is refused, naming the pixel (the input's
  // content, exit 3), unless dropped.
  const auto png = run_lensmith(base + scratch("passes.png").string());
  CHECK(png.exit_code == 0);
  CHECK(png.err.find("only an OpenEXR output") != std::string::npos);
  in_img.at(5, 7, 7) = std::numeric_limits<float>::quiet_NaN();
  const fs::path bad = scratch("passes-nan.exr");
  lensmith::write_float_exr(bad, in_img, {"R", "G", "B", "Z", "diffuse.R", "diffuse.G", "diffuse.B", "N.x"});
  const auto nan = run_lensmith("bokeh --image " + bad.string() + " --thin-lens --focal-length 50 --fstop 2 --focus 2 --other-channels defocus -o " +
                                scratch("passes-nan-out.exr").string());
  CHECK(nan.exit_code == 3);
  CHECK(nan.err.find("N.x at pixel (5, 7)") != std::string::npos);
  CHECK(run_lensmith("bokeh --image " + bad.string() + " --thin-lens --focal-length 50 --fstop 2 --focus 2 -o " +
                     scratch("passes-nan-keep.exr").string()).exit_code == 3);
  CHECK(run_lensmith("bokeh --image " + bad.string() + " --thin-lens --focal-length 50 --fstop 2 --focus 2 --other-channels drop -o " +
                     scratch("passes-nan-drop.exr").string() + " --quiet").exit_code == 0);
}

TEST_CASE("lensmith bokeh --method multiview traces a deep element's lens rays, keeps its coverage and says how it was made",
          "[cli][bokeh][multiview]") {
  // The deep element above, through Lee et al.'s multiview synthesis: the same coverage (each
  // pixel's alpha is the share of its lens rays the square stops), the colour premultiplied by it.
  // 64 lens rays a pixel sample the coverage of the blurred rim.
  constexpr double kMultiviewCoverageTotal = 0.02;
  // The corner's rays all miss the square and the middle's all hit it: 0 and 1 exactly, up to float rounding.
  constexpr double kAllOrNoRays = 1e-6;
  // Inside, every ray sees 0.5 and the spectral round trip over evenly visited nodes is the identity; headroom, not derived.
  constexpr double kMultiviewInside = 1e-3;
  // At the rim each ray carries one wavelength: a channel's share of the stopped rays is alpha only up to that sampling.
  constexpr double kMultiviewRimColour = 0.01;
  const int w = kElementWidth;
  const fs::path in = write_deep_element("element-deep-mv.exr");
  const fs::path out = scratch("element-deep-mv-out.exr");
  const auto r = run_lensmith("bokeh --image " + in.string() + " --thin-lens --focal-length 50 --fstop 1.4 --focus 0.5 --method multiview " +
                              "--samples 64 -o " + out.string());
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  CHECK(r.err.find("method multiview") != std::string::npos);
  CHECK(r.err.find("64 lens rays per pixel") != std::string::npos);
  const auto meta = lensmith::read_image_metadata(out);
  CHECK(value_of(meta, "lensmith:method") == "multiview");
  CHECK(value_of(meta, "lensmith:samples") == "64");
  const auto alpha = lensmith::read_alpha(out);
  REQUIRE(alpha.has_value());
  double total = 0.0;
  for (float a : *alpha) total += a;
  // Every ray the square stops is coverage; 64 rays a pixel over the blurred rim: within 2 %.
  CHECK(total == Approx(256.0).epsilon(kMultiviewCoverageTotal));
  CHECK((*alpha)[0] == Approx(0.0).margin(kAllOrNoRays));
  CHECK((*alpha)[static_cast<std::size_t>(24 * w + 32)] == Approx(1.0).margin(kAllOrNoRays));  // inside: every ray stopped
  const lensmith::Image rgb = lensmith::read_radiance_image(out);
  CHECK(rgb.at(32, 24, 0) == Approx(0.5).margin(kMultiviewInside));
  CHECK(rgb.at(22, 24, 0) == Approx(0.5 * (*alpha)[static_cast<std::size_t>(24 * w + 22)]).margin(kMultiviewRimColour));
}

TEST_CASE("lensmith bokeh refuses options of the other method and apertures multiview cannot sample with traced rays",
          "[cli][bokeh][multiview]") {
  const std::string base = "bokeh --image " + kScene + " --lens sasian-triplet --focus 3 -o " + scratch("m.exr").string() + " ";
  const auto hidden = run_lensmith(base + "--method multiview --hidden stretch");
  CHECK(hidden.exit_code == 2);
  CHECK(hidden.err.find("--hidden is an option of --method scatter") != std::string::npos);
  const auto samples = run_lensmith(base + "--samples 8");
  CHECK(samples.exit_code == 2);
  CHECK(samples.err.find("--samples is an option of --method multiview") != std::string::npos);
  const auto blades = run_lensmith(base + "--method multiview --model exact --blades 6");
  CHECK(blades.exit_code != 0);
  CHECK(blades.err.find("not implemented") != std::string::npos);
  const auto zero = run_lensmith(base + "--method multiview --samples 0");
  CHECK(zero.exit_code == 2);
  CHECK_FALSE(fs::exists(scratch("m.exr")));
}

TEST_CASE("lensmith bokeh --method lightfield warps the picture to its views, says how it was made and refuses what it cannot do",
          "[cli][bokeh][lightfield]") {
  const fs::path out = scratch("lightfield-out.exr");
  const auto r = run_lensmith("bokeh --image " + kScene + " --lens sasian-triplet --focus 3 --method lightfield --views 12 --threads 2 -o " +
                              out.string());
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  CHECK(r.err.find("method lightfield") != std::string::npos);
  CHECK(r.err.find("12 views") != std::string::npos);
  CHECK(r.err.find("three wavelengths, one per RGB channel") != std::string::npos);
  const auto meta = lensmith::read_image_metadata(out);
  CHECK(value_of(meta, "lensmith:method") == "lightfield");
  CHECK(value_of(meta, "lensmith:views") == "12");
  const std::string base = "bokeh --image " + kScene + " --lens sasian-triplet --focus 3 -o " + scratch("lf.exr").string() + " ";
  const auto views = run_lensmith(base + "--views 8");
  CHECK(views.exit_code == 2);
  CHECK(views.err.find("--views is an option of --method lightfield") != std::string::npos);
  const auto hidden = run_lensmith(base + "--method lightfield --hidden stretch");
  CHECK(hidden.exit_code == 2);
  CHECK(hidden.err.find("--hidden is an option of --method scatter") != std::string::npos);
  const auto samples = run_lensmith(base + "--method lightfield --samples 8");
  CHECK(samples.exit_code == 2);
  CHECK(samples.err.find("--samples is an option of --method multiview") != std::string::npos);
  const auto mask = run_lensmith(base + "--method lightfield --blades 6");
  CHECK(mask.exit_code == 0);  // a bladed iris: its views weighted by their share of the area
  const fs::path deep = write_deep_element("element-deep-lf.exr");
  const auto layered = run_lensmith("bokeh --image " + deep.string() + " --thin-lens --focal-length 50 --fstop 1.4 --focus 0.5 --method lightfield -o " +
                                    scratch("lf-deep.exr").string());
  CHECK(layered.exit_code == 2);
  CHECK(layered.err.find("not implemented") != std::string::npos);
  CHECK_FALSE(fs::exists(scratch("lf-deep.exr")));
  const auto zero = run_lensmith(base + "--method lightfield --views 0");
  CHECK(zero.exit_code == 2);
}

TEST_CASE("lensmith bokeh --method ewa splats the picture through the lens's blur, says how it was made and refuses what it cannot do",
          "[cli][bokeh][ewa]") {
  const fs::path out = scratch("ewa-out.exr");
  const auto r = run_lensmith("bokeh --image " + kScene + " --lens sasian-triplet --focus 3 --method ewa --threads 2 -o " + out.string());
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  CHECK(r.err.find("method ewa") != std::string::npos);
  CHECK(r.err.find("the lens's PSF covariance") != std::string::npos);
  CHECK(r.err.find("spectral colour is not implemented") != std::string::npos);
  const auto meta = lensmith::read_image_metadata(out);
  CHECK(value_of(meta, "lensmith:method") == "ewa");
  CHECK(value_of(meta, "lensmith:splat_kernel") == "lens psf");
  const std::string base = "bokeh --image " + kScene + " --lens sasian-triplet --focus 3 -o " + scratch("ewa.exr").string() + " ";
  const auto paper = run_lensmith(base + "--method ewa --circular-splats --no-level-of-detail");
  CHECK(paper.exit_code == 0);
  CHECK(paper.err.find("circular Gaussians of the CoC") != std::string::npos);
  const auto circular = run_lensmith(base + "--circular-splats");
  CHECK(circular.exit_code == 2);
  CHECK(circular.err.find("--circular-splats is an option of --method ewa") != std::string::npos);
  const auto hidden = run_lensmith(base + "--method ewa --hidden stretch");
  CHECK(hidden.exit_code == 2);
  CHECK(hidden.err.find("--hidden is an option of --method scatter") != std::string::npos);
  const auto views = run_lensmith(base + "--method ewa --views 8");
  CHECK(views.exit_code == 2);
  CHECK(views.err.find("--views is an option of --method lightfield") != std::string::npos);
  const fs::path deep = write_deep_element("element-deep-ewa.exr");
  const auto layered = run_lensmith("bokeh --image " + deep.string() + " --thin-lens --focal-length 50 --fstop 1.4 --focus 0.5 --method ewa -o " +
                                    scratch("ewa-deep.exr").string());
  CHECK(layered.exit_code == 2);
  CHECK(layered.err.find("not implemented") != std::string::npos);
  CHECK_FALSE(fs::exists(scratch("ewa-deep.exr")));
}

TEST_CASE("lensmith bokeh --method gather gathers at half resolution, traces holes into a known scene, and refuses what it cannot do",
          "[cli][bokeh][gather]") {
  const fs::path out = scratch("gather-out.exr");
  const auto r = run_lensmith("bokeh --image " + kScene + " --lens sasian-triplet --focus 3 --method gather --threads 2 -o " + out.string());
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  CHECK(r.err.find("method gather") != std::string::npos);
  CHECK(r.err.find("half resolution, 49 taps (3 rings)") != std::string::npos);
  CHECK(r.err.find("spectral colour is not implemented") != std::string::npos);
  const auto meta = lensmith::read_image_metadata(out);
  CHECK(value_of(meta, "lensmith:method") == "gather");
  CHECK(value_of(meta, "lensmith:rings") == "3");
  CHECK(value_of(meta, "lensmith:hidden_surfaces") == "none");
  const std::string base = "bokeh --image " + kScene + " --lens sasian-triplet --focus 3 -o " + scratch("gather.exr").string() + " ";
  const auto tan = run_lensmith(base + "--method gather --rings 4 --no-median");
  CHECK(tan.exit_code == 0);
  CHECK(tan.err.find("81 taps (4 rings)") != std::string::npos);
  // Tan et al.'s hybrid: the pinhole render of an analytic scene, and the scene to trace.
  const std::string scene = std::string(LENSMITH_SOURCE_DIR) + "/examples/scenes/occluder.json";
  const fs::path pinhole = scratch("gather-occluder.exr"), depth = scratch("gather-occluder-z.exr");
  REQUIRE(run_lensmith("scene render " + scene + " --pinhole --width 160 --height 90 --depth " + depth.string() + " -o " + pinhole.string())
              .exit_code == 0);
  const fs::path traced = scratch("gather-traced.exr");
  const auto hybrid = run_lensmith("bokeh --image " + pinhole.string() + " --depth " + depth.string() +
                                   " --lens sasian-triplet --focus 1 --fstop 2 --method gather --hidden trace --scene " + scene +
                                   " --trace-rays 32 -o " + traced.string());
  INFO(hybrid.err);
  REQUIRE(hybrid.exit_code == 0);
  CHECK(hybrid.err.find("pixels traced into") != std::string::npos);
  CHECK(value_of(lensmith::read_image_metadata(traced), "lensmith:hidden_surfaces") == "trace " + scene);
  // What it refuses, each with the reason (exit 2) and no output.
  const auto no_scene = run_lensmith(base + "--method gather --hidden trace");
  CHECK(no_scene.exit_code == 2);
  CHECK(no_scene.err.find("--hidden trace needs --scene FILE") != std::string::npos);
  const auto stretch = run_lensmith(base + "--method gather --hidden stretch");
  CHECK(stretch.exit_code == 2);
  CHECK(stretch.err.find("--method gather takes --hidden trace") != std::string::npos);
  const auto scatter_trace = run_lensmith(base + "--hidden trace --scene " + scene);
  CHECK(scatter_trace.exit_code == 2);
  CHECK(scatter_trace.err.find("--hidden trace is for --method gather") != std::string::npos);
  const auto rings = run_lensmith(base + "--rings 4");
  CHECK(rings.exit_code == 2);
  CHECK(rings.err.find("--rings is an option of --method gather") != std::string::npos);
  const auto five = run_lensmith(base + "--method gather --rings 5");
  CHECK(five.exit_code == 2);
  const auto rays_alone = run_lensmith(base + "--method gather --trace-rays 8");
  CHECK(rays_alone.exit_code == 2);
  CHECK(rays_alone.err.find("--trace-rays is for --method gather --hidden trace") != std::string::npos);
  const fs::path deep = write_deep_element("element-deep-gather.exr");
  const auto layered = run_lensmith("bokeh --image " + deep.string() + " --thin-lens --focal-length 50 --fstop 1.4 --focus 0.5 --method gather -o " +
                                    scratch("gather-deep.exr").string());
  CHECK(layered.exit_code == 2);
  CHECK(layered.err.find("not implemented") != std::string::npos);
  CHECK_FALSE(fs::exists(scratch("gather-deep.exr")));
}

TEST_CASE("lensmith bokeh without --model photographs a mirror lens with the exact model, and says so, and the poly model fits it and a tilt-shift lens", "[cli][bokeh][mirror]") {
  const fs::path image = scratch("mirror-in.exr"), depth = scratch("mirror-depth.exr"), out = scratch("mirror-out.exr");
  const std::string source = std::string(LENSMITH_SOURCE_DIR);
  const auto rendered = run_lensmith("scene render " + source + "/examples/scenes/mirror-lens-highlights.json --pinhole --width 96 "
                                     "--height 54 --sensor-width 36 --pinhole-focal-length 500 --depth " + depth.string() + " -o " +
                                     image.string() + " --quiet");
  REQUIRE(rendered.exit_code == 0);
  const auto r = run_lensmith("bokeh --image " + image.string() + " --depth " + depth.string() + " --lens " + source +
                              "/examples/lenses/cassegrain-500mm.json --focus 30 -o " + out.string());
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  CHECK_THAT(r.err, Catch::Contains("the exact model photographs this lens") && Catch::Contains("2 mirrors"));
  CHECK(value_of(lensmith::read_image_metadata(out), "lensmith:model") == "exact");
  // Asked for another model, it is refused with the reason and the way out.
  const auto seidel = run_lensmith("bokeh --image " + image.string() + " --depth " + depth.string() + " --lens " + source +
                                   "/examples/lenses/cassegrain-500mm.json --focus 30 --model seidel -o " + out.string());
  CHECK(seidel.exit_code != 0);
  CHECK_THAT(seidel.err, Catch::Contains("--model exact"));
  // The poly model fits the mirror lens, obscuration and all.
  const auto poly = run_lensmith("bokeh --image " + image.string() + " --depth " + depth.string() + " --lens " + source +
                                 "/examples/lenses/cassegrain-500mm.json --focus 30 --model poly -o " + out.string());
  INFO(poly.err);
  CHECK(poly.exit_code == 0);
  CHECK(value_of(lensmith::read_image_metadata(out), "lensmith:model") == "poly");
  // The thin model of it renders, and says it keeps no falloff (the real lens's brightness is taken
  // for round refracting lenses only).
  const auto thin = run_lensmith("bokeh --image " + image.string() + " --depth " + depth.string() + " --lens " + source +
                                 "/examples/lenses/cassegrain-500mm.json --focus 30 --model thin -o " + out.string());
  INFO(thin.err);
  CHECK(thin.exit_code == 0);
  CHECK_THAT(thin.err, Catch::Contains("the thin model keeps no falloff") && Catch::Contains("2 mirrors"));
  // And a tilt-shift lens (its elements fitted without the breaks at its ends).
  const auto shifted = run_lensmith("bokeh --image " + image.string() + " --depth " + depth.string() + " --lens " + source +
                                    "/examples/lenses/tilt-shift-50mm.json --focus 3 --model poly -o " + out.string());
  INFO(shifted.err);
  CHECK(shifted.exit_code == 0);
  // It refuses an element tilted inside the lens before any fitting, naming the way out.
  const std::string folded = std::string(LENSMITH_TEST_DATA_DIR) + "/lensmith/tilted-rear-element.json";
  const auto tilted = run_lensmith("bokeh --image " + image.string() + " --depth " + depth.string() + " --lens " + folded +
                                   " --focus 3 --model poly -o " + out.string());
  CHECK(tilted.exit_code == 3);  // the lens lacks what the command needs
  CHECK_THAT(tilted.err, Catch::Contains("coordinate break") && Catch::Contains("between elements") && Catch::Contains("--model exact"));
}

TEST_CASE("lensmith bokeh says when a tilted lens photographs past the input's edge, and not for the same lens untilted",
          "[cli][bokeh][tilt]") {
  // The shipped tilt-shift example (the pbrt double Gauss tilted 2.9 degrees about its front vertex) moves the
  // field about 0.84 mm on a 36-mm sensor: 2.2 px of a 96 x 64 frame, past the 2 % (1.3 px) the note allows.
  const fs::path image = scratch("tilt-in.exr"), depth = scratch("tilt-depth.exr"), out = scratch("tilt-out.exr");
  const std::string source = std::string(LENSMITH_SOURCE_DIR);
  REQUIRE(run_lensmith("scene render " + source + "/examples/scenes/tilted-plane.json --pinhole --width 96 --height 64 "
                       "--sensor-width 36 --pinhole-focal-length 50 --depth " + depth.string() + " -o " + image.string() + " --quiet")
              .exit_code == 0);
  const std::string common = "bokeh --image " + image.string() + " --depth " + depth.string() + " --focus 3 --fstop 4 -o " + out.string();
  const auto tilted = run_lensmith(common + " --lens " + source + "/examples/lenses/tilt-shift-50mm.json --model exact");
  INFO(tilted.err);
  REQUIRE(tilted.exit_code == 0);
  CHECK_THAT(tilted.err, Catch::Contains("past the input's edge") && Catch::Contains("overscan"));
  const auto plain = run_lensmith(common + " --lens pbrt-dgauss-50mm --model exact");
  INFO(plain.err);
  REQUIRE(plain.exit_code == 0);
  CHECK_THAT(plain.err, !Catch::Contains("past the input's edge"));
}

TEST_CASE("lensmith bokeh writes an anamorphic lens's picture squeezed as on the sensor, desqueezed on request, and refuses a "
          "squeezed input", "[cli][bokeh][anamorphic]") {
  // lentil's Schneider anamorphic (entry 2004, US 6,310,731): EFL_y 60.55 mm, EFL_x 31.49 mm, squeeze 1.92 at infinity.
  const std::string lens = std::string(LENSMITH_TEST_DATA_DIR) + "/lentil/lenses.json#2004";
  const fs::path image = scratch("ana-in.exr"), depth = scratch("ana-depth.exr");
  const fs::path squeezed = scratch("ana-squeezed.exr"), desqueezed = scratch("ana-desqueezed.exr");
  const std::string source = std::string(LENSMITH_SOURCE_DIR);
  REQUIRE(run_lensmith("scene render " + source + "/examples/scenes/highlight-field.json --pinhole --width 32 --height 18 "
                       "--pinhole-focal-length 60.5546 --depth " + depth.string() + " -o " + image.string() + " --quiet")
              .exit_code == 0);
  const std::string common = "bokeh --image " + image.string() + " --depth " + depth.string() + " --lens \"" + lens + "\" --focus 30 --fstop 4 ";
  const auto r = run_lensmith(common + "--keep-depth -o " + squeezed.string());
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  CHECK_THAT(r.err, Catch::Contains("squeezed as on the sensor, 17 px wide") && Catch::Contains("(17 x 18)"));
  // The squeeze at 30 m from the sections' magnifications: 1.918 (32 / 17 = 1.882 once rounded to whole pixels).
  const lensmith::Image narrow = lensmith::read_radiance_image(squeezed);
  CHECK(narrow.width == 17);
  CHECK(narrow.height == 18);
  CHECK_THAT(std::stod(value_of(lensmith::read_image_metadata(squeezed), "PixelAspectRatio")), Catch::WithinRel(32.0 / 17.0, 1e-6));
  const auto d = run_lensmith(common + "--desqueeze -o " + desqueezed.string() + " --quiet");
  REQUIRE(d.exit_code == 0);
  const lensmith::Image wide = lensmith::read_radiance_image(desqueezed);
  CHECK(wide.width == 32);
  // Squeezing keeps each row's light: the means agree (the squeezed file is the desqueezed picture
  // integrated over wider sensor pixels).
  CHECK_THAT(narrow.mean(1), Catch::WithinRel(wide.mean(1), 1e-4));
  // A squeezed plate has wide pixels: refused, with the way out.
  const auto again = run_lensmith("bokeh --image " + squeezed.string() + " --thin-lens --focal-length 50 --fstop 2 --focus 3 -o " +
                                  scratch("ana-again.exr").string());
  CHECK(again.exit_code != 0);
  CHECK_THAT(again.err, Catch::Contains("not square") && Catch::Contains("desqueeze it first"));
  CHECK_FALSE(fs::exists(scratch("ana-again.exr")));
}

namespace {

// A 16-bit sRGB code's step is at most 4e-5 in linear light (at 1.0: 1/65535 x the encoding's slope of
// 2.4); written and read back, a pixel comes within that and the rounding of the two conversions.
constexpr double kTiffRoundTrip = 1e-4;

// The little-endian TIFF of one 8-bit gray strip of `width` x `height` pixels whose data is not
// there: enough for libtiff to read its directory.
void write_tiff_header(const fs::path& path, std::uint32_t width, std::uint32_t height) {
  std::vector<unsigned char> bytes{'I', 'I', 42, 0, 8, 0, 0, 0};
  auto put16 = [&](std::uint32_t v) { bytes.insert(bytes.end(), {static_cast<unsigned char>(v), static_cast<unsigned char>(v >> 8)}); };
  auto put32 = [&](std::uint32_t v) { put16(v & 0xffff); put16(v >> 16); };
  const std::vector<std::array<std::uint32_t, 3>> entries{{256, 4, width}, {257, 4, height}, {258, 3, 8},   {259, 3, 1}, {262, 3, 1},
                                                          {273, 4, 134},   {277, 3, 1},      {278, 4, height}, {279, 4, width * height}};
  put16(static_cast<std::uint32_t>(entries.size()));
  for (const auto& [tag, type, value] : entries) {
    put16(tag);
    put16(type);
    put32(1);
    if (type == 3) {
      put16(value);
      put16(0);
    } else {
      put32(value);
    }
  }
  put32(0);
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

}  // namespace

namespace {

// A render to `output` (a file name in the scratch folder) with the module folder empty: exit 5, the
// missing module's path in the message, nothing written.
void check_without_module(const std::string& module_file, const std::string& output, const std::string& render) {
  const fs::path modules = scratch("no-" + module_file);
  fs::create_directories(modules);
  const fs::path out = scratch(output);
  ::setenv("LENSMITH_MODULE_DIR", modules.c_str(), 1);
  const auto r = run_lensmith("bokeh --image " + kScene + render + out.string());
  ::unsetenv("LENSMITH_MODULE_DIR");
  CHECK(r.exit_code == 5);
  CHECK(r.err.find((modules / module_file).string()) != std::string::npos);
  CHECK_FALSE(fs::exists(out));
}

}  // namespace

TEST_CASE("lensmith bokeh writes PNG and reads JPEG through its PNG and JPEG module, and says where it looked without it", "[cli][bokeh]") {
  // The command line loads libpng and libjpeg from liblensmith_png_jpeg.so when a command first needs
  // them (lib/imageio/src/png_jpeg_module.h); this program links the codecs itself, an independent reader.
  const std::string render = " --thin-lens --focal-length 50 --fstop 2 --focus 1.2 --quiet -o ";
  const fs::path png = scratch("module.png"), jpg = scratch("module.jpg"), exr = scratch("module-png.exr");
  REQUIRE(run_lensmith("bokeh --image " + kScene + render + png.string()).exit_code == 0);
  REQUIRE(run_lensmith("bokeh --image " + kScene + render + exr.string()).exit_code == 0);
  // The PNG is the EXR's picture sRGB-encoded in 8 bits: read back (linear), within half a code value
  // of the EXR's clamped to [0, 1], times the decoding curve's steepest slope, at white (IEC 61966-2-1:
  // d/dV ((V + 0.055) / 1.055)^2.4 = 2.4 / 1.055 at V = 1), plus float rounding.
  constexpr double kEightBitRoundTrip = 0.5 / 255.0 * 2.4 / 1.055 + 1e-6;
  const lensmith::Image from_png = lensmith::read_radiance_image(png), from_exr = lensmith::read_radiance_image(exr);
  REQUIRE(from_png.data.size() == from_exr.data.size());
  double worst = 0.0;
  for (std::size_t i = 0; i < from_exr.data.size(); ++i) {
    worst = std::max(worst, std::abs(from_png.data[i] - std::clamp(static_cast<double>(from_exr.data[i]), 0.0, 1.0)));
  }
  CHECK(worst < kEightBitRoundTrip);
  CHECK(value_of(lensmith::read_image_metadata(png), "Software").find("lensmith") != std::string::npos);  // text written by libpng
  SECTION("a JPEG as input, decoded by the module") {
    REQUIRE(run_lensmith("bokeh --image " + kScene + render + jpg.string()).exit_code == 0);
    const fs::path out = scratch("from-jpeg.exr");
    const auto r = run_lensmith("bokeh --image " + jpg.string() + " --depth " + kScene + render + out.string());
    INFO(r.err);
    CHECK(r.exit_code == 0);
    CHECK(lensmith::read_radiance_image(out).width == from_exr.width);
  }
  SECTION("without the module: exit 5, saying where it looked, nothing written") { check_without_module("liblensmith_png_jpeg.so", "nowhere.png", render); }
}

TEST_CASE("lensmith bokeh writes and reads TIFF through its TIFF module and its errors reach the command as any reader's do", "[cli][bokeh]") {
  // The command line loads libtiff from liblensmith_tiff.so when a command first needs it
  // (lib/imageio/src/tiff_module.h); this program links the codec itself, an independent reader.
  const std::string render = " --thin-lens --focal-length 50 --fstop 2 --focus 1.2 --quiet -o ";
  const fs::path tif = scratch("module.tif"), exr = scratch("module.exr");
  REQUIRE(run_lensmith("bokeh --image " + kScene + render + tif.string()).exit_code == 0);
  REQUIRE(run_lensmith("bokeh --image " + kScene + render + exr.string()).exit_code == 0);
  const lensmith::Image from_tiff = lensmith::read_radiance_image(tif), from_exr = lensmith::read_radiance_image(exr);
  REQUIRE(from_tiff.data.size() == from_exr.data.size());
  double worst = 0.0;
  for (std::size_t i = 0; i < from_exr.data.size(); ++i) {
    const double expected = std::clamp(static_cast<double>(from_exr.data[i]), 0.0, 1.0);
    worst = std::max(worst, std::abs(from_tiff.data[i] - expected));
  }
  CHECK(worst < kTiffRoundTrip);
  SECTION("a TIFF as input, read by the module") {
    const fs::path out = scratch("from-tiff.exr");
    const auto r = run_lensmith("bokeh --image " + tif.string() + " --depth " + kScene + render + out.string());
    INFO(r.err);
    CHECK(r.exit_code == 0);
    CHECK(fs::exists(out));
  }
  SECTION("a truncated TIFF: exit 5 (IoError), naming the file") {
    const fs::path cut = scratch("cut.tif");
    fs::copy_file(tif, cut, fs::copy_options::overwrite_existing);
    fs::resize_file(cut, 300);
    const auto r = run_lensmith("bokeh --image " + cut.string() + " --depth " + kScene + render + scratch("cut.exr").string());
    CHECK(r.exit_code == 5);
    CHECK(r.err.find(cut.string() + ": cannot read the TIFF image") != std::string::npos);
  }
  SECTION("a TIFF taller than lensmith reads: exit 3 (ImageFileError), naming the file") {
    const fs::path tall = scratch("tall.tif");
    write_tiff_header(tall, 1, 1u << 25);
    const auto r = run_lensmith("bokeh --image " + tall.string() + " --depth " + kScene + render + scratch("tall.exr").string());
    CHECK(r.exit_code == 3);
    CHECK(r.err.find(tall.string() + ": TIFF of 1 x 33554432 pixels") != std::string::npos);
  }
  SECTION("without the module: exit 5, saying where it looked, nothing written") { check_without_module("liblensmith_tiff.so", "nowhere.tif", render); }
}
