// The plot canvas: coverage-based anti-aliasing conserves area, text lands where it is measured and
// has the font's own widths, and PNG files round-trip and are written through a temporary file.
#include "lensmith/plot/canvas.h"

#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <unistd.h>

#include "lensmith/core/errors.h"
#include "lensmith/core/units.h"
#include "lensmith/plot/plot_axes.h"

using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;
using namespace lensmith;
using namespace lensmith::plot;

namespace {

// Darkness summed over the canvas: for black on white, the area painted in pixels.
double ink(const Canvas& c) {
  double sum = 0.0;
  for (int y = 0; y < c.height(); ++y) {
    for (int x = 0; x < c.width(); ++x) sum += 1.0 - c.pixel(x, y).g;
  }
  return sum;
}

std::filesystem::path scratch_folder() {
  const auto dir = std::filesystem::temp_directory_path() / ("lensmith_plot_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  return dir;
}

}  // namespace

TEST_CASE("a filled disc paints its area: the coverage ramp is one pixel wide and centred on the edge", "[plot][canvas]") {
  Canvas c(100, 100);
  c.fill_disc({50.3, 49.7}, 20.0, kBlack);
  // A linear ramp across the edge integrates to the exact area up to its curvature: ~1e-3 relative at r = 20.
  CHECK_THAT(ink(c), WithinRel(kPi * 20.0 * 20.0, 2e-3));
  CHECK(c.pixel(50, 50) == kBlack);
  CHECK(c.pixel(5, 5) == kWhite);
}

TEST_CASE("a thick line covers width x length, and a polyline does not darken its own joints", "[plot][canvas]") {
  Canvas c(200, 60);
  c.line({20.0, 30.0}, {180.0, 30.0}, LineStyle{kBlack, 3.0});
  // Round caps add pi (w/2)^2 to the rectangle w x L.
  CHECK_THAT(ink(c), WithinRel(3.0 * 160.0 + kPi * 1.5 * 1.5, 0.02));
  Canvas joined(200, 60), single(200, 60);
  const Point2 points[3] = {{20.0, 30.0}, {100.0, 30.0}, {180.0, 30.0}};
  joined.polyline(points, LineStyle{kBlack, 3.0});
  single.line({20.0, 30.0}, {180.0, 30.0}, LineStyle{kBlack, 3.0});
  CHECK_THAT(ink(joined), WithinRel(ink(single), 1e-6));
}

TEST_CASE("a dashed line paints about dash / (dash + gap) of a solid one", "[plot][canvas]") {
  Canvas solid(400, 20), dashed(400, 20);
  solid.line({0.0, 10.0}, {400.0, 10.0}, LineStyle{kBlack, 2.0});
  dashed.line({0.0, 10.0}, {400.0, 10.0}, LineStyle{kBlack, 2.0, 8.0, 8.0});
  // Each dash gains round caps (pi r^2 = 3.1 px on 16 px of pattern): 0.5 + 0.1.
  CHECK_THAT(ink(dashed) / ink(solid), WithinAbs(0.6, 0.05));
}

TEST_CASE("text draws inside its measured width, and draws nothing without a font", "[plot][canvas][text]") {
  const auto font = Canvas::find_default_font();
  if (!font) {
    WARN("DejaVuSans.ttf not found: the text checks are skipped (install fonts-dejavu-core)");
    return;
  }
  Canvas c(300, 60);
  c.set_font(font);
  const double w = c.text_width("RMS 12.3 \xC2\xB5m", 20.0);
  CHECK(w > 80.0);
  CHECK(w < 200.0);
  c.text({10.0, 40.0}, "RMS 12.3 \xC2\xB5m", 20.0, kBlack);
  CHECK(ink(c) > 50.0);
  double right_of_text = 0.0;
  for (int y = 0; y < 60; ++y) {
    for (int x = static_cast<int>(10.0 + w) + 3; x < 300; ++x) right_of_text += 1.0 - c.pixel(x, y).g;
  }
  CHECK(right_of_text == 0.0);
  Canvas no_font(300, 60);
  no_font.set_font(std::nullopt);
  no_font.text({10.0, 40.0}, "hidden", 20.0, kBlack);
  CHECK(ink(no_font) == 0.0);
  CHECK(no_font.text_width("hidden", 20.0) == 0.0);
}

TEST_CASE("text is as wide as the font's advances: 4 digits of DejaVu Sans are 4 x 1303 / 2048 em", "[plot][canvas][text]") {
  const auto font = Canvas::find_default_font();
  if (!font) {
    WARN("DejaVuSans.ttf not found: the text checks are skipped (install fonts-dejavu-core)");
    return;
  }
  // DejaVu Sans 2.37: unitsPerEm 2048 (head), every digit advances 1303 units (hmtx, glyph 19 for '0'),
  // and digits are not kerned. A size is the em height in pixels.
  constexpr double kDigitAdvanceEm = 1303.0 / 2048.0;
  constexpr double kFloatScale = 1e-6;  // the font scale is a float
  Canvas c(10, 10);
  c.set_font(font);
  CHECK_THAT(c.text_width("0000", 20.0), WithinRel(4.0 * kDigitAdvanceEm * 20.0, kFloatScale));
  CHECK_THAT(c.text_width("0000", 2048.0), WithinRel(4.0 * 1303.0, kFloatScale));
}

TEST_CASE("a font file that cannot be read or is not a font is an IoError naming it", "[plot][canvas][text]") {
  const auto dir = scratch_folder();
  Canvas c(10, 10);
  CHECK_THROWS_AS(c.set_font((dir / "no-such-font.ttf").string()), IoError);
  const auto junk = dir / "junk.ttf";
  std::ofstream(junk) << "not a font";
  CHECK_THROWS_AS(c.set_font(junk.string()), IoError);
  CHECK_THROWS_WITH(c.set_font(junk.string()), Catch::Contains("junk.ttf") && Catch::Contains("not a TrueType"));
  std::filesystem::remove_all(dir);
}

TEST_CASE("write_png writes a PNG that reads back with its size and colours, and leaves no temporary file", "[plot][canvas][io]") {
  const auto dir = scratch_folder();
  const std::string path = (dir / "picture.png").string();
  Canvas c(64, 32);
  c.fill_rect({0.0, 0.0}, {32.0, 32.0}, Rgb{1.0f, 0.0f, 0.0f});
  c.write_png(path);
  const Canvas back = Canvas::read_image(path);
  CHECK(back.width() == 64);
  CHECK(back.height() == 32);
  CHECK(back.pixel(5, 5) == Rgb{1.0f, 0.0f, 0.0f});
  CHECK(back.pixel(50, 5) == kWhite);
  std::size_t files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    INFO(entry.path());
    ++files;
  }
  CHECK(files == 1);
  CHECK_THROWS_AS(c.write_png((dir / "no-such-folder" / "x.png").string()), IoError);
  CHECK_THROWS_AS(Canvas::read_image((dir / "missing.png").string()), IoError);
  std::filesystem::remove_all(dir);
}

TEST_CASE("nice ticks step by 1, 2 or 5 times a power of ten and their labels show the step's digits", "[plot][axes]") {
  CHECK(nice_ticks(0.0, 47.0, 5) == std::vector<double>{0.0, 10.0, 20.0, 30.0, 40.0});
  const auto ticks = nice_ticks(-0.013, 0.028, 4);
  REQUIRE(ticks.size() >= 3);
  CHECK_THAT(ticks[1] - ticks[0], WithinRel(0.01, 1e-9));
  CHECK(tick_label(0.25, 0.25) == "0.25");
  CHECK(tick_label(-10.0, 5.0) == "-10");
  CHECK(tick_label(0.5, 0.1) == "0.5");
  const AxisRange r = nice_range(-0.013, 0.028, 4);
  CHECK(r.min <= -0.013);
  CHECK(r.max >= 0.028);
  const AxisRange flat = nice_range(2.0, 2.0);
  CHECK(flat.min < 2.0);
  CHECK(flat.max > 2.0);
}

TEST_CASE("canvas sizes are checked", "[plot][canvas]") {
  CHECK_THROWS_WITH(Canvas(0, 10), Catch::Contains("1 to 16384"));
}
