// Image and depth input/output: the sRGB curve against IEC 61966-2-1:1999 (5.2, 5.3), exact float
// round trips through OpenEXR, depth conventions (planar z, Euclidean distance, inverse depth) against
// their defining formulas, and the errors a user sees for bad files.
#include "lensmith/render/image_io.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <string>

#include "lensmith/core/errors.h"

using Catch::Matchers::Contains;
using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;
using namespace lensmith;
namespace fs = std::filesystem;

namespace {

// IEC 61966-2-1 prints its breakpoints rounded: 0.0031308 stands for 0.04045 / 12.92 = 0.0031308050,
// and the power law at 0.04045 gives 0.0031308073, up to 2.3e-6 relative from the printed value.
constexpr double kIecBreakpointRounding = 3e-6;
// srgb_encode/decode compute in double and round once to float: a round trip keeps ~1 float ulp.
constexpr double kFloatRoundTrip = 1e-6;
// OpenImageIO turns a code value into a float within a few ulps (6e-8 each) of code / 255; near the
// threshold the highlight factor magnifies that by 1 / (1 - threshold) = 50 times the smoothstep slope.
constexpr double kHighlightFactorFromFloatCode = 2e-5;
// One code value of a 16-bit channel (the TIFF output).
constexpr double kOne16BitStep = 1.0 / 65535.0;
// Radiance RGBE keeps an 8-bit mantissa per channel over a shared exponent: ~1/256 relative.
constexpr double kRgbeMantissa = 1.0 / 128.0;
// JPEG quality 95 on a flat colour moves a code value by a step or two.
constexpr double kJpeg95OnFlatColour = 3.0 / 255.0;
// Depth is stored as float: conversions keep float relative precision.
constexpr double kFloatDepth = 1e-6;

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// A fresh directory under the system temporary folder, removed with everything in it at the end.
struct TempDir {
  fs::path path;
  TempDir() {
    std::random_device rd;
    path = fs::temp_directory_path() / ("lensmith_image_io_test_" + std::to_string(rd()) + std::to_string(rd()));
    fs::create_directories(path);
  }
  ~TempDir() {
    std::error_code ignored;
    fs::remove_all(path, ignored);
  }
  fs::path operator/(const std::string& name) const { return path / name; }
  std::vector<std::string> names() const {
    std::vector<std::string> out;
    for (const auto& entry : fs::directory_iterator(path)) out.push_back(entry.path().filename().string());
    std::sort(out.begin(), out.end());
    return out;
  }
};

// A 4 x 3 RGB image with a distinct value in every channel of every pixel.
Image gradient_rgb() {
  Image image(4, 3, 3);
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      for (int c = 0; c < 3; ++c) image.at(x, y, c) = 0.01f * static_cast<float>(1 + x + 10 * y) + 0.3f * static_cast<float>(c);
    }
  }
  return image;
}

// A one-channel float EXR holding `values` (row-major) under `name`.
fs::path write_channel(const TempDir& dir, const std::string& file, const std::string& name, int width, int height,
                       const std::vector<float>& values) {
  Image image(width, height, 1);
  image.data = values;
  const fs::path path = dir / file;
  write_float_exr(path, image, {name});
  return path;
}

std::string value_of(const std::vector<std::pair<std::string, std::string>>& metadata, const std::string& name) {
  for (const auto& [key, value] : metadata) {
    if (key == name) return value;
  }
  return "<absent>";
}

// 4 x 3 pixels, focal length 2 px: wide enough that the corner direction is far off axis.
PinholeFrame small_frame() { return PinholeFrame(4, 3, 2.0); }

}  // namespace

// ---- sRGB ----------------------------------------------------------------------------------------

