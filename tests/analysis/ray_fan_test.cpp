// Transverse ray fans (Welford, Aberrations of Optical Systems, sec. 4.8): lateral colour at the pupil's
// centre, symmetric on axis, and for a perfect focus seen out of focus exactly the straight-line rays
// through that focus.
#include "lensmith/analysis/ray_fan.h"

#include <catch2/catch.hpp>
#include <cmath>

#include "lensmith/core/errors.h"
#include "reference_lenses.h"

using Catch::Matchers::WithinAbs;
using namespace lensmith;
using lensmith::testing::make_surface;

namespace {

// Differences of two traced positions of order 10 mm: rounding is ~1e-13 mm.
constexpr double kTraceRounding = 1e-10;

}  // namespace

TEST_CASE("at the pupil's centre each wavelength's fan is its lateral colour: its own chief ray less the reference one", "[analysis][fan]") {
  // The fans are referenced to the reference wavelength's chief ray (OpticStudio's convention), so at py = 0
  // another wavelength's fan shows where its own chief ray lands relative to it: the lateral colour, traced here
  // separately with AnalysisContext::reference_ray. Off axis it is 0.2 to 0.5 um for this triplet at 20 degrees (a fan
  // referenced to each wavelength's own chief ray would read 0 there and fail); on axis it vanishes by symmetry.
  const AnalysisContext context(lensmith::testing::sasian_triplet());
  const RayFan fan = compute_ray_fan(context);
  REQUIRE(fan.fields.size() == 3);
  for (const FieldFan& f : fan.fields) {
    const FieldPoint field = context.field_at(f.relative_field);
    const double y_reference = context.reference_ray(field, fan.reference_wavelength_nm).image_ray.position_mm.y();
    for (const FanCurve& c : f.curves) {
      const std::size_t middle = c.tangential.size() / 2;
      INFO("field " << f.field_label << ", " << c.wavelength_nm << " nm");
      REQUIRE(c.tangential[middle].pupil == 0.0);
      REQUIRE(c.tangential[middle].ok());
      const double lateral_colour = context.reference_ray(field, c.wavelength_nm).image_ray.position_mm.y() - y_reference;
      CHECK_THAT(c.tangential[middle].error_mm, WithinAbs(lateral_colour, kTraceRounding));
      CHECK_THAT(c.sagittal[middle].error_mm, WithinAbs(0.0, kTraceRounding));  // fields lie along y
      if (f.relative_field > 0.0 && c.wavelength_nm != fan.reference_wavelength_nm) CHECK(std::abs(lateral_colour) > 1e-4);
      if (f.relative_field == 0.0) CHECK_THAT(lateral_colour, WithinAbs(0.0, kTraceRounding));
    }
  }
}

TEST_CASE("on axis the tangential and sagittal fans are one odd curve (rotational symmetry)", "[analysis][fan]") {
  AnalysisOptions options;
  options.relative_fields = {0.0};
  const RayFan fan = compute_ray_fan(AnalysisContext(lensmith::testing::smith_cooke_triplet(), options));
  for (const FanCurve& c : fan.fields.at(0).curves) {
    const std::size_t n = c.tangential.size();
    for (std::size_t i = 0; i < n; ++i) {
      INFO(c.wavelength_nm << " nm, pupil " << c.tangential[i].pupil);
      REQUIRE(c.tangential[i].ok() == c.sagittal[i].ok());
      if (!c.tangential[i].ok()) continue;
      CHECK_THAT(c.tangential[i].error_mm, WithinAbs(c.sagittal[i].error_mm, kTraceRounding));
      CHECK_THAT(c.tangential[i].error_mm, WithinAbs(-c.tangential[n - 1 - i].error_mm, kTraceRounding));
    }
  }
}

TEST_CASE("a perfect focus seen from a plane dz behind it: ey = dz tan(U) for every ray of the ellipsoid", "[analysis][fan]") {
  // Air to glass n = 1.5 through the ellipsoid k = -1/n^2: every ray of a parallel beam meets the far
  // focus z_F = n R / (n - 1) (Welford sec. 2.5). A ray at height h crosses the surface at its sag
  // z_s(h) and heads for (z_F, 0), so on the plane z_F + dz it lands at y = -dz h / (z_F - z_s(h)).
  const double n = 1.5, radius = 10.0, dz = 0.25, epd = 8.0;
  const double k = -1.0 / (n * n), c = 1.0 / radius, z_focus = n * radius / (n - 1.0);
  Prescription p;
  Surface s = make_surface(radius, z_focus + dz, MaterialSpec::model(n, std::nullopt));
  s.conic = k;
  s.is_stop = true;
  p.surfaces = {s};
  p.aperture = ApertureSpec{ApertureSpec::Kind::EntrancePupilDiameter, epd};
  p.wavelengths_nm = {587.5618};
  p.primary_wavelength_index = 0;
  AnalysisOptions options;
  options.relative_fields = {0.0};
  RayFanOptions fan_options;
  fan_options.samples = 11;
  const RayFan fan = compute_ray_fan(AnalysisContext(p, options), fan_options);
  for (const FanSample& sample : fan.fields.at(0).curves.at(0).tangential) {
    const double h = sample.pupil * 0.5 * epd;
    const double sag = c * h * h / (1.0 + std::sqrt(1.0 - (1.0 + k) * c * c * h * h));
    INFO("py = " << sample.pupil);
    REQUIRE(sample.ok());
    CHECK_THAT(sample.error_mm, WithinAbs(-dz * h / (z_focus - sag), kTraceRounding));
  }
}

TEST_CASE("ray fan options: an even sample count has no py = 0 and is refused", "[analysis][fan]") {
  RayFanOptions o;
  o.samples = 20;
  CHECK_THROWS_WITH(o.validate(), Catch::Contains("RayFanOptions::samples = 20") && Catch::Contains("odd"));
}
