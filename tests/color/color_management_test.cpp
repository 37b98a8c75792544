// Colour management through OpenColorIO (color_management.h), with lensmith's test config
// (tests/data/ocio/config.ocio, whose matrices are the Academy's published numbers): pictures reach
// the working space (linear Rec.709) from ACEScg, from the config's own linear Rec.709 and from an
// sRGB-encoded space as the colour science says they should, and come back unchanged.
#include "lensmith/color/color_management.h"

#include <catch2/catch.hpp>
#include <stdlib.h>

#include <array>
#include <filesystem>
#include <fstream>
#include <vector>

#include "lensmith/color/rgb_primaries.h"
#include "lensmith/core/errors.h"

using Catch::Matchers::Contains;
using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;
using namespace lensmith;

namespace {

const std::string kConfig = std::string(LENSMITH_TEST_DATA_DIR) + "/ocio/config.ocio";
// 32-bit float pixels through an 8-decimal config matrix and lensmith's double matrix: 2e-6 relative.
constexpr double kFloatAndSevenDecimals = 2e-6;

ColorManagement with(const std::string& input, const std::string& output) {
  ColorManagementOptions o;
  o.config = kConfig;
  o.input_colorspace = input;
  o.output_colorspace = output;
  return ColorManagement(o);
}

}  // namespace

TEST_CASE("an ACEScg pixel reaches linear Rec.709 as the AP1 to Rec.709 Bradford matrix takes it", "[color][ocio]") {
  const ColorManagement cm = with("ACEScg", "");
  const std::array<double, 3> ap1{0.8, 0.2, 0.05};  // a saturated orange, outside Rec.709 in red
  std::vector<float> pixel{0.8f, 0.2f, 0.05f};
  cm.input_to_working(pixel, 3);
  const auto expected = rgb_conversion(kAcesAp1Primaries, kRec709Primaries) * ap1;
  for (int c = 0; c < 3; ++c) CHECK_THAT(pixel[c], WithinAbs(expected[c], kFloatAndSevenDecimals));
  CHECK(cm.working_route().find("aces_interchange") != std::string::npos);
}

TEST_CASE("the config's own linear Rec.709 is lensmith's working space, and sRGB-encoded values are decoded", "[color][ocio]") {
  std::vector<float> linear{0.18f, 0.5f, 2.0f};
  with("lin_rec709", "").input_to_working(linear, 3);  // an alias of "Linear Rec.709 (sRGB)"
  CHECK_THAT(linear[0], WithinRel(0.18, kFloatAndSevenDecimals));
  CHECK_THAT(linear[1], WithinRel(0.5, kFloatAndSevenDecimals));
  CHECK_THAT(linear[2], WithinRel(2.0, kFloatAndSevenDecimals));
  // IEC 61966-2-1: the code 0.5 is ((0.5 + 0.055) / 1.055)^2.4 = 0.2140411 of linear light.
  std::vector<float> encoded{0.5f, 0.5f, 0.5f};
  with("sRGB Encoded Rec.709 (sRGB)", "").input_to_working(encoded, 3);
  CHECK_THAT(encoded[0], WithinRel(0.2140411, 1e-5));
}

TEST_CASE("ACEScg in and out: every value comes back, negative and HDR ones too, and other channels are not touched", "[color][ocio]") {
  const ColorManagement cm = with("ACEScg", "ACEScg");
  // Three pixels of R, G, B, A, Z: a grey, an HDR highlight, a colour outside Rec.709 (negative there).
  const std::vector<float> original{0.18f, 0.18f, 0.18f, 1.0f, 3.5f, 900.0f, 850.0f, 700.0f, 0.5f, 12.0f, 0.02f, 0.6f, 0.01f, 1.0f, 1e9f};
  std::vector<float> pixels = original;
  cm.input_to_working(pixels, 5);
  CHECK(pixels[3] == 1.0f);
  CHECK(pixels[4] == 3.5f);
  CHECK(pixels[14] == 1e9f);
  CHECK(pixels[10] < 0.0f);  // the green of AP1 is beyond Rec.709: negative red in the working space
  cm.working_to_output(pixels, 5);
  for (std::size_t i = 0; i < pixels.size(); ++i) CHECK_THAT(pixels[i], WithinAbs(original[i], 2e-6 * std::max(1.0f, std::abs(original[i]))));
}

TEST_CASE("without colour spaces nothing is converted", "[color][ocio]") {
  const ColorManagement cm = with("", "");
  std::vector<float> pixel{0.3f, 0.2f, 0.1f};
  cm.input_to_working(pixel, 3);
  cm.working_to_output(pixel, 3);
  CHECK(pixel == std::vector<float>{0.3f, 0.2f, 0.1f});
}

TEST_CASE("the config comes from $OCIO when no file is given, and its absence is a clear error", "[color][ocio]") {
  ColorManagementOptions o;
  o.input_colorspace = "ACEScg";
  const char* saved = std::getenv("OCIO");
  const std::string previous = saved ? saved : "";
  unsetenv("OCIO");
  CHECK_THROWS_WITH(ColorManagement(o), Contains("--ocio CONFIG or set $OCIO"));
  setenv("OCIO", kConfig.c_str(), 1);
  CHECK_NOTHROW(ColorManagement(o));
  setenv("OCIO", "/nonexistent/config.ocio", 1);
  CHECK_THROWS_AS(ColorManagement(o), IoError);
  if (saved) setenv("OCIO", previous.c_str(), 1); else unsetenv("OCIO");
}

TEST_CASE("bad colour management input is refused with what was expected", "[color][ocio]") {
  SECTION("a colour space the config does not have names some it has") {
    CHECK_THROWS_AS(with("ACEScct", ""), OptionsError);
    CHECK_THROWS_WITH(with("", "ACEScct"), Contains("--output-colorspace ACEScct") && Contains("ACEScg"));
  }
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "lensmith_ocio_test";
  std::filesystem::create_directories(dir);
  SECTION("a file that is not a config") {
    const auto path = (dir / "garbage.ocio").string();
    std::ofstream(path) << "this: [is not an OCIO config\n";
    ColorManagementOptions o;
    o.config = path;
    o.input_colorspace = "ACEScg";
    CHECK_THROWS_AS(ColorManagement(o), IoError);
  }
  SECTION("a config without an aces_interchange role asks for --working-colorspace, and works with it") {
    const auto path = (dir / "no_interchange.ocio").string();
    std::ofstream(path) << "ocio_profile_version: 1\nroles:\n  default: lin\n  scene_linear: lin\ndisplays:\n  sRGB:\n"
                           "    - !<View> {name: Raw, colorspace: lin}\ncolorspaces:\n  - !<ColorSpace>\n    name: lin\n"
                           "  - !<ColorSpace>\n    name: double\n    to_reference: !<MatrixTransform> {matrix: [2, 0, 0, 0, 0, 2, 0, 0, 0, 0, 2, 0, 0, 0, 0, 1]}\n";
    ColorManagementOptions o;
    o.config = path;
    o.input_colorspace = "double";
    CHECK_THROWS_WITH(ColorManagement(o), Contains("--working-colorspace"));
    o.working_colorspace = "lin";
    const ColorManagement cm(o);
    std::vector<float> pixel{0.1f, 0.2f, 0.3f};
    cm.input_to_working(pixel, 3);
    CHECK_THAT(pixel[2], WithinRel(0.6, 1e-7));
  }
  std::filesystem::remove_all(dir);
}
