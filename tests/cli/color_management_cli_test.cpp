// lensmith bokeh with OpenColorIO colour spaces (docs/color-management.md), with lensmith's test
// config (tests/data/ocio/config.ocio, the Academy's published ACEScg matrix).
#include <catch2/catch.hpp>
#include <stdlib.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>

#include "lensmith/color/rgb_primaries.h"
#include "lensmith/imageio/image_file.h"
#include "lensmith/render/image.h"
#include "lensmith/render/image_io.h"
#include "run_lensmith.h"

namespace fs = std::filesystem;
using lensmith::testing::run_lensmith;

namespace {

const std::string kScene = std::string(LENSMITH_SOURCE_DIR) + "/examples/bokeh-scene.exr";
const std::string kConfig = std::string(LENSMITH_TEST_DATA_DIR) + "/ocio/config.ocio";
// Academy S-2014-004: AP1's red, green, blue and the ACES white, as read_image_metadata prints them.
constexpr const char* kAp1Chromaticities = "0.713, 0.293, 0.165, 0.83, 0.128, 0.044, 0.32168, 0.33767";
// The framing given, since the converted plate does not carry the scene's own lensmith attributes.
const std::string kCamera = " --lens canon-35mm-f1.8-1956 --focus 1.2 --pinhole-focal-length 50 --sensor-width 36 --quiet";

fs::path scratch(const std::string& name) {
  static const lensmith::testing::ScratchFolder folder("lensmith_color_cli_");
  return folder.dir / name;
}

// The linear Rec.709 pixels of `image` in AP1 (ACEScg), by lensmith's Bradford matrix (equal to
// the Academy's published one to 1e-10, tests/color/rgb_primaries_test.cpp).
lensmith::Image to_acescg(lensmith::Image image) {
  const lensmith::Matrix3 m = lensmith::rgb_conversion(lensmith::kRec709Primaries, lensmith::kAcesAp1Primaries);
  for (std::size_t i = 0; i < image.pixel_count(); ++i) {
    float* p = &image.data[3 * i];
    const auto v = m * std::array<double, 3>{p[0], p[1], p[2]};
    for (int c = 0; c < 3; ++c) p[c] = static_cast<float>(v[c]);
  }
  return image;
}

// The bundled scene with its depth, its colours in ACEScg.
std::string acescg_scene() {
  const fs::path path = scratch("plate_acescg.exr");
  if (fs::exists(path)) return path.string();
  const lensmith::Image rgb = to_acescg(lensmith::read_radiance_image(kScene));
  const lensmith::RasterInfo info = lensmith::read_raster_info(kScene);
  const int channels[1] = {info.channel_index("Z")};
  const lensmith::Raster z = lensmith::read_raster(kScene, info, channels);
  std::vector<float> samples(rgb.pixel_count() * 4);
  for (std::size_t i = 0; i < rgb.pixel_count(); ++i) {
    std::copy_n(&rgb.data[3 * i], 3, &samples[4 * i]);
    samples[4 * i + 3] = z.samples[i];
  }
  // The ACES AP1 primaries and white in OpenEXR's standard chromaticities attribute.
  lensmith::write_exr(path, lensmith::PixelsView<float>{rgb.width, rgb.height, 4, samples}, {"R", "G", "B", "Z"},
                      {{"chromaticities", std::string(kAp1Chromaticities)}});
  return path.string();
}

std::string attribute(const fs::path& file, const std::string& key) {
  for (const auto& [k, v] : lensmith::read_image_metadata(file)) {
    if (k == key) return v;
  }
  return "";
}

}  // namespace

TEST_CASE("an ACEScg plate in and out gives the linear Rec.709 render of the same scene, in ACEScg", "[cli][ocio]") {
  const auto cg = run_lensmith("bokeh --image " + acescg_scene() + " --depth " + kScene + " -o " + scratch("cg.exr").string() +
                               " --input-colorspace ACEScg --ocio " + kConfig + kCamera);
  INFO(cg.err);
  REQUIRE(cg.exit_code == 0);
  const auto plain = run_lensmith("bokeh --image " + kScene + " -o " + scratch("plain.exr").string() + kCamera);
  REQUIRE(plain.exit_code == 0);
  // The renderer is linear in the picture's RGB (spectra too: spectral_basis.h), so converting
  // before and after it is converting its result. 2e-5 relative: float pixels through the config's
  // 10-decimal matrices, the renderer's float sums and the test's own conversion.
  const lensmith::Image expected = to_acescg(lensmith::read_radiance_image(scratch("plain.exr")));
  const lensmith::Image got = lensmith::read_radiance_image(scratch("cg.exr"));
  REQUIRE(got.data.size() == expected.data.size());
  double worst = 0.0;
  for (std::size_t i = 0; i < got.data.size(); ++i) {
    worst = std::max(worst, std::abs(static_cast<double>(got.data[i]) - expected.data[i]) / std::max(1.0, std::abs(static_cast<double>(expected.data[i]))));
  }
  CHECK(worst < 2e-5);
  CHECK(attribute(scratch("cg.exr"), "lensmith:colorspace") == "ACEScg");
  CHECK(attribute(scratch("cg.exr"), "lensmith:ocio_config") == kConfig);
  CHECK(attribute(scratch("plain.exr"), "lensmith:colorspace").empty());  // without colour management, as before
  // ACEScg in, ACEScg out: the picture's chromaticities are the output's.
  CHECK(attribute(scratch("cg.exr"), "chromaticities") == kAp1Chromaticities);
}