TEST_CASE("sRGB: the two pieces of the curve meet at the IEC 61966-2-1 breakpoint 0.04045 <-> 0.0031308", "[render][image_io][srgb]") {
  CHECK_THAT(srgb_decode(0.04045f), WithinRel(0.0031308, kIecBreakpointRounding));
  CHECK_THAT(srgb_encode(0.0031308f), WithinRel(0.04045, kIecBreakpointRounding));
  // Continuity: the power-law piece, evaluated at the breakpoint, gives the same value.
  CHECK_THAT(std::pow((0.04045 + 0.055) / 1.055, 2.4), WithinRel(0.0031308, kIecBreakpointRounding));
  CHECK(srgb_decode(0.0f) == 0.0f);
  CHECK(srgb_encode(0.0f) == 0.0f);
}

TEST_CASE("sRGB: full scale maps to full scale, 1 <-> 1", "[render][image_io][srgb]") {
  CHECK_THAT(srgb_decode(1.0f), WithinAbs(1.0, kFloatRoundTrip));
  CHECK_THAT(srgb_encode(1.0f), WithinAbs(1.0, kFloatRoundTrip));
}

TEST_CASE("sRGB: encoding undoes decoding across [0, 1]", "[render][image_io][srgb]") {
  for (int i = 0; i <= 1000; ++i) {
    const float e = static_cast<float>(i) / 1000.0f;
    INFO("encoded " << e << " -> linear " << srgb_decode(e));
    CHECK_THAT(srgb_encode(srgb_decode(e)), WithinAbs(e, kFloatRoundTrip));
  }
}

// ---- radiance ------------------------------------------------------------------------------------

TEST_CASE("an 8-bit PNG of code value 128 reads as linear ((128/255 + 0.055) / 1.055)^2.4 = 0.2158605", "[render][image_io]") {
  TempDir dir;
  const fs::path png = dir / "grey.png";
  // Written through the sRGB encoder: 128 / 255 decoded lands exactly on code value 128 again.
  write_output_image(png, Image(2, 2, 3, srgb_decode(128.0f / 255.0f)), {});
  const Image image = read_radiance_image(png);
  REQUIRE(image.channels == 3);
  REQUIRE(image.width == 2);
  for (int c = 0; c < 3; ++c) CHECK_THAT(image.at(1, 1, c), WithinAbs(0.2158605, kFloatRoundTrip));
}

TEST_CASE("a float EXR round-trips exactly through write_output_image and read_radiance_image", "[render][image_io]") {
  TempDir dir;
  const fs::path exr = dir / "render.EXR";  // the extension is matched in any case
  Image original = gradient_rgb();
  original.at(3, 2, 0) = 1234.5f;  // radiance far above display white stays as it is
  original.at(0, 0, 2) = 0.0f;
  write_output_image(exr, original, {});
  const Image read = read_radiance_image(exr);
  REQUIRE(read.width == original.width);
  REQUIRE(read.height == original.height);
  REQUIRE(read.channels == 3);
  CHECK(read.data == original.data);
}

TEST_CASE("EXR output records lens, f-number, focus, model, version and extra keys as lensmith: attributes", "[render][image_io]") {
  TempDir dir;
  const fs::path exr = dir / "render.exr";
  OutputMetadata meta;
  meta.lens = "double-gauss-50";
  meta.model = "exact";
  meta.lensmith_version = "0.3.0";
  meta.f_number = 2.8;
  meta.focus_m = 2.5;
  meta.extra = {{"samples", "64"}};
  write_output_image(exr, gradient_rgb(), meta);
  const auto metadata = read_image_metadata(exr);
  CHECK(value_of(metadata, "lensmith:lens") == "double-gauss-50");
  CHECK(value_of(metadata, "lensmith:model") == "exact");
  CHECK(value_of(metadata, "lensmith:version") == "0.3.0");
  CHECK(value_of(metadata, "lensmith:f_number") == "2.8");
  CHECK(value_of(metadata, "lensmith:focus_m") == "2.5");
  CHECK(value_of(metadata, "lensmith:samples") == "64");
  CHECK(value_of(metadata, "Software") == "lensmith 0.3.0");
  CHECK_THAT(value_of(metadata, "ImageDescription"), Contains("f/2.8") && Contains("focus 2.5 m") && Contains("double-gauss-50"));
  CHECK(value_of(metadata, "compression") == "zip");
}

