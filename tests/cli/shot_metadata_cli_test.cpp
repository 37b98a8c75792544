// lensmith bokeh with camera metadata in the picture and with overscan (docs/sequences.md).
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <string>

#include "lensmith/imageio/image_file.h"
#include "lensmith/render/image.h"
#include "lensmith/render/image_io.h"
#include "run_lensmith.h"

namespace fs = std::filesystem;
using lensmith::testing::run_lensmith;

namespace {

const std::string kScene = std::string(LENSMITH_SOURCE_DIR) + "/examples/bokeh-scene.exr";

fs::path scratch(const std::string& name) {
  static const lensmith::testing::ScratchFolder folder("lensmith_shot_metadata_cli_");
  return folder.dir / name;
}

// The bundled scene (RGB and Z) rewritten with `attributes` and, optionally, OpenEXR windows.
// Without its `skip_columns` leftmost columns when given (a data window that starts further right).
void write_scene(const fs::path& path, const std::vector<lensmith::ImageAttribute>& attributes,
                 const std::optional<std::pair<lensmith::PixelBox, lensmith::PixelBox>>& windows = {}, int skip_columns = 0) {
  const lensmith::Image rgb = lensmith::read_radiance_image(kScene);
  const lensmith::RasterInfo info = lensmith::read_raster_info(kScene);
  const int z_channel = info.channel_index("Z");
  REQUIRE(z_channel >= 0);
  const int channels[1] = {z_channel};
  const lensmith::Raster z = lensmith::read_raster(kScene, info, channels);
  std::vector<float> samples(rgb.pixel_count() * 4);
  for (std::size_t i = 0; i < rgb.pixel_count(); ++i) {
    for (std::size_t c = 0; c < 3; ++c) samples[4 * i + c] = rgb.data[3 * i + c];
    samples[4 * i + 3] = z.samples[i];
  }
  if (skip_columns > 0) samples = lensmith::crop_pixels(samples, rgb.width, 4, skip_columns, 0, rgb.width - skip_columns, rgb.height);
  lensmith::write_exr(path, lensmith::PixelsView<float>{rgb.width - skip_columns, rgb.height, 4, samples}, {"R", "G", "B", "Z"}, attributes,
                      windows);
}

std::string attribute(const fs::path& file, const std::string& key) {
  for (const auto& [k, v] : lensmith::read_image_metadata(file)) {
    if (k == key) return v;
  }
  return "";
}

double max_difference(const fs::path& a, const fs::path& b) {
  const lensmith::Image x = lensmith::read_radiance_image(a), y = lensmith::read_radiance_image(b);
  REQUIRE(x.data.size() == y.data.size());
  double d = 0.0;
  for (std::size_t i = 0; i < x.data.size(); ++i) d = std::max(d, static_cast<double>(std::abs(x.data[i] - y.data[i])));
  return d;
}

}  // namespace

