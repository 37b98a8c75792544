// Bokeh through an anamorphic lens (issue 18): lentil's Schneider anamorphic (tests/data/lentil, entry 2004,
// US 6,310,731: cylinders curved in x in front of a spherical prime; EFL_y 60.55 mm, EFL_x 31.49 mm)
// photographed by the exact model. First-order optics says what comes out: the x section's shorter focal
// length takes in a wider field, which the sensor records squeezed by EFL_y / EFL_x; the output framing
// undoes it (the output grid is the input's, desqueezed), so points on the focus plane land on their own
// pixels in x as in y; the whole frame is photographed; and a defocused point is an oval whose axes are the
// two sections' blur discs (the x entrance pupil is narrower by the squeeze, and focuses elsewhere).
#include <catch2/catch.hpp>
#include <array>
#include <cmath>
#include <string>

#include "lensmith/camera/ray_model.h"
#include "lensmith/core/units.h"
#include "lensmith/paraxial/paraxial_system.h"
#include "lensmith/polyfit/lens_fit.h"
#include "ray_model_agreement.h"
#include "lensmith/prescription/lens_file.h"
#include "lensmith/render/image.h"

using namespace lensmith;
using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;

namespace {

Prescription schneider_anamorphic() {
  return read_lens_file(std::string(LENSMITH_TEST_DATA_DIR) + "/lentil/lenses.json#2004").prescription;
}

constexpr int kWidth = 320, kHeight = 180;

Camera camera_at(double focus_m, double f_number) {
  CameraOptions o;
  o.focus_distance_m = focus_m;
  o.f_number = f_number;
  o.framing.sensor_width_mm = 36.0;
  return Camera::from_lens(schneider_anamorphic(), o, kWidth, kHeight);
}

SensorHit chief(const RayModel& model, const ScenePoint& p) {
  static constexpr std::array<PupilPoint, 1> kCentre{{{0.0, 0.0}}};
  std::array<SensorHit, 1> hit;
  model.map(p, model.camera().reference_wavelength_nm(), kCentre, hit);
  return hit[0];
}

}  // namespace

TEST_CASE("An anamorphic lens's squeeze is the ratio of its sections' focal lengths", "[render][anamorphic]") {
  const Prescription lens = schneider_anamorphic();
  ParaxialOptions x;
  x.section = Section::X;
  const double efl_y = ParaxialSystem(lens).efl_mm(), efl_x = ParaxialSystem(lens, x).efl_mm();
  // Focused at infinity the squeeze is the focal lengths' ratio, to how far the x section's image lies
  // from the y section's (0.03 mm here: 0.1 % of the x magnification at the sensor).
  CHECK_THAT(camera_at(kInfinity, 4.0).squeeze(), WithinRel(efl_y / efl_x, 2e-3));
  // A round lens does not squeeze.
  CameraOptions o;
  o.focus_distance_m = 3.0;
  o.framing.sensor_width_mm = 36.0;
  const Prescription round = read_lens_file(std::string(LENSMITH_TEST_DATA_DIR) + "/lentil/lenses.json#0001").prescription;
  CHECK(Camera::from_lens(round, o, kWidth, kHeight).squeeze() == 1.0);
}

TEST_CASE("An anamorphic lens's output frames x by its x section: points on the focus plane near the axis land on their own "
          "pixels", "[render][anamorphic]") {
  const Camera camera = camera_at(30.0, 4.0);
  const auto model = make_ray_model(RayModelKind::Exact, camera, {});
  const double w = 1.0 / mm_from_m(30.0);
  // Near the axis distortion is negligible (third order: 1e-6 of the offset at these angles), so the
  // real chief ray meets the sensor where first order puts it. Framed with the y section alone, x would
  // land at 1 / 1.92 of its offset, 2.6 px short at tan 0.01.
  constexpr double kTolerancePx = 0.05;
  for (const auto& [tx, ty] : std::array<std::array<double, 2>, 4>{{{0.01, 0.0}, {-0.01, 0.0}, {0.0, 0.01}, {0.007, -0.007}}}) {
    const SensorHit hit = chief(*model, {tx, ty, w});
    REQUIRE(hit.ok);
    const PixelPoint at = camera.output_pixel(hit.x_mm, hit.y_mm);
    const PixelPoint input = camera.frame().pixel_at({tx, ty});
    CHECK_THAT(at.x, WithinAbs(input.x, kTolerancePx));
    CHECK_THAT(at.y, WithinAbs(input.y, kTolerancePx));
  }
}