TEST_CASE("PNG output records Software and an ImageDescription of the lens settings", "[render][image_io]") {
  TempDir dir;
  const fs::path png = dir / "render.png";
  OutputMetadata meta;
  meta.lens = "triplet";
  meta.f_number = 4.0;
  meta.lensmith_version = "0.3.0";
  write_output_image(png, gradient_rgb(), meta);
  const auto metadata = read_image_metadata(png);
  CHECK(value_of(metadata, "Software") == "lensmith 0.3.0");
  CHECK_THAT(value_of(metadata, "ImageDescription"), Contains("lens triplet") && Contains("f/4"));
}

TEST_CASE("16-bit TIFF, JPEG and HDR outputs read back within their quantisation", "[render][image_io]") {
  TempDir dir;
  const Image original = gradient_rgb();
  SECTION("16-bit TIFF: one code value of the sRGB encoding") {
    const fs::path tif = dir / "render.tiff";
    write_output_image(tif, original, {});
    const Image read = read_radiance_image(tif);
    for (std::size_t i = 0; i < original.data.size(); ++i) {
      INFO("value " << i);
      CHECK_THAT(srgb_encode(read.data[i]), WithinAbs(srgb_encode(original.data[i]), kOne16BitStep));
    }
  }
  SECTION("JPEG quality 95: a flat colour within a few code values") {
    const fs::path jpg = dir / "render.jpg";
    write_output_image(jpg, Image(16, 16, 3, 0.2f), {});
    const Image read = read_radiance_image(jpg);
    CHECK_THAT(srgb_encode(read.at(8, 8, 1)), WithinAbs(srgb_encode(0.2f), kJpeg95OnFlatColour));
  }
  SECTION("Radiance HDR: float, linear, an 8-bit mantissa") {
    const fs::path hdr = dir / "render.hdr";
    Image bright = original;
    bright.at(1, 1, 1) = 250.0f;
    write_output_image(hdr, bright, {});
    const Image read = read_radiance_image(hdr);
    CHECK_THAT(read.at(1, 1, 1), WithinRel(250.0, kRgbeMantissa));
    CHECK_THAT(read.at(2, 2, 2), WithinRel(static_cast<double>(bright.at(2, 2, 2)), kRgbeMantissa));
  }
}

TEST_CASE("RGB channels are found by name wherever they sit, and alpha is ignored", "[render][image_io]") {
  TempDir dir;
  Image image(2, 1, 4);
  image.data = {0.5f, 0.3f, 0.2f, 0.1f, 1.0f, 0.7f, 0.6f, 0.4f};  // per pixel: A, B, G, R
  const fs::path exr = dir / "abgr.exr";
  write_float_exr(exr, image, {"A", "B", "G", "R"});
  const Image read = read_radiance_image(exr);
  REQUIRE(read.channels == 3);
  CHECK(read.at(0, 0, 0) == 0.1f);
  CHECK(read.at(0, 0, 1) == 0.2f);
  CHECK(read.at(0, 0, 2) == 0.3f);
  CHECK(read.at(1, 0, 0) == 0.4f);
  CHECK(read.at(1, 0, 2) == 0.7f);
}

TEST_CASE("a gray float image is replicated to R = G = B", "[render][image_io]") {
  TempDir dir;
  const fs::path exr = write_channel(dir, "gray.exr", "Y", 2, 1, {0.25f, 3.0f});
  const Image read = read_radiance_image(exr);
  REQUIRE(read.channels == 3);
  for (int c = 0; c < 3; ++c) {
    CHECK(read.at(0, 0, c) == 0.25f);
    CHECK(read.at(1, 0, c) == 3.0f);
  }
}