TEST_CASE("a picture whose chromaticities are not Rec.709 gets a note without --input-colorspace, and keeps them", "[cli][ocio]") {
  const auto r = run_lensmith("bokeh --image " + acescg_scene() + " --depth " + kScene + " -o " + scratch("as-is.exr").string() +
                              " --lens canon-35mm-f1.8-1956 --focus 1.2 --pinhole-focal-length 50");
  REQUIRE(r.exit_code == 0);
  CHECK(r.err.find("chromaticities are not Rec.709 (ACES AP1: ACEScg)") != std::string::npos);
  CHECK(attribute(scratch("as-is.exr"), "chromaticities") == kAp1Chromaticities);  // the numbers are still AP1's
  // Converted to another colour space, the input's primaries no longer describe the output.
  const auto to709 = run_lensmith("bokeh --image " + acescg_scene() + " --depth " + kScene + " -o " + scratch("to709.exr").string() +
                                  " --input-colorspace ACEScg --output-colorspace lin_rec709 --ocio " + kConfig + kCamera);
  REQUIRE(to709.exit_code == 0);
  CHECK(attribute(scratch("to709.exr"), "chromaticities").empty());
}

TEST_CASE("the OCIO config comes from $OCIO, and a PNG from an ACEScg plate is an sRGB picture of the same colours", "[cli][ocio]") {
  setenv("OCIO", kConfig.c_str(), 1);
  const auto r = run_lensmith("bokeh --image " + acescg_scene() + " --depth " + kScene + " -o " + scratch("cg.png").string() +
                              " --input-colorspace ACEScg" + kCamera);
  unsetenv("OCIO");
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  REQUIRE(run_lensmith("bokeh --image " + kScene + " -o " + scratch("plain.png").string() + kCamera).exit_code == 0);
  // The same 8-bit sRGB codes but for rounding (1 code).
  const lensmith::Image a = lensmith::read_radiance_image(scratch("cg.png")), b = lensmith::read_radiance_image(scratch("plain.png"));
  REQUIRE(a.data.size() == b.data.size());
  int worst_code = 0;
  for (std::size_t i = 0; i < a.data.size(); ++i) {
    worst_code = std::max(worst_code, static_cast<int>(std::lround(std::abs(lensmith::srgb_encode(a.data[i]) - lensmith::srgb_encode(b.data[i])) * 255.0)));
  }
  CHECK(worst_code <= 1);
}

TEST_CASE("colour management refuses what it cannot do right, saying why", "[cli][ocio]") {
  const std::string out = " -o " + scratch("bad.exr").string();
  SECTION("a colour space the config lacks: exit 3, naming some it has") {
    const auto r = run_lensmith("bokeh --image " + kScene + out + " --input-colorspace ACEScct --ocio " + kConfig + kCamera);
    CHECK(r.exit_code == 3);
    CHECK(r.err.find("ACEScg") != std::string::npos);
  }
  SECTION("an output colour space for a PNG, which is an sRGB picture: exit 2") {
    const auto r = run_lensmith("bokeh --image " + kScene + " -o " + scratch("bad.png").string() + " --output-colorspace ACEScg --ocio " + kConfig + kCamera);
    CHECK(r.exit_code == 2);
    CHECK(r.err.find(".exr output") != std::string::npos);
  }
  SECTION("an input colour space for 8-bit sRGB codes: exit 2") {
    REQUIRE(run_lensmith("bokeh --image " + kScene + " -o " + scratch("in.png").string() + kCamera).exit_code == 0);
    const auto r = run_lensmith("bokeh --image " + scratch("in.png").string() + " --depth " + kScene + out +
                                " --input-colorspace ACEScg --ocio " + kConfig + kCamera);
    CHECK(r.exit_code == 2);
    CHECK(r.err.find("uint8") != std::string::npos);
  }
  SECTION("without its OpenColorIO module (lensmith/core/module_loader.h): exit 5, saying where it looked, nothing written") {
    const fs::path modules = scratch("no-modules");
    fs::create_directories(modules);
    ::setenv("LENSMITH_MODULE_DIR", modules.c_str(), 1);
    const auto r = run_lensmith("bokeh --image " + kScene + out + " --input-colorspace ACEScg --ocio " + kConfig + kCamera);
    ::unsetenv("LENSMITH_MODULE_DIR");
    CHECK(r.exit_code == 5);
    CHECK(r.err.find((modules / "liblensmith_ocio.so").string()) != std::string::npos);
    CHECK(r.err.find("LENSMITH_MODULE_DIR") != std::string::npos);
    CHECK_FALSE(fs::exists(scratch("bad.exr")));
  }
  SECTION("--ocio alone converts nothing: exit 2") {
    CHECK(run_lensmith("bokeh --image " + kScene + out + " --ocio " + kConfig + kCamera).exit_code == 2);
  }
  SECTION("no config at all: the message says how to give one") {
    unsetenv("OCIO");
    const auto r = run_lensmith("bokeh --image " + kScene + out + " --input-colorspace ACEScg" + kCamera);
    CHECK(r.exit_code != 0);
    CHECK(r.err.find("--ocio") != std::string::npos);
  }
  CHECK_FALSE(fs::exists(scratch("bad.exr")));
}
