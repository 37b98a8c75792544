// Image and depth input/output: the sRGB curve against IEC 61966-2-1:1999 (5.2, 5.3), exact float
// round trips through OpenEXR, depth conventions (planar z, Euclidean distance, inverse depth) against
// their defining formulas, and the errors a user sees for bad files. Inputs in the formats lensmith
// reads are made here with OpenEXR, libpng and libtiff directly, or byte by byte from the format's
// specification (PFM, Radiance RGBE), never with the code under test; JPEG inputs with libjpeg's
// compressor, which lensmith does not use (it writes JPEG with stb_image_write).
#include "lensmith/render/image_io.h"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfChromaticitiesAttribute.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfDeepFrameBuffer.h>
#include <OpenEXR/ImfDeepScanLineOutputFile.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfPartType.h>
#include <OpenEXR/ImfTiledOutputFile.h>
#include <png.h>
#include <tiffio.h>

#include <cstdio>
// jpeglib.h needs size_t and FILE declared before it.
#include <jpeglib.h>

#include <Imath/half.h>

#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <random>
#include <string>

#include "lensmith/core/errors.h"
#include "lensmith/core/text_file.h"
#include "lensmith/imageio/image_file.h"
#include "lensmith/render/deep_image.h"
#include "deep_exr_writer.h"

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
// A code value becomes the float code / 255 within an ulp (6e-8); near the threshold the highlight
// factor magnifies that by 1 / (1 - threshold) = 50 times the smoothstep slope.
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

// Channels of float or half samples for the OpenEXR writers below, one name per channel.
struct ExrChannels {
  std::vector<std::string> names;
  Imf::PixelType type = Imf::FLOAT;
};

// Writes `values` (interleaved, width x height x names.size()) to an OpenEXR file with the
// OpenEXR library itself; tiled with tile_px x tile_px tiles when tile_px > 0.
void write_exr_directly(const fs::path& path, int width, int height, const ExrChannels& channels, const std::vector<float>& values,
                        int tile_px = 0, Imf::Compression compression = Imf::ZIP_COMPRESSION) {
  Imf::Header header(width, height);
  header.compression() = compression;
  if (tile_px > 0) header.setTileDescription(Imf::TileDescription(static_cast<unsigned>(tile_px), static_cast<unsigned>(tile_px)));
  const std::size_t stride = channels.names.size();
  std::vector<Imath::half> halves(values.begin(), values.end());
  Imf::FrameBuffer frame;
  for (std::size_t c = 0; c < stride; ++c) {
    header.channels().insert(channels.names[c], Imf::Channel(channels.type));
    const bool half = channels.type == Imf::HALF;
    const std::size_t size = half ? sizeof(Imath::half) : sizeof(float);
    const void* base = half ? static_cast<const void*>(halves.data() + c) : static_cast<const void*>(values.data() + c);
    frame.insert(channels.names[c], Imf::Slice::Make(channels.type, base, header.dataWindow(), stride * size,
                                                     static_cast<std::size_t>(width) * stride * size));
  }
  if (tile_px > 0) {
    Imf::TiledOutputFile out(path.c_str(), header);
    out.setFrameBuffer(frame);
    out.writeTiles(0, out.numXTiles() - 1, 0, out.numYTiles() - 1);
  } else {
    Imf::OutputFile out(path.c_str(), header);
    out.setFrameBuffer(frame);
    out.writePixels(height);
  }
}

// A 4 x 3 x 3 ramp whose every sample differs: (x, y, c) -> x + 10 y + 100 c + 0.5.
std::vector<float> ramp_4x3x3() {
  std::vector<float> values;
  for (int y = 0; y < 3; ++y) {
    for (int x = 0; x < 4; ++x) {
      for (int c = 0; c < 3; ++c) values.push_back(static_cast<float>(x + 10 * y + 100 * c) + 0.5f);
    }
  }
  return values;
}

// Writes one row of `width` pixels with libpng's simplified writer (`format` a PNG_FORMAT_* value;
// 8-bit formats are marked sRGB, PNG_FORMAT_FLAG_LINEAR ones 16-bit with gAMA 1.0). False on failure.
bool write_png_directly(const fs::path& path, png_uint_32 width, png_uint_32 format, const void* samples) {
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  image.width = width;
  image.height = 1;
  image.format = format;
  return png_image_write_to_file(&image, path.c_str(), 0, samples, 0, nullptr) != 0;
}

std::string little_endian_u32(std::uint32_t bits) {
  std::string out;
  for (int shift = 0; shift < 32; shift += 8) out += static_cast<char>((bits >> shift) & 0xFFu);
  return out;
}

std::string little_endian_float(float v) { return little_endian_u32(std::bit_cast<std::uint32_t>(v)); }

std::string big_endian_float(float v) {
  std::string out = little_endian_float(v);
  std::reverse(out.begin(), out.end());
  return out;
}

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