TEST_CASE("NaN, infinite or negative radiance in a float file is refused, naming the pixel, channel and value", "[render][image_io]") {
  TempDir dir;
  Image image(3, 2, 3, 0.5f);
  SECTION("NaN") {
    image.at(2, 1, 1) = kNaN;
    const fs::path exr = dir / "nan.exr";
    write_float_exr(exr, image, {"R", "G", "B"});
    CHECK_THROWS_WITH(read_radiance_image(exr), Contains("pixel (2, 1) channel G = nan") && Contains("finite and >= 0"));
  }
  SECTION("negative") {
    image.at(1, 0, 0) = -0.25f;
    const fs::path exr = dir / "negative.exr";
    write_float_exr(exr, image, {"R", "G", "B"});
    CHECK_THROWS_AS(read_radiance_image(exr), ImageFileError);
    CHECK_THROWS_WITH(read_radiance_image(exr), Contains("negative.exr") && Contains("pixel (1, 0) channel R = -0.25"));
  }
  SECTION("infinite") {
    image.at(0, 1, 2) = kInf;
    const fs::path exr = dir / "inf.exr";
    write_float_exr(exr, image, {"R", "G", "B"});
    CHECK_THROWS_WITH(read_radiance_image(exr), Contains("pixel (0, 1) channel B = inf"));
  }
}

TEST_CASE("a missing or unreadable picture is an IoError naming the path", "[render][image_io]") {
  TempDir dir;
  CHECK_THROWS_AS(read_radiance_image(dir / "absent.exr"), IoError);
  CHECK_THROWS_WITH(read_radiance_image(dir / "absent.exr"), Contains("absent.exr"));
  const fs::path junk = dir / "junk.png";
  std::ofstream(junk) << "not a picture";
  CHECK_THROWS_AS(read_radiance_image(junk), IoError);
  CHECK_THROWS_WITH(read_radiance_image(junk), Contains("junk.png"));
}

TEST_CASE("highlight gain raises clipped pixels of an 8-bit picture and leaves unclipped ones alone", "[render][image_io]") {
  TempDir dir;
  const fs::path png = dir / "highlights.png";
  Image image(3, 1, 3, 0.0f);
  // Pixel 0: only red clipped (code 255). Pixel 1: unclipped mid grey. Pixel 2: code 252 (0.988),
  // halfway from the default threshold 0.98 to full scale.
  image.at(0, 0, 0) = 1.0f;
  image.at(0, 0, 1) = 0.2f;
  for (int c = 0; c < 3; ++c) image.at(1, 0, c) = 0.2f;
  for (int c = 0; c < 3; ++c) image.at(2, 0, c) = srgb_decode(252.0f / 255.0f);
  write_output_image(png, image, {});

  const Image plain = read_radiance_image(png);
  RadianceReadOptions options;
  options.highlight_gain = 4.0;
  const Image boosted = read_radiance_image(png, options);

  // Full scale gets the whole gain, on every channel of the pixel (its colour is kept).
  CHECK_THAT(boosted.at(0, 0, 0), WithinRel(4.0 * plain.at(0, 0, 0), kFloatRoundTrip));
  CHECK_THAT(boosted.at(0, 0, 1), WithinRel(4.0 * plain.at(0, 0, 1), kFloatRoundTrip));
  for (int c = 0; c < 3; ++c) CHECK(boosted.at(1, 0, c) == plain.at(1, 0, c));
  // Between threshold and full scale the factor follows the smoothstep: 1 + 3 s(u).
  const double u = (252.0 / 255.0 - 0.98) / (1.0 - 0.98);
  const double factor = 1.0 + 3.0 * u * u * (3.0 - 2.0 * u);
  CHECK(factor > 1.0);
  CHECK(factor < 4.0);
  CHECK_THAT(boosted.at(2, 0, 1), WithinRel(factor * plain.at(2, 0, 1), kHighlightFactorFromFloatCode));
}

TEST_CASE("highlight gain leaves float pictures alone", "[render][image_io]") {
  TempDir dir;
  const fs::path exr = dir / "hdr.exr";
  write_output_image(exr, Image(2, 2, 3, 1.0f), {});
  RadianceReadOptions options;
  options.highlight_gain = 8.0;
  CHECK(read_radiance_image(exr, options).at(0, 0, 0) == 1.0f);
}