TEST_CASE("Every part of an anamorphic lens's frame is photographed, to its corners", "[render][anamorphic]") {
  // The chief ray of a field point far off axis in x heads for the x section's entrance pupil, 99 mm in
  // front of the y section's: aimed at the y pupil's centre it missed the rear group beyond tan x = 0.2,
  // and the sides of the frame came out empty.
  const Camera camera = camera_at(30.0, 4.0);
  const auto model = make_ray_model(RayModelKind::Exact, camera, {});
  for (const double depth_m : {2.0, 30.0}) {
    for (const PixelPoint p : {PixelPoint{0.5, 0.5}, PixelPoint{kWidth - 0.5, 0.5}, PixelPoint{0.5, kHeight - 0.5},
                               PixelPoint{kWidth - 0.5, kHeight - 0.5}, PixelPoint{0.5, 0.5 * kHeight}, PixelPoint{kWidth - 0.5, 0.5 * kHeight}}) {
      const Tangents t = camera.frame().tangents_at(p);
      const SensorHit hit = chief(*model, {t.x, t.y, 1.0 / mm_from_m(depth_m)});
      INFO("pixel " << p.x << ", " << p.y << " at " << depth_m << " m");
      CHECK(hit.unclipped);
      // It lands near its own pixel: within the lens's distortion (3.8 % at the frame's side).
      const PixelPoint at = camera.output_pixel(hit.x_mm, hit.y_mm);
      CHECK(std::hypot(at.x - p.x, at.y - p.y) < 0.05 * kWidth);
    }
  }
}

TEST_CASE("A defocused point through an anamorphic lens is an oval of the two sections' blur discs", "[render][anamorphic]") {
  // Focused at 30 m, the sensor focuses the x section at x_section_focus_distance (6.8 m: its focal length
  // is shorter). A point at 1 m on the axis, f/8: the blur in each section is its entrance pupil's diameter
  // times the difference of inverse distances from that pupil (angles; the output is desqueezed, so both
  // axes have the frame's pixels per radian).
  const Camera camera = camera_at(30.0, 8.0);
  const auto model = make_ray_model(RayModelKind::Exact, camera, {});
  const double depth_mm = mm_from_m(1.0);
  const std::array<PupilPoint, 4> rim{{{1.0, 0.0}, {-1.0, 0.0}, {0.0, 1.0}, {0.0, -1.0}}};
  std::array<SensorHit, 4> hits;
  model->map({0.0, 0.0, 1.0 / depth_mm}, camera.reference_wavelength_nm(), rim, hits);
  for (const SensorHit& h : hits) REQUIRE(h.ok);
  const double width_px = std::abs(camera.output_pixel(hits[0].x_mm, 0).x - camera.output_pixel(hits[1].x_mm, 0).x);
  const double height_px = std::abs(camera.output_pixel(0, hits[2].y_mm).y - camera.output_pixel(0, hits[3].y_mm).y);

  const FirstOrderSample y = camera.first_order(camera.reference_wavelength_nm());
  const FirstOrderSample& x = *camera.x_section();
  const double x_pupil_behind = x.z_entrance_pupil_mm - camera.z_perspective_mm();  // mm
  const double focus_y = camera.focus_distance_mm(), focus_x = *camera.x_section_focus_distance_mm() + x_pupil_behind;
  const double f_px = camera.frame().focal_length_px();
  const double expected_height = 2.0 * y.entrance_pupil_radius_mm * std::abs(1.0 / depth_mm - 1.0 / focus_y) * f_px;
  const double expected_width = 2.0 * x.entrance_pupil_radius_mm * std::abs(1.0 / (depth_mm + x_pupil_behind) - 1.0 / focus_x) * f_px;
  INFO("oval " << width_px << " x " << height_px << " px, first order " << expected_width << " x " << expected_height);
  // 3 %: the real rim rays' aberrations, which first order leaves out (measured 1.7 % in x and 0.3 % in y
  // at f/8; at f/4 the x rim lies 9 % beyond first order: aberrations grow as the cube of the aperture).
  CHECK_THAT(height_px, WithinRel(expected_height, 0.03));
  CHECK_THAT(width_px, WithinRel(expected_width, 0.03));
  // The oval is tall: the x pupil is narrower by about the squeeze.
  CHECK(width_px < 0.8 * height_px);
}

