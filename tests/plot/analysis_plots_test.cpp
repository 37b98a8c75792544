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

namespace {

// Every pair of labels drawn on `picture` is apart; a failure names both texts.
void check_labels_apart(const Canvas& picture) {
  const auto& boxes = picture.text_boxes();
  REQUIRE(boxes.size() > 3);  // a font was found and labels were drawn
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    for (std::size_t j = i + 1; j < boxes.size(); ++j) {
      INFO("\"" << boxes[i].text << "\" and \"" << boxes[j].text << "\"");
      CHECK_FALSE(boxes[i].box.intersects(boxes[j].box));
    }
  }
}

}  // namespace

TEST_CASE("spot diagram: no two labels overlap with five wavelengths, wide spots and lost rays", "[plot][spot][labels]") {
  AnalysisOptions options;
  options.relative_fields = {0.0, 0.5, 0.7, 1.0};
  options.wavelengths_nm = {450.0, 486.1327, 550.0, 587.5618, 656.2725};
  options.max_field_angle_deg = 20.0;  // the Angenieux f/1.1 vignettes and spreads its rays at this field
  const SpotDiagram spots = compute_spot_diagram(AnalysisContext(lensmith::testing::angenieux_double_gauss(), options));
  check_labels_apart(plot_spot_diagram(spots));
}

TEST_CASE("spot diagram: tick labels at the panels' edges and long loss notes stay apart", "[plot][spot][labels]") {
  // Spots 195 um wide: the panels run to +/-200 um with labels "-200" and "200" on their edges, where
  // neighbouring panels' labels meet; most rays lost, some missed, for the longest loss note.
  SpotDiagram spots;
  spots.lens_name = "synthetic";
  spots.wavelengths_nm = {450.0, 486.1327, 550.0, 587.5618, 656.2725};
  spots.reference_wavelength_nm = 587.5618;
  spots.field_unit = "deg";
  spots.working_f_number = 4.0;
  for (int f = 0; f < 2; ++f) {
    FieldSpot field;
    field.field_label = f == 0 ? "0.00 deg" : "20.00 deg";
    field.chief = {0.0, -12.345 * f, 100.0};
    SpotStatistics stats;
    stats.traced = 127;
    stats.passed = 2;
    stats.lost.vignetted = 100;
    stats.lost.missed = 25;
    stats.rms_radius_chief_mm = stats.geo_radius_chief_mm = 0.195;
    for (double nm : spots.wavelengths_nm) {
      Spot spot;
      spot.wavelength_nm = nm;
      spot.points = {{-0.195, field.chief.y_mm, 100.0}, {0.195, field.chief.y_mm, 100.0}};
      spot.stats = stats;
      field.spots.push_back(spot);
    }
    field.polychromatic = stats;
    spots.fields.push_back(field);
  }
  check_labels_apart(plot_spot_diagram(spots));
}

TEST_CASE("spot diagram: the Airy radius of an f/4 lens at 587.6 nm is 1.22 x 0.5876 um x 4 = 2.87 um", "[plot][spot]") {
  // Sasian triplet: EFL 50 mm, entrance pupil 12.5 mm (ray-optics' documentation), object at infinity.
  const SpotDiagram spots = compute_spot_diagram(AnalysisContext(lensmith::testing::sasian_triplet()));
  constexpr double kParaxialRounding = 1e-6;  // the prescription's 4-digit radii give f/4 to better than this
  CHECK_THAT(spots.working_f_number, Catch::Matchers::WithinRel(4.0, 1e-3));
  CHECK_THAT(spots.airy_radius_mm(587.5618), Catch::Matchers::WithinAbs(1.21967 * 587.5618e-6 * spots.working_f_number, kParaxialRounding));
  CHECK_THAT(spots.airy_radius_mm(587.5618), Catch::Matchers::WithinRel(2.866e-3, 2e-3));
}

TEST_CASE("pupil picture: no two stopping surfaces share a swatch, even past the twenty colours", "[plot][pupil]") {
  const Rgb pass{0.55f, 0.72f, 0.95f};  // the cells that reach the image (plot_pupil_shape)
  std::vector<Swatch> swatches;
  for (std::size_t rank = 0; rank < 60; ++rank) swatches.push_back(surface_swatch(rank));
  for (std::size_t i = 0; i < swatches.size(); ++i) {
    INFO("surface rank " << i);
    CHECK_FALSE(swatches[i].colour == pass);
    for (std::size_t j = i + 1; j < swatches.size(); ++j) CHECK_FALSE(swatches[i] == swatches[j]);
  }
  // Plain colours first: a lens with up to twenty stopping surfaces shows no hatching.
  for (std::size_t i = 0; i < 20; ++i) CHECK(swatches[i].hatch == 0);
  for (std::size_t i = 0; i < 20; ++i) {
    for (std::size_t j = i + 1; j < 20; ++j) CHECK_FALSE(swatches[i].colour == swatches[j].colour);
  }
}

TEST_CASE("pupil and Seidel pictures: no two labels overlap", "[plot][labels]") {
  AnalysisOptions options;
  options.relative_fields = {0.0, 0.5, 0.8, 1.0};
  options.max_field_angle_deg = 20.0;
  const AnalysisContext context(lensmith::testing::angenieux_double_gauss(), options);
  PupilShapeOptions pupil;
  pupil.grid = 24;
  check_labels_apart(plot_pupil_shape(compute_pupil_shape(context, pupil)));
  SeidelOptions seidel;
  seidel.field_angle_deg = 20.0;
  check_labels_apart(plot_seidel_diagram(SeidelAnalysis(lensmith::testing::angenieux_double_gauss(), seidel), "Angenieux"));
}