TEST_CASE("RadianceReadOptions: the threshold must lie above 0 and at most 1, and the gain be at least 1", "[render][image_io]") {
  RadianceReadOptions options;
  CHECK_NOTHROW(options.validate());
  options.highlight_threshold = 0.0;
  CHECK_THROWS_WITH(options.validate(), Contains("highlight_threshold = 0") && Contains("(0, 1]"));
  options = {};
  options.highlight_gain = 0.5;
  CHECK_THROWS_AS(options.validate(), OptionsError);
  CHECK_THROWS_WITH(options.validate(), Contains("highlight_gain = 0.5") && Contains(">= 1"));
  CHECK(RadianceReadOptions{}.to_string() == "RadianceReadOptions(highlight_threshold 0.98, highlight_gain 1)");
}

// ---- depth ---------------------------------------------------------------------------------------

TEST_CASE("depth sources: FILE:CHANNEL splits at the last ':', an existing file name is never split", "[render][image_io][depth]") {
  const DepthSource plain = DepthSource::parse("depth.exr");
  CHECK(plain.file == fs::path("depth.exr"));
  CHECK(plain.channel.empty());
  const DepthSource named = DepthSource::parse("renders/shot:1.exr:ViewLayer.Depth.Z");
  CHECK(named.file == fs::path("renders/shot:1.exr"));
  CHECK(named.channel == "ViewLayer.Depth.Z");
  CHECK(named.to_string() == "renders/shot:1.exr:ViewLayer.Depth.Z");

  TempDir dir;
  const fs::path odd = dir / "take:2";
  std::ofstream(odd) << "x";
  const DepthSource existing = DepthSource::parse(odd.string());
  CHECK(existing.file == odd);
  CHECK(existing.channel.empty());

  CHECK_THROWS_WITH(DepthSource::parse("depth.exr:"), Contains("channel name after ':' is empty"));
  CHECK_THROWS_AS(DepthSource::parse(""), OptionsError);
}

TEST_CASE("depth words parse and print back, other words list the allowed ones", "[render][image_io][depth]") {
  for (const char* word : {"z", "distance", "inverse"}) CHECK(to_string(parse_depth_kind(word)) == word);
  for (const char* word : {"m", "cm", "mm"}) CHECK(to_string(parse_depth_unit(word)) == word);
  for (const char* word : {"error", "far", "near"}) CHECK(to_string(parse_invalid_depth(word)) == word);
  CHECK_THROWS_WITH(parse_depth_kind("depth"), Contains("z, distance or inverse"));
  CHECK_THROWS_WITH(parse_depth_unit("in"), Contains("m, cm or mm"));
  CHECK_THROWS_AS(parse_invalid_depth("zero"), OptionsError);
  CHECK_THROWS_WITH(parse_invalid_depth("zero"), Contains("error, far or near"));
  CHECK(DepthReadOptions{}.to_string() == "DepthReadOptions(kind z, unit m, invalid error)");
}

TEST_CASE("depth is read from the Z channel of an EXR that also holds RGB", "[render][image_io][depth]") {
  TempDir dir;
  Image rgbz(4, 3, 4, 0.5f);
  for (int y = 0; y < 3; ++y) {
    for (int x = 0; x < 4; ++x) rgbz.at(x, y, 3) = 1.0f + static_cast<float>(x + 4 * y);
  }
  rgbz.at(3, 2, 3) = kInf;  // infinitely far is a valid depth
  const fs::path exr = dir / "rgbz.exr";
  write_float_exr(exr, rgbz, {"R", "G", "B", "Z"});

  const DepthMap depth = read_depth(DepthSource{exr, ""}, {}, small_frame());
  CHECK(depth.width == 4);
  CHECK(depth.height == 3);
  CHECK(depth.at(0, 0) == 1.0f);
  CHECK(depth.at(2, 1) == 7.0f);
  CHECK(depth.at(3, 2) == kInf);
  // The same file still reads as the picture.
  CHECK(read_radiance_image(exr).at(2, 1, 0) == 0.5f);
}