TEST_CASE("The poly model photographs an anamorphic lens where the exact model does", "[render][anamorphic]") {
  // The fit in the component form (each output's x and y its own polynomial, the section mirrors'
  // parity rules), with fewer rays than the default to keep the test short. Its rays must land where the
  // exact tracer's do, to within 5 x the fit's own held-out sensor error (11 um RMS for this camera's
  // f/4 beam: 0.3 px of this frame; measured at most 0.07 px): chief and rim rays, in focus and defocused,
  // on the axis and off it in x and y, at the reference wavelength and near both ends of the spectrum.
  const Camera camera = camera_at(30.0, 4.0);
  LensFitOptions fit_options = lens_fit_options_for(camera);
  fit_options.training_rays = 12000;
  fit_options.test_rays = 2000;
  RayModelOptions poly_options;
  poly_options.fit = std::make_shared<const LensFit>(LensFit::fit(*camera.lens(), fit_options));
  REQUIRE(poly_options.fit->symmetry() == LensSymmetry::kSectionMirrors);
  const auto poly = make_ray_model(RayModelKind::Poly, camera, poly_options);
  const auto exact = make_ray_model(RayModelKind::Exact, camera, {});
  const double tolerance_px = 5.0 * 1e-3 * poly_options.fit->errors().sensor_position_rms_um *
                              std::abs(camera.px_per_sensor_mm()) * std::max(1.0, camera.squeeze());
  INFO("tolerance " << tolerance_px << " px; " << poly_options.fit->errors());
  const std::array<PupilPoint, 5> pupil{{{0.0, 0.0}, {0.9, 0.0}, {-0.9, 0.0}, {0.0, 0.9}, {0.0, -0.9}}};
  const std::array<double, 2> depths_m{30.0, 2.0};
  const std::array<std::array<double, 2>, 4> tangents{{{0.0, 0.0}, {0.25, 0.0}, {0.0, 0.12}, {-0.2, 0.1}}};
  const std::array<double, 3> wavelengths_nm{camera.reference_wavelength_nm(), 420.0, 680.0};
  const testing::RayModelAgreement agreement = testing::compare_ray_models(*poly, *exact, camera, depths_m, tangents, wavelengths_nm, pupil);
  INFO(agreement);
  CHECK(agreement.unlanded == 0);
  CHECK(agreement.verdicts_differ == 0);
  CHECK(agreement.worst_px < tolerance_px);
  CHECK(agreement.worst_px > 0.0);  // two independent models
  CHECK(poly->unaimed_rays() == 0);
}

TEST_CASE("Squeezing a picture's columns integrates each new pixel's share of the row", "[render][anamorphic]") {
  // Four pixels of one row into two, then into three (each new pixel 4/3 of an old one).
  const std::vector<float> row{1.0f, 3.0f, 5.0f, 7.0f};
  const std::vector<float> halved = squeeze_columns(row, 4, 1, 1, 2);
  CHECK(halved == std::vector<float>{2.0f, 6.0f});
  const std::vector<float> thirds = squeeze_columns(row, 4, 1, 1, 3);
  CHECK_THAT(thirds[0], WithinRel((1.0 + 3.0 / 3.0) / (4.0 / 3.0), 1e-6));                    // 1 and a third of 3
  CHECK_THAT(thirds[1], WithinRel((2.0 / 3.0 * 3.0 + 2.0 / 3.0 * 5.0) / (4.0 / 3.0), 1e-6));  // two thirds of 3 and of 5
  CHECK_THAT((thirds[0] + thirds[1] + thirds[2]) / 3.0, WithinRel(4.0, 1e-6));              // the row's mean kept
  // The nearest sample takes the pixel under each new pixel's centre (depths are not averaged).
  CHECK(squeeze_columns_nearest(row, 4, 1, 1, 3) == std::vector<float>{1.0f, 5.0f, 7.0f});
  // A squeeze below 1 stretches: each old pixel spread over the new ones it covers.
  CHECK(squeeze_columns(std::vector<float>{1.0f, 3.0f}, 2, 1, 1, 4) == std::vector<float>{1.0f, 1.0f, 3.0f, 3.0f});
  CHECK_THROWS_AS(squeeze_columns(row, 4, 1, 1, 0), OptionsError);
  CHECK_THROWS_AS(squeeze_columns(row, 3, 1, 1, 2), OptionsError);
}
