// Relative illumination by the projected solid angle of the image-space beam (Rimmer, Proc. SPIE 655,
// 99 (1986)) and the vignetting factor of a pupil grid.
#include "lensmith/analysis/relative_illumination.h"

#include <catch2/catch.hpp>
#include <cmath>

#include "lensmith/core/units.h"
#include "reference_lenses.h"

using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;
using namespace lensmith;
using lensmith::testing::make_surface;

TEST_CASE("a lens that does not vignette its axial beam has vignetting factor 1 on axis", "[analysis][illumination]") {
  AnalysisOptions options;
  options.aiming = RayAiming::RealStop;  // rays fill the real stop exactly, so only vignetting can cut them
  IlluminationOptions o;
  o.field_samples = 3;
  const RelativeIllumination ri = compute_relative_illumination(AnalysisContext(lensmith::testing::sasian_triplet(), options), o);
  INFO(ri);
  CHECK(ri.points.front().vignetting_factor == 1.0);
  CHECK(ri.points.front().rays_passed == ri.points.front().rays_in_pupil);
  CHECK(ri.points.front().relative_illumination == 1.0);  // the axis is this lens's brightest point
  CHECK(ri.points.back().relative_illumination < 1.0);
}

TEST_CASE("a sphere with a flat stop at its centre of curvature: relative illumination cos^2(theta)", "[analysis][illumination]") {
  // Every field sees the axial beam turned by theta (the chief ray is a radius), so the image-space
  // cone keeps its size except for two factors: the flat stop is seen foreshortened by cos(theta),
  // and the cone meets the flat image plane tilted by theta, which shrinks its projected solid
  // angle by cos(theta). The inverse-square part of the cos^4 law is absent: the focus stays at the
  // same distance from the stop.
  const double n = 1.5, radius = 20.0;
  const MaterialSpec glass = MaterialSpec::model(n, std::nullopt);
  Prescription p;
  p.surfaces = {make_surface(radius, radius, glass), make_surface(kInfinity, n * radius / (n - 1.0) - radius, glass, 0.4)};
  p.surfaces[1].is_stop = true;
  p.aperture = ApertureSpec{ApertureSpec::Kind::FloatByStop, 0.0};
  p.field = FieldSpec{FieldSpec::Kind::AngleDeg, {40.0}};
  p.wavelengths_nm = {587.5618};
  p.primary_wavelength_index = 0;
  AnalysisOptions options;
  options.aiming = RayAiming::RealStop;
  IlluminationOptions o;
  o.field_samples = 5;
  o.pupil_grid = 32;
  const RelativeIllumination ri = compute_relative_illumination(AnalysisContext(p, options), o);
  INFO(ri);
  // The cone's half angle is about 0.4 / 40 = 0.01 rad: its projected area departs from the
  // small-cone law by about that squared, 1e-4; the finite-difference Jacobians add ~1e-4 more.
  constexpr double kSmallCone = 1e-3;
  for (const IlluminationPoint& point : ri.points) {
    INFO("field " << point.field_value << " deg");
    const double c = std::cos(rad_from_deg(point.field_value));
    CHECK(point.vignetting_factor == 1.0);
    CHECK_THAT(point.relative_illumination, WithinRel(c * c, kSmallCone));
    CHECK_THAT(point.chief_ray_angle_deg, WithinAbs(point.field_value, 1e-9));
  }
}

TEST_CASE("illumination options name the field and the limit", "[analysis][illumination]") {
  IlluminationOptions o;
  o.pupil_grid = 4;
  CHECK_THROWS_WITH(o.validate(), Catch::Contains("pupil_grid = 4") && Catch::Contains("8 to 1024"));
}