TEST_CASE("the default depth channel is Z, then depth.Z, then the first channel, FILE:CHANNEL overrides", "[render][image_io][depth]") {
  TempDir dir;
  Image three(4, 3, 3);
  for (std::size_t i = 0; i < three.pixel_count(); ++i) {
    three.data[3 * i] = 1.0f;
    three.data[3 * i + 1] = 2.0f;
    three.data[3 * i + 2] = 3.0f;
  }
  const PinholeFrame frame = small_frame();

  const fs::path with_z = dir / "z.exr";
  write_float_exr(with_z, three, {"depth.Z", "Z", "other"});
  CHECK(read_depth(DepthSource{with_z, ""}, {}, frame).at(1, 1) == 2.0f);

  const fs::path with_depth_z = dir / "depth_z.exr";
  write_float_exr(with_depth_z, three, {"a", "b", "depth.Z"});
  CHECK(read_depth(DepthSource{with_depth_z, ""}, {}, frame).at(1, 1) == 3.0f);

  const fs::path neither = dir / "first.exr";
  write_float_exr(neither, three, {"first", "second", "third"});
  CHECK(read_depth(DepthSource{neither, ""}, {}, frame).at(1, 1) == 1.0f);

  CHECK(read_depth(DepthSource::parse(neither.string() + ":third"), {}, frame).at(1, 1) == 3.0f);
}

TEST_CASE("a missing depth channel is an error listing the file's channels", "[render][image_io][depth]") {
  TempDir dir;
  const fs::path exr = dir / "rgb.exr";
  write_float_exr(exr, Image(4, 3, 3, 1.0f), {"R", "G", "B"});
  CHECK_THROWS_AS(read_depth(DepthSource{exr, "Z"}, {}, small_frame()), ImageFileError);
  CHECK_THROWS_WITH(read_depth(DepthSource{exr, "Z"}, {}, small_frame()), Contains("no channel 'Z'") && Contains("R, G, B"));
}

TEST_CASE("distance depth becomes planar depth z = d / sqrt(1 + tx^2 + ty^2) at the corner pixel", "[render][image_io][depth]") {
  TempDir dir;
  const PinholeFrame frame = small_frame();
  const fs::path exr = write_channel(dir, "distance.exr", "Z", 4, 3, std::vector<float>(12, 10.0f));
  DepthReadOptions options;
  options.kind = DepthKind::Distance;
  const DepthMap depth = read_depth(DepthSource{exr, ""}, options, frame);
  // Top-left pixel centre (0.5, 0.5): tx = (0.5 - 2) / 2 = -0.75, ty = (1.5 - 0.5) / 2 = 0.5.
  const double expected = 10.0 / std::sqrt(1.0 + 0.75 * 0.75 + 0.5 * 0.5);
  CHECK_THAT(depth.at(0, 0), WithinRel(expected, kFloatDepth));
  // The centre row's middle pixels look 0.25 off axis in x only.
  CHECK_THAT(depth.at(2, 1), WithinRel(10.0 / std::sqrt(1.0 + 0.25 * 0.25), kFloatDepth));
}

TEST_CASE("inverse depth is 1 / z, and 0 means infinitely far", "[render][image_io][depth]") {
  TempDir dir;
  std::vector<float> values(12, 0.5f);
  values[5] = 0.0f;
  const fs::path exr = write_channel(dir, "inverse.exr", "Z", 4, 3, values);
  DepthReadOptions options;
  options.kind = DepthKind::Inverse;
  const DepthMap depth = read_depth(DepthSource{exr, ""}, options, small_frame());
  CHECK(depth.at(0, 0) == 2.0f);
  CHECK(depth.at(1, 1) == kInf);
}