TEST_CASE("OpenEXR's focus and aperture attributes set the camera, focus converted from the image plane to the pupil",
          "[cli][metadata]") {
  // Framing as the scene was rendered; focus 1.25 m from the image plane, f/2.8.
  // OpenEXR's focus, aperture and entrancePupilOffset are float attributes: 2^-24 = 6e-8 relative each.
  constexpr double kFloatAttribute = 1e-6;
  // The Canon is scaled to a 35 mm EFL (lenses/README.md): this only tells the lens's focal length from the 50 mm framing's.
  constexpr double kLensFocalLength_mm = 0.5;
  const fs::path in = scratch("std.exr");
  write_scene(in, {{"lensmith:focal_length_mm", 50.0}, {"lensmith:sensor_width_mm", 36.0}, {"focus", 1.25, true}, {"aperture", 2.8, true}});
  const fs::path out = scratch("std_out.exr");
  const auto r = run_lensmith("bokeh --image " + in.string() + " --lens canon-35mm-f1.8-1956 --no-spectral -o " + out.string());
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  CHECK(r.err.find("focus 1.25 m from the image plane") != std::string::npos);
  // The output says where it focused, both ways: from the pupil (lensmith) and from the image plane
  // (OpenEXR), the difference being its entrance pupil offset.
  const double pupil_m = std::stod(attribute(out, "lensmith:focus_m"));
  const double offset_mm = std::stod(attribute(out, "entrancePupilOffset"));
  CHECK(std::stod(attribute(out, "focus")) == Approx(1.25).epsilon(kFloatAttribute));  // float attribute
  CHECK(pupil_m + offset_mm / 1000.0 == Approx(1.25).epsilon(kFloatAttribute));
  CHECK(offset_mm > 30.0);  // a 35 mm lens focused near 1.2 m: its sensor lies ~36 mm behind its entrance pupil
  CHECK(std::stod(attribute(out, "FNumber")) == Approx(2.8).epsilon(kFloatAttribute));
  CHECK(std::stod(attribute(out, "focalLength")) == Approx(35.0).margin(kLensFocalLength_mm));
  // The same picture as the flags would make.
  const fs::path flags = scratch("std_flags.exr");
  REQUIRE(run_lensmith("bokeh --image " + in.string() + " --lens canon-35mm-f1.8-1956 --no-spectral --quiet --fstop 2.8 --focus " +
                       attribute(out, "lensmith:focus_m") + " -o " + flags.string())
              .exit_code == 0);
  CHECK(max_difference(out, flags) < 1e-4);
  // The flags win over the file.
  const auto flag_wins = run_lensmith("bokeh --image " + in.string() + " --lens canon-35mm-f1.8-1956 --no-spectral --fstop 4 --focus 3 -o " +
                                      scratch("flags_win.exr").string());
  CHECK(std::stod(attribute(scratch("flags_win.exr"), "FNumber")) == Approx(4.0));
}

TEST_CASE("Unreal's Movie Render Queue keys set focus (cm from the camera), f-number and blades", "[cli][metadata]") {
  const fs::path in = scratch("ue.exr");
  write_scene(in, {{"lensmith:focal_length_mm", 50.0}, {"lensmith:sensor_width_mm", 36.0}, {"unreal/camera/FinalImage/focalDistance", "250"},
                   {"unreal/camera/FinalImage/fstop", "2"}, {"unreal/camera/FinalImage/dofDiaphragmBladeCount", "6"}});
  const fs::path out = scratch("ue_out.exr");
  const auto r = run_lensmith("bokeh --image " + in.string() + " --thin-lens --focal-length 50 --no-spectral -o " + out.string());
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  CHECK(std::stod(attribute(out, "lensmith:focus_m")) == Approx(2.5));
  CHECK(attribute(out, "lensmith:aperture").find("6 blades") != std::string::npos);
}