TEST_CASE("a scanline EXR whose pixel blocks are damaged or cut short is an IoError naming the file, never a picture", "[render][image_io]") {
  // Flat scanline files are decoded chunk by chunk through OpenEXRCore (exr_codec.cpp,
  // read_exr_chunks); its error codes must come out as the C++ reader's did.
  TempDir dir;
  const fs::path exr = dir / "render.exr";
  Image original(64, 48, 3);
  for (std::size_t i = 0; i < original.data.size(); ++i) original.data[i] = 0.001f * static_cast<float>(i % 997);
  write_output_image(exr, original, {});
  std::ifstream in(exr, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const fs::path damaged = dir / "damaged.exr", cut = dir / "cut.exr";
  std::string flipped = bytes;
  for (std::size_t i = flipped.size() - 600; i < flipped.size() - 300; ++i) flipped[i] = static_cast<char>(flipped[i] ^ 0x5a);
  std::ofstream(damaged, std::ios::binary) << flipped;
  std::ofstream(cut, std::ios::binary) << bytes.substr(0, bytes.size() - 400);
  for (const fs::path& bad : {damaged, cut}) {
    INFO(bad.filename());
    CHECK_THROWS_AS(read_radiance_image(bad), IoError);
    CHECK_THROWS_WITH(read_radiance_image(bad), Contains(bad.string()) && Contains("cannot read the OpenEXR pixels"));
  }
  CHECK(read_radiance_image(exr).data == original.data);
}

TEST_CASE("ZIP and ZIPS EXRs that OpenEXR wrote read back as OpenEXR's own reader reads them, deflated blocks and stored ones", "[render][image_io]") {
  // Their blocks are inflated and unfiltered by lensmith's own routine (exr_codec.cpp,
  // decompress_zip_block), not OpenEXRCore's: checked against OpenEXR's C++ reader, an independent
  // decoder, on smooth samples (deflated) and noise (OpenEXR stores a block that does not shrink),
  // float and half, one scanline a block (ZIPS) and sixteen (ZIP), an odd width and a last ZIP block
  // of fewer lines.
  TempDir dir;
  constexpr int kWidth = 37, kHeight = 21;
  std::mt19937 random(12);
  std::uniform_real_distribution<float> noise(0.0f, 1000.0f);
  for (const Imf::Compression compression : {Imf::ZIP_COMPRESSION, Imf::ZIPS_COMPRESSION}) {
    for (const Imf::PixelType type : {Imf::FLOAT, Imf::HALF}) {
      for (const bool noisy : {false, true}) {
        std::vector<float> values;
        for (int y = 0; y < kHeight; ++y) {
          for (int x = 0; x < kWidth; ++x) {
            for (int c = 0; c < 4; ++c) values.push_back(noisy ? noise(random) : 0.25f * static_cast<float>(x + 3 * y + 50 * c));
          }
        }
        const fs::path exr = dir / "openexr.exr";
        write_exr_directly(exr, kWidth, kHeight, {{"R", "G", "B", "Z"}, type}, values, 0, compression);
        // OpenEXR's reader: the four channels as floats, interleaved.
        std::vector<float> expected(values.size());
        {
          Imf::InputFile in(exr.c_str());
          Imf::FrameBuffer frame;
          const char* names[] = {"R", "G", "B", "Z"};
          for (std::size_t c = 0; c < 4; ++c) {
            frame.insert(names[c], Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(expected.data() + c), 4 * sizeof(float),
                                              static_cast<std::size_t>(kWidth) * 4 * sizeof(float)));
          }
          in.setFrameBuffer(frame);
          in.readPixels(0, kHeight - 1);
        }
        INFO((compression == Imf::ZIP_COMPRESSION ? "zip" : "zips") << (type == Imf::HALF ? " half" : " float") << (noisy ? " noise" : " smooth"));
        const RasterInfo info = read_raster_info(exr);
        const Raster read = read_raster(exr, info, std::vector<int>{0, 1, 2, 3});
        REQUIRE(read.samples.size() == expected.size());
        CHECK(read.samples == expected);
        // The file holds what was written: exactly for float, rounded to the nearest half for half.
        if (type == Imf::FLOAT) CHECK(read.samples == values);
      }
    }
  }
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

TEST_CASE("EXR output deflates the blocks that deflate shrinks and stores noisy ones as they are and both read back exactly",
          "[render][image_io]") {
  // A render's float samples carry noise in their low bytes: deflating such a block saves a few per
  // cent for half of the writing time (lib/imageio/src/exr_codec.cpp, kZipWorthRatio). OpenEXR's
  // readers know a stored block by its size, whatever the file's compression.
  TempDir dir;
  constexpr int kWidth = 256, kHeight = 64;
  Image noisy(kWidth, kHeight, 3), smooth(kWidth, kHeight, 3);
  std::mt19937 random(7);
  std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) {
      for (int c = 0; c < 3; ++c) {
        noisy.at(x, y, c) = uniform(random);
        smooth.at(x, y, c) = 0.25f * static_cast<float>(c + 1);  // a flat colour
      }
    }
  }
  const std::uintmax_t raw_bytes = std::uintmax_t{kWidth} * kHeight * 3 * sizeof(float);
  for (const auto& [name, image] : {std::pair{"noisy.exr", noisy}, std::pair{"smooth.exr", smooth}}) {
    const fs::path exr = dir / name;
    write_output_image(exr, image, OutputMetadata{});
    CHECK(value_of(read_image_metadata(exr), "compression") == "zip");
    CHECK(read_radiance_image(exr).data == image.data);
    // OpenEXR's own C++ reader, which other tools use, gives the same samples.
    Imf::InputFile file(exr.c_str());
    std::vector<float> samples(static_cast<std::size_t>(kWidth) * kHeight * 3);
    Imf::FrameBuffer frame;
    for (int c = 0; c < 3; ++c) {
      frame.insert(std::string(1, "RGB"[c]), Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(samples.data() + c), 3 * sizeof(float),
                                                           static_cast<std::size_t>(kWidth) * 3 * sizeof(float)));
    }
    file.setFrameBuffer(frame);
    file.readPixels(0, kHeight - 1);
    CHECK(samples == image.data);
    const std::uintmax_t bytes = fs::file_size(exr);
    INFO(name << ": " << bytes << " bytes of " << raw_bytes << " raw");
    if (image.data == noisy.data) {
      CHECK(bytes > raw_bytes);  // stored: the pixels and the header
      CHECK(bytes < raw_bytes + raw_bytes / 50);
    } else {
      CHECK(bytes < raw_bytes / 20);  // deflated
    }
  }
}