TEST_CASE("depth in centimetres and millimetres is converted to metres", "[render][image_io][depth]") {
  TempDir dir;
  const fs::path exr = write_channel(dir, "units.exr", "Z", 4, 3, std::vector<float>(12, 250.0f));
  DepthReadOptions options;
  options.unit = DepthUnit::Cm;
  CHECK_THAT(read_depth(DepthSource{exr, ""}, options, small_frame()).at(0, 0), WithinRel(2.5, kFloatDepth));
  options.unit = DepthUnit::Mm;
  CHECK_THAT(read_depth(DepthSource{exr, ""}, options, small_frame()).at(0, 0), WithinRel(0.25, kFloatDepth));
  // Inverse depth in 1/mm: 0.004 / mm is z = 250 mm.
  const fs::path inverse = write_channel(dir, "inverse_mm.exr", "Z", 4, 3, std::vector<float>(12, 0.004f));
  options.kind = DepthKind::Inverse;
  CHECK_THAT(read_depth(DepthSource{inverse, ""}, options, small_frame()).at(0, 0), WithinRel(0.25, kFloatDepth));
}

TEST_CASE("NaN, negative or zero depth is an error naming the pixel, far and near override it", "[render][image_io][depth]") {
  TempDir dir;
  const PinholeFrame frame = small_frame();
  std::vector<float> values(12, 3.0f);
  values[1] = 1.5f;  // the nearest valid depth
  SECTION("NaN") {
    values[6] = kNaN;  // pixel (2, 1)
    const fs::path exr = write_channel(dir, "nan.exr", "Z", 4, 3, values);
    CHECK_THROWS_AS(read_depth(DepthSource{exr, ""}, {}, frame), ImageFileError);
    CHECK_THROWS_WITH(read_depth(DepthSource{exr, ""}, {}, frame),
                      Contains("nan.exr channel Z") && Contains("pixel (2, 1) = nan") && Contains("'far'") && Contains("'near'"));
    DepthReadOptions far;
    far.invalid = InvalidDepth::Far;
    CHECK(read_depth(DepthSource{exr, ""}, far, frame).at(2, 1) == kInf);
    DepthReadOptions near;
    near.invalid = InvalidDepth::Near;
    CHECK(read_depth(DepthSource{exr, ""}, near, frame).at(2, 1) == 1.5f);
  }
  SECTION("negative, and a count of the others") {
    values[4] = -2.0f;  // pixel (0, 1)
    values[11] = -1.0f;
    const fs::path exr = write_channel(dir, "negative.exr", "Z", 4, 3, values);
    CHECK_THROWS_WITH(read_depth(DepthSource{exr, ""}, {}, frame),
                      Contains("pixel (0, 1) = -2") && Contains("and 1 more invalid pixels") && Contains("must be > 0"));
  }
  SECTION("zero: a point at the pinhole") {
    values[3] = 0.0f;  // pixel (3, 0)
    const fs::path exr = write_channel(dir, "zero.exr", "Z", 4, 3, values);
    CHECK_THROWS_WITH(read_depth(DepthSource{exr, ""}, {}, frame), Contains("pixel (3, 0) = 0"));
  }
  SECTION("negative inverse depth") {
    values[2] = -0.5f;  // pixel (2, 0)
    const fs::path exr = write_channel(dir, "inverse.exr", "Z", 4, 3, values);
    DepthReadOptions options;
    options.kind = DepthKind::Inverse;
    CHECK_THROWS_WITH(read_depth(DepthSource{exr, ""}, options, frame),
                      Contains("pixel (2, 0) = -0.5") && Contains("inverse depth must be finite and >= 0"));
  }
  SECTION("near with no finite valid depth is still an error") {
    std::vector<float> bad(12, kInf);
    bad[0] = kNaN;
    const fs::path exr = write_channel(dir, "hopeless.exr", "Z", 4, 3, bad);
    DepthReadOptions near;
    near.invalid = InvalidDepth::Near;
    CHECK_THROWS_WITH(read_depth(DepthSource{exr, ""}, near, frame), Contains("the map has none"));
  }
}