TEST_CASE("overscan: the pixels beyond the frame are photographed, the output keeps the windows, a PNG gets the frame",
          "[cli][metadata][overscan]") {
  // The scene's 640 x 360 pixels as the data window around a 600 x 320 frame at (20, 20): the frame's
  // 36 mm sensor spans 600 px, so the data window is the whole picture framed 640/600 wider.
  const fs::path in = scratch("over.exr");
  const lensmith::PixelBox data{0, 0, 639, 359}, frame{20, 20, 619, 339};
  write_scene(in, {{"lensmith:focal_length_mm", 50.0}, {"lensmith:sensor_width_mm", 36.0}}, std::pair{data, frame});
  const fs::path out = scratch("over_out.exr"), png = scratch("over_out.png");
  const std::string common = " --lens zeiss-biotar-1927 --focus 2 --no-spectral --quiet";
  REQUIRE(run_lensmith("bokeh --image " + in.string() + common + " -o " + out.string()).exit_code == 0);
  const lensmith::RasterInfo written = lensmith::read_raster_info(out);
  CHECK(written.data_window == data);
  CHECK(written.display_window == frame);
  REQUIRE(run_lensmith("bokeh --image " + in.string() + common + " -o " + png.string()).exit_code == 0);
  CHECK(lensmith::read_raster_info(png).width == 600);
  CHECK(lensmith::read_raster_info(png).height == 320);
  // The same as the whole picture without overscan on a sensor 640/600 as wide (38.4 mm): 1e-4 allows
  // for the focal length in pixels reached by two roundings.
  const fs::path wide = scratch("wide.exr");
  REQUIRE(run_lensmith("bokeh --image " + kScene + common + " --sensor-width 38.4 -o " + wide.string()).exit_code == 0);
  CHECK(max_difference(out, wide) < 1e-4);

  // A crop (data inside the frame) is refused.
  const fs::path cropped = scratch("cropped.exr");
  write_scene(cropped, {}, std::pair{data, lensmith::PixelBox{0, 0, 699, 399}});
  const auto r = run_lensmith("bokeh --image " + cropped.string() + common + " -o " + scratch("y.exr").string());
  CHECK(r.exit_code == 3);
  CHECK(r.err.find("cropped") != std::string::npos);
}

TEST_CASE("overscan wider on one side: the axis stays at the frame's centre, and away from the short side the picture is the "
          "symmetric one's", "[cli][metadata][overscan]") {
  // The symmetric case above (640 x 360 around the frame at (20, 20)), and the same without its 10
  // leftmost columns: overscan of 10 px on the left, 20 on the right. lensmith extends the left edge
  // by 10 px to centre the axis; beyond the reach of the blur from those columns the two agree.
  const lensmith::PixelBox frame{20, 20, 619, 339};
  const fs::path whole = scratch("sym.exr"), lopsided = scratch("lopsided.exr");
  write_scene(whole, {{"lensmith:focal_length_mm", 50.0}, {"lensmith:sensor_width_mm", 36.0}}, std::pair{lensmith::PixelBox{0, 0, 639, 359}, frame});
  write_scene(lopsided, {{"lensmith:focal_length_mm", 50.0}, {"lensmith:sensor_width_mm", 36.0}}, std::pair{lensmith::PixelBox{10, 0, 639, 359}, frame},
              10);
  const std::string common = " --lens zeiss-biotar-1927 --focus 2 --no-spectral --quiet";
  const fs::path a = scratch("sym_out.exr"), b = scratch("lopsided_out.exr");
  REQUIRE(run_lensmith("bokeh --image " + whole.string() + common + " -o " + a.string()).exit_code == 0);
  const auto r = run_lensmith("bokeh --image " + lopsided.string() + common + " -o " + b.string());
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const lensmith::RasterInfo written = lensmith::read_raster_info(b);
  CHECK(written.data_window == lensmith::PixelBox{10, 0, 639, 359});  // the input's windows, kept
  CHECK(written.display_window == frame);
  const lensmith::Image x = lensmith::read_radiance_image(a), y = lensmith::read_radiance_image(b);
  REQUIRE(y.width == 630);
  // Columns 60 and more px from the extended edge: the largest blur here is about 14 px, and the
  // hidden-surface fill reaches a few pyramid levels further. 1e-4: float sums in another order.
  double far_from_edge = 0.0, near_edge = 0.0;
  for (int row = 0; row < y.height; ++row) {
    for (int col = 0; col < y.width; ++col) {
      for (int c = 0; c < 3; ++c) {
        const double d = std::abs(static_cast<double>(x.data[(static_cast<std::size_t>(row) * 640 + col + 10) * 3 + c]) -
                                  y.data[(static_cast<std::size_t>(row) * 630 + col) * 3 + c]);
        (col >= 60 ? far_from_edge : near_edge) = std::max(col >= 60 ? far_from_edge : near_edge, d);
      }
    }
  }
  INFO("near the extended edge the largest difference is " << near_edge);
  CHECK(far_from_edge < 1e-4);
}