TEST_CASE("EXR output writes chromaticities as OpenEXR's standard attribute, which reads back as its eight numbers", "[render][image_io]") {
  TempDir dir;
  const fs::path exr = dir / "acescg.exr";
  OutputMetadata meta;
  meta.chromaticities = "0.713, 0.293, 0.165, 0.83, 0.128, 0.044, 0.32168, 0.33767";  // ACES AP1 (S-2014-004)
  write_output_image(exr, gradient_rgb(), meta);
  // Read by OpenEXR itself: the typed attribute (a string of that name would hide it from readers).
  Imf::InputFile file(exr.c_str());
  const auto* c = file.header().findTypedAttribute<Imf::ChromaticitiesAttribute>("chromaticities");
  REQUIRE(c != nullptr);
  CHECK(c->value().green.y == 0.83f);
  CHECK(c->value().white.x == 0.32168f);
  CHECK(value_of(read_image_metadata(exr), "chromaticities") == meta.chromaticities);
  meta.chromaticities = "0.713, 0.293";
  CHECK_THROWS_AS(write_output_image(dir / "bad.exr", gradient_rgb(), meta), OptionsError);
  CHECK_FALSE(fs::exists(dir / "bad.exr"));
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

// A JPEG written by libjpeg's own compressor: `components` 8-bit samples a pixel in `space`
// (JCS_GRAYSCALE or JCS_CMYK; libjpeg marks CMYK with Adobe's APP14 segment), at quality 100.
void write_libjpeg(const fs::path& path, int width, int height, int components, J_COLOR_SPACE space,
                   const std::vector<unsigned char>& samples) {
  jpeg_compress_struct jpeg{};
  jpeg_error_mgr errors{};
  jpeg.err = jpeg_std_error(&errors);
  jpeg_create_compress(&jpeg);
  std::FILE* file = std::fopen(path.c_str(), "wb");
  REQUIRE(file != nullptr);
  jpeg_stdio_dest(&jpeg, file);
  jpeg.image_width = static_cast<JDIMENSION>(width);
  jpeg.image_height = static_cast<JDIMENSION>(height);
  jpeg.input_components = components;
  jpeg.in_color_space = space;
  jpeg_set_defaults(&jpeg);
  jpeg_set_quality(&jpeg, 100, TRUE);
  jpeg_start_compress(&jpeg, TRUE);
  while (jpeg.next_scanline < jpeg.image_height) {
    auto* row = const_cast<JSAMPROW>(samples.data() + static_cast<std::size_t>(jpeg.next_scanline) * width * components);
    jpeg_write_scanlines(&jpeg, &row, 1);
  }
  jpeg_finish_compress(&jpeg);
  jpeg_destroy_compress(&jpeg);
  std::fclose(file);
}

// Quality 100 on 8 x 8 blocks of one colour, or a gentle ramp, leaves a code value or two.
constexpr double kJpeg100 = 2.0 / 255.0;

TEST_CASE("a gray JPEG reads as one channel, a CMYK one as the RGB its inks leave", "[render][image_io]") {
  TempDir dir;
  SECTION("gray: one channel Y, the written ramp") {
    std::vector<unsigned char> ramp(32 * 16);
    for (std::size_t i = 0; i < ramp.size(); ++i) ramp[i] = static_cast<unsigned char>(4 * (i % 32) + 60);
    write_libjpeg(dir / "gray.jpg", 32, 16, 1, JCS_GRAYSCALE, ramp);
    const RasterInfo info = read_raster_info(dir / "gray.jpg");
    REQUIRE(info.channels.size() == 1);
    CHECK(info.channels[0].name == "Y");
    const Raster raster = read_raster(dir / "gray.jpg", info, std::vector<int>{0});
    for (std::size_t i = 0; i < ramp.size(); ++i) {
      INFO("sample " << i);
      CHECK_THAT(raster.samples[i], WithinAbs(ramp[i] / 255.0, kJpeg100));
    }
  }
  SECTION("CMYK, stored inverted as Adobe's are: light = (1 - ink) x (1 - black ink)") {
    // Four 8 x 8 patches, as inks (0 none, 255 full): cyan; half black; magenta + yellow; a mix.
    const unsigned char inks[4][4] = {{255, 0, 0, 0}, {0, 0, 0, 128}, {0, 255, 255, 0}, {64, 128, 192, 32}};
    std::vector<unsigned char> stored(32 * 8 * 4);
    for (int x = 0; x < 32; ++x) {
      for (int y = 0; y < 8; ++y) {
        for (int c = 0; c < 4; ++c) stored[static_cast<std::size_t>((y * 32 + x) * 4 + c)] = static_cast<unsigned char>(255 - inks[x / 8][c]);
      }
    }
    write_libjpeg(dir / "cmyk.jpg", 32, 8, 4, JCS_CMYK, stored);
    const RasterInfo info = read_raster_info(dir / "cmyk.jpg");
    REQUIRE(info.channels.size() == 3);
    const Raster raster = read_raster(dir / "cmyk.jpg", info, std::vector<int>{0, 1, 2});
    for (int patch = 0; patch < 4; ++patch) {
      for (int c = 0; c < 3; ++c) {
        const double light = (1.0 - inks[patch][c] / 255.0) * (1.0 - inks[patch][3] / 255.0);
        INFO("patch " << patch << ", channel " << c);
        CHECK_THAT(raster.samples[static_cast<std::size_t>((4 * 32 + 8 * patch + 4) * 3 + c)], WithinAbs(light, kJpeg100));
      }
    }
  }
}

TEST_CASE("a JPEG with a damaged Huffman table or cut short is an IoError naming the file, never a picture", "[render][image_io]") {
  TempDir dir;
  // Found by lensmith's fuzzer: a DHT segment declaring more than 256 codes, on which Debian 12's
  // stb_image (which decoded JPEG before libjpeg-turbo) wrote past its table.
  const unsigned char huffman[] = {0xff, 0xd8, 0xff, 0xff, 0xc4, 0xff, 0x0a, 0x00, 0x00, 0x00,
                                   0x00, 0x00, 0x00, 0xfb, 0xff, 0x8f, 0x2b, 0x20};
  const fs::path damaged = dir / "huffman.jpg";
  std::ofstream(damaged, std::ios::binary).write(reinterpret_cast<const char*>(huffman), sizeof huffman);
  CHECK_THROWS_AS(read_radiance_image(damaged), IoError);
  CHECK_THROWS_WITH(read_radiance_image(damaged), Contains(damaged.string()) && Contains("cannot read the JPEG image"));

  std::vector<unsigned char> ramp(64 * 64);
  for (std::size_t i = 0; i < ramp.size(); ++i) ramp[i] = static_cast<unsigned char>((i * 7) % 251);
  write_libjpeg(dir / "whole.jpg", 64, 64, 1, JCS_GRAYSCALE, ramp);
  const std::string bytes = read_file_bytes((dir / "whole.jpg").string());
  const fs::path cut = dir / "cut.jpg";
  std::ofstream(cut, std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  CHECK_NOTHROW(read_radiance_image(dir / "whole.jpg"));
  CHECK_THROWS_WITH(read_radiance_image(cut), Contains(cut.string()) && Contains("Premature end of JPEG file"));
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

TEST_CASE("the default depth channel is Z, then depth.Z, then a layer's Depth.Z, then a one-channel file's, FILE:CHANNEL overrides",
          "[render][image_io][depth]") {
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

  const fs::path layer = dir / "layer.exr";
  write_float_exr(layer, three, {"ViewLayer.Combined.R", "ViewLayer.Depth.Z", "ViewLayer.Normal.Z"});
  CHECK(read_depth(DepthSource{layer, ""}, {}, frame).at(1, 1) == 2.0f);

  // With several channels and none of depth, channel 0 would be a colour: an error listing them
  // (it once read a picture's red as metres).
  const fs::path neither = dir / "first.exr";
  write_float_exr(neither, three, {"first", "second", "third"});
  CHECK_THROWS_WITH(read_depth(DepthSource{neither, ""}, {}, frame), Contains("no depth channel") && Contains("first, second, third"));
  CHECK(read_depth(DepthSource::parse(neither.string() + ":third"), {}, frame).at(1, 1) == 3.0f);

  const fs::path single = dir / "single.exr";
  write_float_exr(single, Image(4, 3, 1, 5.0f), {"Y"});
  CHECK(read_depth(DepthSource{single, ""}, {}, frame).at(1, 1) == 5.0f);
}

TEST_CASE("a Blender multilayer EXR: the picture, alpha and depth from its layers, the other passes listed by name",
          "[render][image_io]") {
  // Blender 3.4's OPEN_EXR_MULTILAYER names channels layer.pass.channel and has no plain R, G, B.
  TempDir dir;
  const std::vector<std::string> names{"ViewLayer.Combined.R", "ViewLayer.Combined.G", "ViewLayer.Combined.B", "ViewLayer.Combined.A",
                                       "ViewLayer.Depth.Z",    "ViewLayer.DiffCol.R",  "ViewLayer.DiffCol.G",  "ViewLayer.DiffCol.B",
                                       "ViewLayer.Normal.X"};
  Image img(4, 3, static_cast<int>(names.size()));
  for (std::size_t i = 0; i < img.pixel_count(); ++i) {
    for (std::size_t c = 0; c < names.size(); ++c) img.data[i * names.size() + c] = 0.1f * static_cast<float>(c + 1);
  }
  const fs::path exr = dir / "multilayer.exr";
  write_float_exr(exr, img, names);
  const Image rgb = read_radiance_image(exr);
  CHECK(rgb.at(2, 1, 0) == Approx(0.1f));
  CHECK(rgb.at(2, 1, 1) == Approx(0.2f));
  CHECK(rgb.at(2, 1, 2) == Approx(0.3f));
  const auto alpha = read_alpha(exr);
  REQUIRE(alpha.has_value());
  CHECK(alpha->front() == Approx(0.4f));
  CHECK(read_depth(DepthSource{exr, ""}, {}, small_frame()).at(0, 0) == Approx(0.5f));
  OtherChannels other = read_other_channels(exr);
  std::sort(other.names.begin(), other.names.end());
  CHECK(other.names == std::vector<std::string>{"ViewLayer.DiffCol.B", "ViewLayer.DiffCol.G", "ViewLayer.DiffCol.R", "ViewLayer.Normal.X"});
}

TEST_CASE("within an ImageReadCache a file read for picture, alpha, passes and depth gives what separate reads give",
          "[render][image_io]") {
  TempDir dir;
  const std::vector<std::string> names{"R", "G", "B", "A", "Z", "N.X"};
  Image img(4, 3, static_cast<int>(names.size()));
  for (std::size_t i = 0; i < img.data.size(); ++i) img.data[i] = 0.25f + static_cast<float>(i);
  for (std::size_t p = 0; p < img.pixel_count(); ++p) img.data[p * names.size() + 3] = 0.05f * static_cast<float>(p);  // alpha in [0, 1]
  const fs::path exr = dir / "all.exr";
  write_float_exr(exr, img, names);
  const Image rgb = read_radiance_image(exr);
  const auto alpha = read_alpha(exr);
  const DepthMap depth = read_depth(DepthSource{exr, ""}, {}, small_frame());
  const OtherChannels other = read_other_channels(exr);
  ImageReadCache cache;
  CHECK(read_radiance_image(exr).data == rgb.data);
  CHECK(read_alpha(exr) == alpha);
  CHECK(read_depth(DepthSource{exr, ""}, {}, small_frame()).z_m == depth.z_m);
  CHECK(read_other_channels(exr).samples == other.samples);
}

TEST_CASE("an ImageReadCache decodes a file and reads its header anew once it has changed, and reads nothing stale after its scope",
          "[render][image_io]") {
  TempDir dir;
  const fs::path exr = dir / "changing.exr";
  Image first(4, 3, 3);
  std::fill(first.data.begin(), first.data.end(), 1.0f);
  write_float_exr(exr, first, {"R", "G", "B"});
  Image second(4, 3, 3);
  std::fill(second.data.begin(), second.data.end(), 2.0f);
  {
    ImageReadCache cache;
    CHECK(read_radiance_image(exr).at(1, 1, 0) == 1.0f);
    // Rewritten with other contents and another modification time: the stamp differs.
    write_float_exr(exr, second, {"R", "G", "B"});
    fs::last_write_time(exr, fs::last_write_time(exr) + std::chrono::seconds(2));
    CHECK(read_radiance_image(exr).at(1, 1, 0) == 2.0f);
    // Its header too: the cache serves read_raster_info, which the readers above ask first.
    write_float_exr(exr, Image(6, 2, 4, 3.0f), {"R", "G", "B", "A"});
    fs::last_write_time(exr, fs::last_write_time(exr) + std::chrono::seconds(4));
    const RasterInfo info = read_raster_info(exr);
    CHECK(info.width == 6);
    CHECK(info.channels.size() == 4);
    CHECK(read_radiance_image(exr).at(5, 1, 0) == 3.0f);
  }
  write_float_exr(exr, first, {"R", "G", "B"});
  CHECK(read_radiance_image(exr).at(1, 1, 0) == 1.0f);
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
                      Contains("nan.exr channel Z") && Contains("pixel (2, 1) = nan") && Contains("--invalid-depth far") && Contains("--invalid-depth near"));
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

// ---- formats read through lensmith::imageio -------------------------------------------------------

TEST_CASE("a tiled OpenEXR reads sample for sample like the scanline file, partial edge tiles included", "[render][image_io]") {
  TempDir dir;
  const std::vector<float> ramp = ramp_4x3x3();
  // 3 x 3 tiles over 4 x 3 pixels: the right column of tiles is one pixel wide.
  write_exr_directly(dir / "tiled.exr", 4, 3, {{"R", "G", "B"}}, ramp, 3);
  const Image read = read_radiance_image(dir / "tiled.exr");
  REQUIRE(read.width == 4);
  REQUIRE(read.height == 3);
  CHECK(read.data == ramp);
}

TEST_CASE("an OpenEXR whose tiles would take more than 256 MiB each is refused before OpenEXR decodes them", "[render][image_io]") {
  TempDir dir;
  // R, G, B and 77 more float channels (320 bytes a pixel) in 16 x 16 tiles, written by OpenEXR;
  // then the tile description (the "tiles" attribute's two 32-bit sides) says 1024 x 1024: 320 MiB.
  ExrChannels channels{{"R", "G", "B"}};
  for (int c = 0; c < 77; ++c) channels.names.push_back("extra" + std::to_string(c));
  write_exr_directly(dir / "tiles.exr", 16, 16, channels, std::vector<float>(16 * 16 * 80, 0.5f), 16);
  CHECK_NOTHROW(read_radiance_image(dir / "tiles.exr"));
  std::string bytes = read_file_bytes((dir / "tiles.exr").string());
  const std::string attribute("tiles\0tiledesc\0", 15);
  const std::size_t at = bytes.find(attribute);
  REQUIRE(at != std::string::npos);
  bytes.replace(at + attribute.size() + 4, 8, little_endian_u32(1024) + little_endian_u32(1024));
  std::ofstream(dir / "big-tiles.exr", std::ios::binary) << bytes;
  CHECK_THROWS_AS(read_radiance_image(dir / "big-tiles.exr"), ImageFileError);
  CHECK_THROWS_WITH(read_radiance_image(dir / "big-tiles.exr"), Contains("tiles of 1024 x 1024 pixels of 80 channels take 335544320 bytes"));
}

TEST_CASE("half-float OpenEXR channels read as the IEEE 754 binary16 values they hold", "[render][image_io]") {
  TempDir dir;
  // binary16 has a 10-bit fraction: 0.1 is stored as 1638 / 16384 = 0.0999755859375; 65504 is its largest finite value.
  std::vector<float> values(4 * 3 * 3, 0.5f);
  values[0] = 0.1f;
  values[1] = 65504.0f;
  write_exr_directly(dir / "half.exr", 4, 3, {{"R", "G", "B"}, Imf::HALF}, values);
  const Image read = read_radiance_image(dir / "half.exr");
  CHECK(read.at(0, 0, 0) == 0.0999755859375f);
  CHECK(read.at(0, 0, 1) == 65504.0f);
  CHECK(read.at(3, 2, 2) == 0.5f);
  // Half depth is float depth: read_depth takes it.
  write_exr_directly(dir / "half_z.exr", 4, 3, {{"Z"}, Imf::HALF}, std::vector<float>(12, 2.5f));
  CHECK(read_depth(DepthSource{dir / "half_z.exr", ""}, {}, small_frame()).at(3, 2) == 2.5f);
}

TEST_CASE("an OpenEXR cropped inside its display window is refused (overscan, the other way, is read)", "[render][image_io]") {
  TempDir dir;
  // Display window 4 x 3 at (0, 0); pixels stored for the 2 x 3 columns 1 and 2 only (a crop).
  const Imath::Box2i display(Imath::V2i(0, 0), Imath::V2i(3, 2));
  const Imath::Box2i data(Imath::V2i(1, 0), Imath::V2i(2, 2));
  Imf::Header header(display, data);
  header.channels().insert("Y", Imf::Channel(Imf::FLOAT));
  const std::vector<float> values(6, 1.0f);
  Imf::FrameBuffer frame;
  frame.insert("Y", Imf::Slice::Make(Imf::FLOAT, values.data(), data, sizeof(float), 2 * sizeof(float)));
  {
    Imf::OutputFile out((dir / "crop.exr").c_str(), header);
    out.setFrameBuffer(frame);
    out.writePixels(3);
  }
  CHECK_THROWS_AS(read_radiance_image(dir / "crop.exr"), ImageFileError);
  CHECK_THROWS_WITH(read_radiance_image(dir / "crop.exr"),
                    Contains("data window 2 x 3 at (1, 0) does not cover the display window 4 x 3 at (0, 0)") && Contains("cropped"));
  // The same pixels as overscan around a 1 x 1 frame: read whole, with both windows known.
  const Imath::Box2i frame_window(Imath::V2i(1, 1), Imath::V2i(1, 1));
  Imf::Header overscan(frame_window, data);
  overscan.channels().insert("Y", Imf::Channel(Imf::FLOAT));
  {
    Imf::OutputFile out((dir / "overscan.exr").c_str(), overscan);
    out.setFrameBuffer(frame);
    out.writePixels(3);
  }
  const lensmith::RasterInfo info = lensmith::read_raster_info(dir / "overscan.exr");
  CHECK(info.width == 2);
  CHECK(info.height == 3);
  CHECK(info.has_overscan());
  CHECK(info.display_window == lensmith::PixelBox{1, 1, 1, 1});
  CHECK(read_radiance_image(dir / "overscan.exr").data == std::vector<float>(18, 1.0f));
}

TEST_CASE("an OpenEXR whose header attribute claims more bytes than the file holds is an IoError naming it, before any allocation",
          "[render][image_io]") {
  // Found by tests/fuzz's exr_image target: OpenEXR 3.1 allocated the 1.98 GB this string attribute claims.
  const fs::path damaged = fs::path(LENSMITH_SOURCE_DIR) / "tests/fuzz/corpus/exr_image/damaged-string-size.exr";
  CHECK_THROWS_AS(read_radiance_image(damaged), IoError);
  CHECK_THROWS_WITH(read_radiance_image(damaged), Contains("header attribute 'p -o flat-zip.exrcapDate' claims 1979711507 bytes") &&
                                                      Contains("a damaged file"));
}

TEST_CASE("a deep OpenEXR is refused by the flat readers, which point to the bokeh command and to flattening it",
          "[render][image_io]") {
  TempDir dir;
  const fs::path deep = dir / "deep.exr";
  lensmith::testing::write_deep_exr(deep, 2, 1, {"Z"}, {{{1.0f}}, {{2.0f}}});
  CHECK_THROWS_AS(read_radiance_image(deep), ImageFileError);
  CHECK_THROWS_WITH(read_radiance_image(deep), Contains("deep.exr: a deep image; lensmith bokeh reads it as layered input") &&
                                                   Contains("oiiotool --flatten"));
  CHECK_THROWS_WITH(read_depth(DepthSource{deep, ""}, {}, PinholeFrame(2, 1, 2.0)), Contains("a deep image"));
  CHECK(is_deep_image(deep));
  CHECK_FALSE(is_deep_image(write_channel(dir, "flat.exr", "Z", 2, 1, std::vector<float>(2, 1.0f))));
}

namespace {
// 3 x 2 pixels of R, G, B, A, Z, ZBack: no sample, one surface, two surfaces stored back to front, a
// volume, a surface behind a volume, and one more surface.
const std::vector<std::string> kDeepChannels{"A", "B", "G", "R", "Z", "ZBack"};  // as OpenEXR sorts them
std::vector<std::vector<std::vector<float>>> deep_pixels() {
  return {{},
          {{1.0f, 0.3f, 0.2f, 0.1f, 2.0f, 2.0f}},
          {{1.0f, 0.0f, 0.0f, 0.9f, 5.0f, 5.0f}, {0.5f, 0.25f, 0.0f, 0.0f, 1.5f, 1.5f}},
          {{0.6f, 0.1f, 0.1f, 0.1f, 3.0f, 4.0f}},
          {{1.0f, 0.0f, 1.0f, 0.0f, 6.0f, 6.0f}, {0.2f, 0.0f, 0.0f, 0.2f, 1.0f, 2.0f}},
          {{1.0f, 2.0f, 2.0f, 2.0f, 8.0f, 8.0f}}};
}
}  // namespace

TEST_CASE("a deep scanline OpenEXR reads as each pixel's samples front to back, with premultiplied colour, alpha, Z and ZBack",
          "[render][image_io][deep]") {
  TempDir dir;
  const fs::path path = dir / "deep.exr";
  lensmith::testing::write_deep_exr(path, 3, 2, kDeepChannels, deep_pixels());
  const DeepImage deep = read_deep_image(path, {}, PinholeFrame(3, 2, 2.0));
  REQUIRE(deep.sample_count() == 7);
  CHECK(deep.pixel(0, 0).empty());
  REQUIRE(deep.pixel(2, 0).size() == 2);
  // Stored back to front, read front to back.
  CHECK(deep.pixel(2, 0)[0].z_m == 1.5f);
  CHECK(deep.pixel(2, 0)[0].alpha == 0.5f);
  CHECK(deep.pixel(2, 0)[0].rgb == std::array<float, 3>{0.0f, 0.0f, 0.25f});
  CHECK(deep.pixel(2, 0)[1].rgb == std::array<float, 3>{0.9f, 0.0f, 0.0f});
  CHECK(deep.pixel(0, 1)[0].is_volume());
  CHECK(deep.pixel(0, 1)[0].z_back_m == 4.0f);
  CHECK_FALSE(deep.pixel(1, 0)[0].is_volume());
  // Flattened front to back: the half-transparent blue sample over the opaque red one.
  const Image flat = deep.flatten();
  CHECK(flat.at(2, 0, 0) == Approx(0.45f));
  CHECK(flat.at(2, 0, 2) == Approx(0.25f));
  CHECK(flat.at(2, 0, 3) == Approx(1.0f));
  CHECK(flat.at(0, 0, 3) == 0.0f);
  CHECK(deep.max_transparency() == Approx(1.0));  // pixel (0, 0) has nothing
  CHECK(deep.front_depth().at(2, 1) == 8.0f);
}

TEST_CASE("a deep tiled OpenEXR reads sample for sample like the deep scanline file, partial edge tiles included",
          "[render][image_io][deep]") {
  TempDir dir;
  lensmith::testing::write_deep_exr(dir / "lines.exr", 3, 2, kDeepChannels, deep_pixels());
  lensmith::testing::write_deep_exr(dir / "tiles.exr", 3, 2, kDeepChannels, deep_pixels(), 2);
  const DeepImage a = read_deep_image(dir / "lines.exr", {}, PinholeFrame(3, 2, 2.0));
  const DeepImage b = read_deep_image(dir / "tiles.exr", {}, PinholeFrame(3, 2, 2.0));
  CHECK(a.first_sample == b.first_sample);
  REQUIRE(a.samples.size() == b.samples.size());
  for (std::size_t i = 0; i < a.samples.size(); ++i) {
    CHECK(a.samples[i].rgb == b.samples[i].rgb);
    CHECK(a.samples[i].z_m == b.samples[i].z_m);
    CHECK(a.samples[i].z_back_m == b.samples[i].z_back_m);
  }
}

TEST_CASE("deep OpenEXR files written by OpenImageIO (oiiotool --deepen, scanline and tiled) read back as the flat picture they came from",
          "[render][image_io][deep]") {
  // tests/fuzz/corpus/exr_image: flat-none.exr (oiiotool 2.4.7 --pattern fill, R G B A Z) and its
  // deep scanline and deep tiled (2 x 2) versions written by oiiotool --deepen.
  const fs::path corpus = fs::path(LENSMITH_SOURCE_DIR) / "tests/fuzz/corpus/exr_image";
  const RasterInfo info = read_raster_info(corpus / "flat-none.exr");
  const std::vector<int> rgbaz{info.channel_index("R"), info.channel_index("G"), info.channel_index("B"), info.channel_index("A"),
                               info.channel_index("Z")};
  const Raster flat = read_raster(corpus / "flat-none.exr", info, rgbaz);
  for (const char* name : {"deep-scanline.exr", "deep-tiled.exr"}) {
    INFO(name);
    REQUIRE(is_deep_image(corpus / name));
    const DeepImage deep = read_deep_image(corpus / name, {}, PinholeFrame(info.width, info.height, 10.0));
    const Image composite = deep.flatten();
    for (int y = 0; y < info.height; ++y) {
      for (int x = 0; x < info.width; ++x) {
        REQUIRE(deep.pixel(x, y).size() == 1);
        for (int c = 0; c < 4; ++c) CHECK(composite.at(x, y, c) == flat.at(x, y, c));
        CHECK(deep.pixel(x, y)[0].z_m == flat.at(x, y, 4));
      }
    }
  }
}

TEST_CASE("a deep OpenEXR cropped to its element (data window inside the display window) reads with empty pixels around it",
          "[render][image_io][deep]") {
  // Renderers crop deep elements to where they have samples; 2 x 1 pixels at (3, 2) of a 6 x 4 frame.
  TempDir dir;
  const fs::path path = dir / "cropped.exr";
  lensmith::testing::write_deep_exr(path, 2, 1, kDeepChannels, {{{1.0f, 0.3f, 0.2f, 0.1f, 2.0f, 2.0f}}, {}}, 0, 6, 4, 3, 2);
  const DeepImage deep = read_deep_image(path, {}, PinholeFrame(6, 4, 2.0));
  CHECK(deep.sample_count() == 1);
  REQUIRE(deep.pixel(3, 2).size() == 1);
  CHECK(deep.pixel(3, 2)[0].z_m == 2.0f);
  CHECK(deep.pixel(0, 0).empty());
  CHECK(deep.pixel(4, 2).empty());
  // Tiled the same way.
  lensmith::testing::write_deep_exr(dir / "cropped-tiles.exr", 2, 1, kDeepChannels, {{{1.0f, 0.3f, 0.2f, 0.1f, 2.0f, 2.0f}}, {}}, 2, 6, 4, 3, 2);
  CHECK(read_deep_image(dir / "cropped-tiles.exr", {}, PinholeFrame(6, 4, 2.0)).pixel(3, 2).size() == 1);
  // A data window reaching beyond the display window (overscan) is refused.
  lensmith::testing::write_deep_exr(dir / "overscan.exr", 2, 1, kDeepChannels, {{{1.0f, 0.3f, 0.2f, 0.1f, 2.0f, 2.0f}}, {}}, 0, 6, 4, 5, 2);
  CHECK_THROWS_WITH(read_deep_image(dir / "overscan.exr", {}, PinholeFrame(6, 4, 2.0)), Contains("differs from the display window"));
}

TEST_CASE("a deep sample with a bad depth, alpha or colour is refused naming the pixel and the sample", "[render][image_io][deep]") {
  TempDir dir;
  const std::vector<std::string> names{"A", "B", "G", "R", "Z", "ZBack"};
  auto one_bad = [&](std::vector<float> sample) {
    std::vector<std::vector<std::vector<float>>> pixels(4, {{1.0f, 0.1f, 0.1f, 0.1f, 2.0f, 2.0f}});
    pixels[3].push_back(std::move(sample));
    const fs::path path = dir / "bad.exr";
    lensmith::testing::write_deep_exr(path, 2, 2, names, pixels);
    return path;
  };
  const PinholeFrame frame(2, 2, 2.0);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  CHECK_THROWS_WITH(read_deep_image(one_bad({1.0f, 0.1f, 0.1f, 0.1f, -1.0f, -1.0f}), {}, frame),
                    Contains("pixel (1, 1) sample 1: Z = -1: depth must be > 0"));
  CHECK_THROWS_WITH(read_deep_image(one_bad({1.0f, 0.1f, 0.1f, 0.1f, nan, nan}), {}, frame), Contains("pixel (1, 1) sample 1: Z = nan"));
  CHECK_THROWS_WITH(read_deep_image(one_bad({1.0f, 0.1f, 0.1f, 0.1f, 3.0f, 2.5f}), {}, frame),
                    Contains("pixel (1, 1) sample 1: ZBack = 2.5 lies in front of Z = 3"));
  CHECK_THROWS_WITH(read_deep_image(one_bad({1.5f, 0.1f, 0.1f, 0.1f, 3.0f, 3.0f}), {}, frame),
                    Contains("pixel (1, 1) sample 1: A = 1.5: deep alpha must lie in [0, 1]"));
  CHECK_THROWS_WITH(read_deep_image(one_bad({1.0f, 0.1f, -0.5f, 0.1f, 3.0f, 3.0f}), {}, frame),
                    Contains("pixel (1, 1) sample 1: G = -0.5"));
  // --invalid-depth far: the sample goes infinitely far instead.
  DepthReadOptions far;
  far.invalid = InvalidDepth::Far;
  const DeepImage d = read_deep_image(one_bad({1.0f, 0.1f, 0.1f, 0.1f, -1.0f, -1.0f}), far, frame);
  CHECK(std::isinf(d.pixel(1, 1).back().z_m));
  // Without A every sample is opaque (`oiiotool --deepen` of a picture without alpha writes B, G, R, Z).
  lensmith::testing::write_deep_exr(dir / "no_alpha.exr", 1, 1, {"B", "G", "R", "Z"}, {{{0.1f, 0.2f, 0.3f, 1.0f}}});
  const DeepImage opaque = read_deep_image(dir / "no_alpha.exr", {}, PinholeFrame(1, 1, 2.0));
  REQUIRE(opaque.pixel(0, 0).size() == 1);
  CHECK(opaque.pixel(0, 0)[0].alpha == 1.0f);
  CHECK(opaque.pixel(0, 0)[0].rgb[0] == Approx(0.3f));
  // Without Z there is no depth.
  lensmith::testing::write_deep_exr(dir / "no_z.exr", 1, 1, {"A", "B", "G", "R"}, {{{1.0f, 0.1f, 0.1f, 0.1f}}});
  CHECK_THROWS_WITH(read_deep_image(dir / "no_z.exr", {}, PinholeFrame(1, 1, 2.0)),
                    Contains("a deep image without channel Z; lensmith reads deep R, G, B and Z"));
  CHECK_THROWS_WITH(read_deep_image(one_bad({1.0f, 0.1f, 0.1f, 0.1f, 3.0f, 3.0f}), {}, PinholeFrame(3, 2, 2.0)),
                    Contains("deep image of 2 x 2 pixels, but the camera is framed for 3 x 2"));
}

TEST_CASE("an OpenEXR depth stored as 32-bit unsigned integers is refused like any integer depth", "[render][image_io][depth]") {
  TempDir dir;
  Imf::Header header(4, 3);
  header.channels().insert("Z", Imf::Channel(Imf::UINT));
  const std::vector<std::uint32_t> ids(12, 7u);
  Imf::FrameBuffer frame;
  frame.insert("Z", Imf::Slice::Make(Imf::UINT, ids.data(), header.dataWindow(), sizeof(std::uint32_t), 4 * sizeof(std::uint32_t)));
  {
    Imf::OutputFile out((dir / "ids.exr").c_str(), header);
    out.setFrameBuffer(frame);
    out.writePixels(3);
  }
  CHECK_THROWS_WITH(read_depth(DepthSource{dir / "ids.exr", ""}, {}, small_frame()), Contains("uint32") && Contains("store depth as float"));
}

TEST_CASE("a 16-bit PNG keeps its 16 bits, and its gAMA of 1.0 makes it linear", "[render][image_io]") {
  TempDir dir;
  // libpng's simplified writer stores linear 16-bit data with gAMA 1.0 and no sRGB chunk.
  std::vector<png_uint_16> codes(2 * 1 * 3, 0);
  codes[0] = 32768;  // 16-bit precision: 8 bits would give 128 / 255 = 0.50196
  codes[4] = 65535;
  const fs::path path = dir / "linear16.png";
  REQUIRE(write_png_directly(path, 2, PNG_FORMAT_LINEAR_RGB, codes.data()));
  const Image read = read_radiance_image(path);
  CHECK_THAT(read.at(0, 0, 0), WithinAbs(32768.0 / 65535.0, kFloatRoundTrip));
  CHECK(read.at(1, 0, 1) == 1.0f);
  CHECK(read.at(0, 0, 1) == 0.0f);
}

TEST_CASE("an 8-bit gray PNG with an sRGB chunk is decoded and replicated to R = G = B", "[render][image_io]") {
  TempDir dir;
  // libpng's simplified writer marks 8-bit data as sRGB.
  const std::uint8_t codes[2] = {128, 255};
  const fs::path path = dir / "gray.png";
  REQUIRE(write_png_directly(path, 2, PNG_FORMAT_GRAY, codes));
  const Image read = read_radiance_image(path);
  for (int c = 0; c < 3; ++c) {
    CHECK_THAT(read.at(0, 0, c), WithinAbs(0.2158605, kFloatRoundTrip));  // ((128/255 + 0.055) / 1.055)^2.4
    CHECK_THAT(read.at(1, 0, c), WithinAbs(1.0, kFloatRoundTrip));
  }
}

// How write_tiff_directly lays out a 4 x 3 float TIFF.
struct FloatTiffLayout {
  int channels = 3;
  int bits = 32;       // 32 (float) or 16 (IEEE half)
  bool tiled = false;  // one 16 x 16 tile (the smallest TIFF allows), mostly outside the picture
};

// Writes 4 x 3 pixels of float samples (interleaved) with libtiff itself.
void write_tiff_directly(const fs::path& path, const FloatTiffLayout& layout, const std::vector<float>& values) {
  TIFF* t = TIFFOpen(path.c_str(), "w");
  REQUIRE(t != nullptr);
  TIFFSetField(t, TIFFTAG_IMAGEWIDTH, 4);
  TIFFSetField(t, TIFFTAG_IMAGELENGTH, 3);
  TIFFSetField(t, TIFFTAG_SAMPLESPERPIXEL, layout.channels);
  TIFFSetField(t, TIFFTAG_BITSPERSAMPLE, layout.bits);
  TIFFSetField(t, TIFFTAG_SAMPLEFORMAT, SAMPLEFORMAT_IEEEFP);
  TIFFSetField(t, TIFFTAG_PHOTOMETRIC, layout.channels == 3 ? PHOTOMETRIC_RGB : PHOTOMETRIC_MINISBLACK);
  TIFFSetField(t, TIFFTAG_PLANARCONFIG, PLANARCONFIG_CONTIG);
  TIFFSetField(t, TIFFTAG_COMPRESSION, COMPRESSION_ADOBE_DEFLATE);
  const auto row_samples = static_cast<std::size_t>(4 * layout.channels);
  const std::size_t sample_bytes = static_cast<std::size_t>(layout.bits) / 8;
  // The samples as the file stores them: floats, or the bits of IEEE halves.
  std::vector<unsigned char> bytes(values.size() * sample_bytes);
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (layout.bits == 32) {
      std::memcpy(bytes.data() + 4 * i, &values[i], 4);
    } else {
      const std::uint16_t bits = Imath::half(values[i]).bits();
      std::memcpy(bytes.data() + 2 * i, &bits, 2);
    }
  }
  if (layout.tiled) {
    TIFFSetField(t, TIFFTAG_TILEWIDTH, 16);
    TIFFSetField(t, TIFFTAG_TILELENGTH, 16);
    std::vector<unsigned char> tile(16 * 16 * static_cast<std::size_t>(layout.channels) * sample_bytes, 0);
    for (std::size_t y = 0; y < 3; ++y) {
      std::copy_n(bytes.begin() + static_cast<std::ptrdiff_t>(y * row_samples * sample_bytes), row_samples * sample_bytes,
                  tile.begin() + static_cast<std::ptrdiff_t>(y * 16 * static_cast<std::size_t>(layout.channels) * sample_bytes));
    }
    REQUIRE(TIFFWriteTile(t, tile.data(), 0, 0, 0, 0) > 0);
  } else {
    for (std::size_t y = 0; y < 3; ++y) {
      std::vector<unsigned char> row(bytes.begin() + static_cast<std::ptrdiff_t>(y * row_samples * sample_bytes),
                                     bytes.begin() + static_cast<std::ptrdiff_t>((y + 1) * row_samples * sample_bytes));
      REQUIRE(TIFFWriteScanline(t, row.data(), static_cast<std::uint32_t>(y), 0) == 1);
    }
  }
  TIFFClose(t);
}

TEST_CASE("a float TIFF reads its samples as stored, as a picture and as depth", "[render][image_io]") {
  TempDir dir;
  std::vector<float> ramp = ramp_4x3x3();
  ramp[5] = 1234.5f;  // radiance far above display white
  SECTION("32-bit, in strips") {
    write_tiff_directly(dir / "float.tif", {}, ramp);
    CHECK(read_radiance_image(dir / "float.tif").data == ramp);
  }
  SECTION("32-bit, in one tile larger than the picture") {
    write_tiff_directly(dir / "tiled.tif", {3, 32, true}, ramp);
    CHECK(read_radiance_image(dir / "tiled.tif").data == ramp);
  }
  SECTION("16-bit IEEE half: the plain ramp's values need at most 9 of a half's 11 significant bits") {
    write_tiff_directly(dir / "half.tif", {3, 16, false}, ramp_4x3x3());
    CHECK(read_radiance_image(dir / "half.tif").data == ramp_4x3x3());
  }
  SECTION("one channel as depth") {
    std::vector<float> depth(12, 4.0f);
    depth[6] = 0.75f;  // pixel (2, 1)
    write_tiff_directly(dir / "depth.tif", {1, 32, false}, depth);
    const DepthMap read = read_depth(DepthSource{dir / "depth.tif", ""}, {}, small_frame());
    CHECK(read.at(2, 1) == 0.75f);
    CHECK(read.at(0, 0) == 4.0f);
  }
}

// A little-endian TIFF of one directory, byte by byte (TIFF 6.0, section 2): header, the entries
// (tag, type 3 SHORT or 4 LONG, count 1, value), no next directory, then `padding` zero bytes.
std::string tiff_bytes(std::vector<std::array<std::uint32_t, 3>> entries, std::size_t padding) {
  std::sort(entries.begin(), entries.end());
  std::string bytes = std::string("II*\0", 4) + little_endian_u32(8);
  bytes += static_cast<char>(entries.size() & 0xFF);
  bytes += static_cast<char>(entries.size() >> 8);
  for (const auto& [tag, type, value] : entries) {
    bytes += static_cast<char>(tag & 0xFF);
    bytes += static_cast<char>(tag >> 8);
    bytes += static_cast<char>(type);
    bytes += '\0';
    bytes += little_endian_u32(1) + little_endian_u32(value);
  }
  return bytes + little_endian_u32(0) + std::string(padding, '\0');
}

TEST_CASE("a TIFF claiming tiles far larger than its picture, or thousands of samples a pixel, is refused before decoding", "[render][image_io]") {
  TempDir dir;
  // 16 x 16 pixels of 8-bit RGB, uncompressed; the pixel data (zeros) from byte 200 on.
  const std::vector<std::array<std::uint32_t, 3>> rgb16 = {{256, 4, 16}, {257, 4, 16}, {258, 3, 8}, {259, 3, 1}, {262, 3, 2}, {284, 3, 1}};
  SECTION("tiles of 825104 x 1024 pixels (found by the fuzzer: libtiff took 2.5 GB for one)") {
    auto entries = rgb16;
    entries.insert(entries.end(), {{277, 3, 3}, {322, 4, 825104}, {323, 4, 1024}, {324, 4, 200}, {325, 4, 100}});
    std::ofstream(dir / "tiles.tif", std::ios::binary) << tiff_bytes(entries, 300);
    CHECK_THROWS_AS(read_radiance_image(dir / "tiles.tif"), ImageFileError);
    CHECK_THROWS_WITH(read_radiance_image(dir / "tiles.tif"),
                      Contains((dir / "tiles.tif").string()) && Contains("tiles of 825104 x 1024 pixels for a picture of 16 x 16"));
  }
  SECTION("tiles of 4194304 x 1024 pixels on a picture as wide and one row tall") {
    std::vector<std::array<std::uint32_t, 3>> entries = {{256, 4, 4194304}, {257, 4, 1},   {258, 3, 8},   {259, 3, 1},
                                                         {262, 3, 2},       {284, 3, 1},   {277, 3, 3},   {322, 4, 4194304},
                                                         {323, 4, 1024},    {324, 4, 200}, {325, 4, 100}};
    std::ofstream(dir / "wide.tif", std::ios::binary) << tiff_bytes(entries, 300);
    CHECK_THROWS_WITH(read_radiance_image(dir / "wide.tif"), Contains("lensmith reads tiles of up to 256 MiB"));
  }
  SECTION("60000 samples a pixel") {
    auto entries = rgb16;
    entries.insert(entries.end(), {{277, 3, 60000}, {273, 4, 200}, {278, 4, 16}, {279, 4, 100}});
    std::ofstream(dir / "samples.tif", std::ios::binary) << tiff_bytes(entries, 300);
    CHECK_THROWS_WITH(read_radiance_image(dir / "samples.tif"), Contains("60000 samples per pixel"));
  }
  SECTION("while tiles of 512 x 512 on the same small picture, as some writers make, are read") {
    auto entries = rgb16;
    entries.insert(entries.end(), {{277, 3, 3}, {322, 4, 512}, {323, 4, 512}, {324, 4, 200}, {325, 4, 512 * 512 * 3}});
    std::ofstream(dir / "small.tif", std::ios::binary) << tiff_bytes(entries, 200 + 512 * 512 * 3);
    const Image read = read_radiance_image(dir / "small.tif");
    CHECK(read.width == 16);
    CHECK(read.at(15, 15, 2) == 0.0f);
  }
}

TEST_CASE("a PFM is read bottom row first, in the byte order the sign of its scale gives", "[render][image_io]") {
  TempDir dir;
  SECTION("PF (RGB), negative scale: little-endian") {
    // 2 x 2 pixels; the file's first row is the picture's bottom row.
    std::string bytes = "PF\n2 2\n-1.0\n";
    for (const float v : {1.f, 2.f, 3.f, 4.f, 5.f, 6.f}) bytes += little_endian_float(v);     // bottom row
    for (const float v : {7.f, 8.f, 9.f, 10.f, 11.f, 12.f}) bytes += little_endian_float(v);  // top row
    std::ofstream(dir / "rgb.pfm", std::ios::binary) << bytes;
    const Image read = read_radiance_image(dir / "rgb.pfm");
    CHECK(read.at(0, 0, 0) == 7.0f);
    CHECK(read.at(1, 0, 2) == 12.0f);
    CHECK(read.at(0, 1, 0) == 1.0f);
    CHECK(read.at(1, 1, 1) == 5.0f);
  }
  SECTION("Pf (gray), positive scale: big-endian, as depth") {
    std::string bytes = "Pf\n4 3\n1.0\n";
    for (int file_row = 0; file_row < 3; ++file_row) {
      for (int x = 0; x < 4; ++x) bytes += big_endian_float(static_cast<float>(1 + x + 4 * (2 - file_row)));
    }
    std::ofstream(dir / "depth.pfm", std::ios::binary) << bytes;
    const DepthMap depth = read_depth(DepthSource{dir / "depth.pfm", ""}, {}, small_frame());
    CHECK(depth.at(0, 0) == 1.0f);
    CHECK(depth.at(3, 2) == 12.0f);
  }
  SECTION("a truncated file is an IoError saying how many bytes are missing") {
    std::ofstream(dir / "short.pfm", std::ios::binary) << "PF\n2 2\n-1.0\n" << little_endian_float(1.0f);
    CHECK_THROWS_AS(read_radiance_image(dir / "short.pfm"), IoError);
    CHECK_THROWS_WITH(read_radiance_image(dir / "short.pfm"), Contains("short.pfm") && Contains("48 expected"));
  }
}

TEST_CASE("a Radiance RGBE pixel (128, 64, 32, exponent 129) reads as (1, 0.5, 0.25)", "[render][image_io]") {
  // Ward, "Real Pixels" (Graphics Gems II): value = mantissa / 256 * 2^(exponent - 128). A width
  // below 8 is stored flat, without run-length encoding.
  TempDir dir;
  std::string bytes = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1 +X 2\n";
  bytes += std::string{'\x80', '\x40', '\x20', '\x81'};
  bytes += std::string{'\x80', '\x80', '\x80', '\x80'};  // 0.5 grey
  std::ofstream(dir / "flat.hdr", std::ios::binary) << bytes;
  const Image read = read_radiance_image(dir / "flat.hdr");
  REQUIRE(read.width == 2);
  CHECK_THAT(read.at(0, 0, 0), WithinRel(1.0, kRgbeMantissa));
  CHECK_THAT(read.at(0, 0, 1), WithinRel(0.5, kRgbeMantissa));
  CHECK_THAT(read.at(0, 0, 2), WithinRel(0.25, kRgbeMantissa));
  CHECK_THAT(read.at(1, 0, 1), WithinRel(0.5, kRgbeMantissa));
}

TEST_CASE("TIFF, JPEG and HDR outputs record Software and the ImageDescription", "[render][image_io]") {
  TempDir dir;
  OutputMetadata meta;
  meta.lens = "triplet";
  meta.f_number = 4.0;
  meta.lensmith_version = "0.3.0";
  for (const std::string name : {"render.tif", "render.jpg", "render.hdr"}) {
    INFO(name);
    write_output_image(dir / name, gradient_rgb(), meta);
    const auto metadata = read_image_metadata(dir / name);
    CHECK(value_of(metadata, "Software") == "lensmith 0.3.0");
    CHECK_THAT(value_of(metadata, "ImageDescription"), Contains("lens triplet") && Contains("f/4"));
  }
  // Radiance headers keep free variables: the lensmith attributes too.
  CHECK(value_of(read_image_metadata(dir / "render.hdr"), "lensmith:f_number") == "4");
}

TEST_CASE("a file in no format lensmith reads is an IoError naming it and listing the formats read", "[render][image_io]") {
  TempDir dir;
  const fs::path gif = dir / "picture.gif";
  std::ofstream(gif, std::ios::binary) << "GIF89a" << std::string(32, '\0');
  CHECK_THROWS_AS(read_radiance_image(gif), IoError);
  CHECK_THROWS_WITH(read_radiance_image(gif), Contains("picture.gif") && Contains("OpenEXR") && Contains("TIFF") &&
                                                  Contains("PNG") && Contains("JPEG") && Contains("Radiance HDR") &&
                                                  Contains("PFM"));
  CHECK_THROWS_AS(read_image_metadata(gif), IoError);
}

TEST_CASE("a PNM header number too long for stb_image's int is refused before stb reads it", "[render][image_io]") {
  // Found by tests/fuzz's exr_image target: "P5" and 110 fives overflowed stb_image's header parser.
  const fs::path file = fs::path(LENSMITH_SOURCE_DIR) / "tests/fuzz/corpus/exr_image/pnm-header-overflow.pnm";
  CHECK_THROWS_WITH(read_radiance_image(file), Contains("not a picture lensmith can read"));
  // With whitespace after the magic it is a PNM header, refused by the number's length.
  TempDir dir;
  std::ofstream(dir / "long.pnm") << "P5 " << std::string(12, '5') << " 2\n255\n";
  CHECK_THROWS_WITH(read_radiance_image(dir / "long.pnm"), Contains("more than nine digits"));
}

TEST_CASE("an OpenEXR header attribute of negative size is an IoError, not an allocation of 2^64 bytes", "[render][image_io]") {
  // Found by tests/fuzz's exr_image target: OpenEXR reads the size as a signed int and allocated
  // what a negative one became for an attribute of a type it does not know.
  const fs::path damaged = fs::path(LENSMITH_SOURCE_DIR) / "tests/fuzz/corpus/exr_image/negative-attribute-size.exr";
  CHECK_THROWS_AS(read_radiance_image(damaged), IoError);
  CHECK_THROWS_WITH(read_radiance_image(damaged), Contains("'weird' has a negative size"));
}

TEST_CASE("an OpenEXR header naming an attribute twice is an IoError, not pixels sized by one copy and decoded by the other", "[render][image_io]") {
  // Found by CI's exr_image fuzz run on 0ac7166: a flat 5 x 4 picture with a second header after
  // the first, whose dataWindow is 4194309 x 4. OpenEXR's C++ reader keeps the last copy (5 x 4,
  // what the pixels were sized for); OpenEXRCore, which decodes the chunks, the first, and wrote
  // its 4-million-pixel rows past them (ASan: SEGV in exr_decoding_run).
  const fs::path damaged = fs::path(LENSMITH_SOURCE_DIR) / "tests/fuzz/corpus/exr_image/duplicate-data-window.exr";
  CHECK_THROWS_AS(read_radiance_image(damaged), IoError);
  CHECK_THROWS_WITH(read_radiance_image(damaged), Contains("duplicate-data-window.exr") && Contains("appears twice"));
  CHECK_THROWS_AS(read_image_metadata(damaged), IoError);
  // The sound file the fuzzer started from reads.
  const auto sound = read_radiance_image(fs::path(LENSMITH_SOURCE_DIR) / "tests/fuzz/corpus/exr_image/flat-none.exr");
  CHECK(sound.width == 5);
  CHECK(sound.height == 4);
}

TEST_CASE("an OpenEXR whose tiles are 2^29 pixels or more is an IoError, not an allocation OpenEXR's int arithmetic wrapped", "[render][image_io]") {
  // Found by tests/fuzz's exr_image target: a deep tiled header with a huge tile made OpenEXR 3.1
  // size its sample-count table as xSize * ySize * 4 in an int and allocate 2^64 - 2^31 bytes.
  const fs::path damaged = fs::path(LENSMITH_SOURCE_DIR) / "tests/fuzz/corpus/exr_image/deep-tiled-huge-tile.exr";
  CHECK_THROWS_AS(read_radiance_image(damaged), IoError);
  CHECK_THROWS_WITH(read_radiance_image(damaged), Contains("tile size"));
  CHECK_FALSE(is_deep_image(fs::path(LENSMITH_SOURCE_DIR) / "examples/bokeh-scene.exr"));  // a sound file still opens
}