TEST_CASE("a depth map of another size than the picture is refused, giving both sizes", "[render][image_io][depth]") {
  TempDir dir;
  const fs::path exr = write_channel(dir, "small.exr", "Z", 2, 3, std::vector<float>(6, 1.0f));
  CHECK_THROWS_AS(read_depth(DepthSource{exr, ""}, {}, small_frame()), ImageFileError);
  CHECK_THROWS_WITH(read_depth(DepthSource{exr, ""}, {}, small_frame()), Contains("2 x 3") && Contains("4 x 3"));
}

TEST_CASE("an 8-bit depth file is refused: normalised integers carry no metric depth", "[render][image_io][depth]") {
  TempDir dir;
  const fs::path png = dir / "depth.png";
  write_output_image(png, Image(4, 3, 3, 0.5f), {});
  CHECK_THROWS_AS(read_depth(DepthSource{png, ""}, {}, small_frame()), ImageFileError);
  CHECK_THROWS_WITH(read_depth(DepthSource{png, ""}, {}, small_frame()),
                    Contains("uint8") && Contains("store depth as float"));
}

// ---- output --------------------------------------------------------------------------------------

TEST_CASE("an unknown output extension is an error listing the supported ones", "[render][image_io]") {
  TempDir dir;
  CHECK_THROWS_AS(write_output_image(dir / "render.bmp", gradient_rgb(), {}), OptionsError);
  CHECK_THROWS_WITH(write_output_image(dir / "render.bmp", gradient_rgb(), {}),
                    Contains("'.bmp'") && Contains(".exr, .hdr, .png, .jpg, .jpeg, .tif, .tiff"));
  CHECK_THROWS_AS(write_output_image(dir / "render", gradient_rgb(), {}), OptionsError);
  CHECK(dir.names().empty());
}

TEST_CASE("an image with a NaN is refused before anything is written", "[render][image_io]") {
  TempDir dir;
  Image image = gradient_rgb();
  image.at(1, 2, 0) = kNaN;
  CHECK_THROWS_AS(write_output_image(dir / "render.exr", image, {}), ComputationError);
  CHECK_THROWS_WITH(write_output_image(dir / "render.exr", image, {}), Contains("pixel (1, 2)"));
  CHECK(dir.names().empty());
}

TEST_CASE("the output may not name one of the inputs", "[render][image_io]") {
  TempDir dir;
  const fs::path input = dir / "photo.exr";
  write_output_image(input, gradient_rgb(), {});
  const fs::path depth = dir / "depth.exr";
  // The same existing file under another spelling.
  const fs::path same = dir.path / "sub" / ".." / "photo.exr";
  fs::create_directories(dir.path / "sub");
  CHECK_THROWS_AS(ensure_not_an_input(same, {depth, input}), OptionsError);
  CHECK_THROWS_WITH(ensure_not_an_input(same, {depth, input}), Contains("photo.exr") && Contains("choose another output"));
  // Neither exists yet: compared as normalised paths.
  CHECK_THROWS_AS(ensure_not_an_input(dir.path / "." / "depth.exr", {depth}), OptionsError);
  CHECK_NOTHROW(ensure_not_an_input(dir / "render.exr", {input, depth}));
}

TEST_CASE("writing leaves only the finished file behind, also when it replaces one or fails", "[render][image_io]") {
  TempDir dir;
  const fs::path exr = dir / "render.exr";
  write_output_image(exr, gradient_rgb(), {});
  write_output_image(exr, Image(4, 3, 3, 7.0f), {});  // replaces the first
  write_output_image(dir / "render.png", gradient_rgb(), {});
  CHECK(dir.names() == std::vector<std::string>{"render.exr", "render.png"});
  CHECK(read_radiance_image(exr).at(0, 0, 0) == 7.0f);
  // A folder that does not exist: the writer fails and leaves nothing anywhere.
  CHECK_THROWS_AS(write_output_image(dir.path / "missing" / "render.exr", gradient_rgb(), {}), IoError);
  CHECK(dir.names() == std::vector<std::string>{"render.exr", "render.png"});
}
