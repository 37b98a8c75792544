// Analysis pictures: sizes follow the layout, each wavelength shows in its colour, and every
// picture can be drawn and saved with and without a font.
#include "lensmith/plot/analysis_plots.h"

#include <catch2/catch.hpp>
#include <filesystem>
#include <unistd.h>

#include "reference_lenses.h"

using namespace lensmith;
using namespace lensmith::plot;

namespace {

// Pixels within `tolerance` of `colour` in every channel.
std::size_t count_colour(const Canvas& c, Rgb colour, float tolerance = 0.02f) {
  std::size_t n = 0;
  for (int y = 0; y < c.height(); ++y) {
    for (int x = 0; x < c.width(); ++x) {
      const Rgb p = c.pixel(x, y);
      if (std::abs(p.r - colour.r) <= tolerance && std::abs(p.g - colour.g) <= tolerance && std::abs(p.b - colour.b) <= tolerance) ++n;
    }
  }
  return n;
}

}  // namespace

TEST_CASE("wavelength colours: the shortest blue, the longest red, green between, whatever the order", "[plot]") {
  const auto colours = wavelength_colours({656.2725, 486.1327, 587.5618});
  CHECK(colours[1].b > colours[1].r);  // 486 nm
  CHECK(colours[0].r > colours[0].b);  // 656 nm
  CHECK(colours[2].g > colours[2].r);  // 587 nm
  CHECK(colours[2].g > colours[2].b);
  CHECK(wavelength_colours({550.0}).size() == 1);
}

TEST_CASE("the spot diagram picture has a panel per field and wavelength and dots in each wavelength's colour", "[plot][spot]") {
  const SpotDiagram spots = compute_spot_diagram(AnalysisContext(lensmith::testing::sasian_triplet()));
  PlotOptions o;
  const Canvas picture = plot_spot_diagram(spots, o);
  // 3 wavelengths + the overlay column, 3 field rows: wider than 4 panels of 230 px, taller than 3.
  CHECK(picture.width() > 4 * 230);
  CHECK(picture.height() > 3 * 230);
  const auto colours = wavelength_colours(spots.wavelengths_nm);
  for (std::size_t w = 0; w < colours.size(); ++w) {
    INFO("wavelength " << spots.wavelengths_nm[w]);
    // At least the centres of the dots of 127 x 3 fields (overlap makes it fewer than the rays).
    CHECK(count_colour(picture, colours[w]) > 100);
  }
}

TEST_CASE("every analysis picture draws and saves, with the default font and without any", "[plot][io]") {
  AnalysisOptions options;
  options.relative_fields = {0.0, 1.0};
  const Prescription lens = lensmith::testing::angenieux_double_gauss();
  const AnalysisContext context(lens, options);
  RayFanOptions fan_options;
  fan_options.samples = 11;
  DistortionOptions distortion_options;
  distortion_options.field_samples = 5;
  FieldCurveOptions curve_options;
  curve_options.field_samples = 5;
  IlluminationOptions illumination_options;
  illumination_options.field_samples = 3;
  illumination_options.pupil_grid = 16;
  PupilShapeOptions pupil_options;
  pupil_options.grid = 16;
  pupil_options.outline_points = 16;
  SpotOptions spot_options;
  spot_options.sampling.rings = 3;

  const auto dir = std::filesystem::temp_directory_path() / ("lensmith_plots_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  for (bool with_font : {true, false}) {
    PlotOptions o;
    if (!with_font) o.font_path.reset();
    INFO("font: " << (with_font ? "default" : "none"));
    const std::vector<std::pair<std::string, Canvas>> pictures = {
        {"spot", plot_spot_diagram(compute_spot_diagram(context, spot_options), o)},
        {"fan", plot_ray_fan(compute_ray_fan(context, fan_options), o)},
        {"distortion", plot_distortion(compute_distortion(context, distortion_options), o)},
        {"field-curves", plot_field_curves(compute_field_curves(context, curve_options), o)},
        {"focal-shift", plot_chromatic_focal_shift(compute_chromatic_focal_shift(lens), o)},
        {"illumination", plot_relative_illumination(compute_relative_illumination(context, illumination_options), o)},
        {"pupil", plot_pupil_shape(compute_pupil_shape(context, pupil_options), o)},
    };
    for (const auto& [name, canvas] : pictures) {
      INFO(name);
      const std::string path = (dir / (name + ".png")).string();
      canvas.write_png(path);
      const Canvas back = Canvas::read_image(path);
      CHECK(back.width() == canvas.width());
      CHECK(back.height() == canvas.height());
      CHECK(back.pixel(1, 1) == kWhite);  // white background, as designers expect
      CHECK(count_colour(back, kWhite) < static_cast<std::size_t>(back.width() * back.height()));  // something drawn
    }
  }
  std::filesystem::remove_all(dir);
}

TEST_CASE("plot options check the text size", "[plot]") {
  PlotOptions o;
  o.font_px = 2.0;
  CHECK_THROWS_WITH(o.validate(), Catch::Contains("font_px"));
}
