// The one home of a surface's shape (conic_profile.h, Surface::sag_mm, Surface::sag_and_slope,
// Surface::max_semi_diameter_mm) against forms derived independently of its rationalised sag: a sphere's
// R - sqrt(R^2 - r^2), a paraboloid's r^2 / 2R, the implicit conic c r^2 - 2 z + (1 + k) c z^2 = 0 (W. J.
// Smith, Modern Optical Engineering, 4th ed., sec. 18.4), slopes by central differences.
#include "lensmith/prescription/conic_profile.h"

#include <catch2/catch.hpp>
#include <algorithm>
#include <cmath>
#include <utility>

#include "lensmith/prescription/surface.h"

using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;
using namespace lensmith;

namespace {

// Sags of up to ~20 mm from a handful of roundings: a few ulps of 20.
constexpr double kSagRounding_mm = 1e-12;
// Central differences with step h = 1e-5 mm: truncation error h^2 z''' / 6 and rounding 1e-16 z / h;
// the slopes here are O(1), their third derivatives O(1e-2) / mm^2: 1e-9 leaves both far behind.
constexpr double kCentralDifferenceSlope = 1e-8;
constexpr double kStep_mm = 1e-5;

Surface standard(double radius_mm, double conic) {
  Surface s;
  s.curvature_per_mm = 1.0 / radius_mm;
  s.conic = conic;
  s.semi_diameter_mm = 10.0;
  return s;
}

}  // namespace

TEST_CASE("a sphere's sag is R - sqrt(R^2 - r^2), convex or concave", "[prescription][sag]") {
  for (double radius : {50.0, -37.5}) {
    const Surface s = standard(radius, 0.0);
    for (double r : {0.0, 1.0, 10.0, 30.0, 37.0}) {
      const double closed = radius - std::copysign(std::sqrt(radius * radius - r * r), radius);
      CHECK_THAT(s.sag_mm(r), WithinAbs(closed, kSagRounding_mm));
    }
  }
}

TEST_CASE("a paraboloid's sag is r^2 / 2R at every radius and it has no rim", "[prescription][sag]") {
  const Surface s = standard(80.0, -1.0);
  for (double r : {0.5, 40.0, 200.0, 5000.0}) CHECK_THAT(s.sag_mm(r), WithinRel(r * r / 160.0, 1e-14));
  CHECK(std::isinf(s.max_semi_diameter_mm()));
}

TEST_CASE("every conic's sag satisfies the implicit conic c r^2 - 2 z + (1 + k) c z^2 = 0", "[prescription][sag]") {
  for (double k : {-3.0, -0.6, 0.0, 0.8}) {
    const Surface s = standard(25.0, k);
    const double c = s.curvature_per_mm;
    for (double r : {0.3, 5.0, 12.0, 0.999 * std::min(40.0, s.max_semi_diameter_mm())}) {
      const double z = s.sag_mm(r);
      INFO("k = " << k << ", r = " << r << " mm, z = " << z << " mm");
      CHECK_THAT(c * r * r - 2.0 * z + (1.0 + k) * c * z * z, WithinAbs(0.0, kSagRounding_mm));
    }
  }
}

TEST_CASE("the largest radius is |R| for a sphere, R / sqrt(1 + k) for an ellipsoid, and the sag ends there",
          "[prescription][sag]") {
  CHECK_THAT(standard(-30.0, 0.0).max_semi_diameter_mm(), WithinRel(30.0, 1e-15));
  const Surface oblate = standard(30.0, 3.0);  // (1 + k) c^2 = 4 / 900
  CHECK_THAT(oblate.max_semi_diameter_mm(), WithinRel(15.0, 1e-15));
  CHECK(std::isfinite(oblate.sag_mm(15.0 - 1e-9)));
  CHECK(std::isnan(oblate.sag_mm(15.0 + 1e-9)));
  double z = 0.0, dz_dx = 0.0, dz_dy = 0.0;
  CHECK_FALSE(oblate.sag_and_slope(15.0 + 1e-9, 0.0, z, dz_dx, dz_dy));
  CHECK_FALSE(oblate.sag_and_slope(15.0, 0.0, z, dz_dx, dz_dy));  // the rim itself: infinite slope
  CHECK(std::isinf(standard(30.0, -2.0).max_semi_diameter_mm()));  // a hyperboloid
}

TEST_CASE("an asphere adds its polynomial to the conic: a4 r^4 + a6 r^6 on a sphere", "[prescription][sag]") {
  Surface s = standard(60.0, 0.0);
  s.even_asphere[1] = 2e-5;   // a4, mm^-3
  s.even_asphere[2] = -3e-8;  // a6, mm^-5
  for (double r : {1.0, 8.0, 15.0}) {
    const double sphere = 60.0 - std::sqrt(3600.0 - r * r);
    CHECK_THAT(s.sag_mm(r), WithinAbs(sphere + 2e-5 * std::pow(r, 4) - 3e-8 * std::pow(r, 6), kSagRounding_mm));
  }
}

TEST_CASE("the slopes of every kind of surface are the central differences of its sag", "[prescription][sag]") {
  Surface asphere = standard(45.0, -0.7);
  asphere.even_asphere[1] = 1e-5;
  Surface toroid = standard(45.0, 0.0);
  toroid.kind = SurfaceKind::Toroidal;
  toroid.curvature_x_per_mm = 1.0 / 70.0;
  toroid.even_asphere[1] = -4e-6;
  Surface biconic = standard(-45.0, 0.3);
  biconic.kind = SurfaceKind::Biconic;
  biconic.curvature_x_per_mm = 1.0 / 90.0;
  biconic.conic_x = -1.5;
  for (const Surface* s : {&asphere, &toroid, &biconic}) {
    for (auto [x, y] : {std::pair{3.0, 4.0}, std::pair{-7.0, 1.5}, std::pair{0.5, -9.0}}) {
      double z = 0.0, dz_dx = 0.0, dz_dy = 0.0;
      REQUIRE(s->sag_and_slope(x, y, z, dz_dx, dz_dy));
      double zp = 0.0, zm = 0.0, unused_x = 0.0, unused_y = 0.0;
      REQUIRE(s->sag_and_slope(x + kStep_mm, y, zp, unused_x, unused_y));
      REQUIRE(s->sag_and_slope(x - kStep_mm, y, zm, unused_x, unused_y));
      INFO(s->to_string() << " at (" << x << ", " << y << ") mm");
      CHECK_THAT(dz_dx, WithinAbs((zp - zm) / (2.0 * kStep_mm), kCentralDifferenceSlope));
      REQUIRE(s->sag_and_slope(x, y + kStep_mm, zp, unused_x, unused_y));
      REQUIRE(s->sag_and_slope(x, y - kStep_mm, zm, unused_x, unused_y));
      CHECK_THAT(dz_dy, WithinAbs((zp - zm) / (2.0 * kStep_mm), kCentralDifferenceSlope));
    }
  }
  // A Standard surface's sag from sag_and_slope is its rotational sag_mm.
  double z = 0.0, dz_dx = 0.0, dz_dy = 0.0;
  REQUIRE(asphere.sag_and_slope(3.0, 4.0, z, dz_dx, dz_dy));
  CHECK_THAT(z, WithinAbs(asphere.sag_mm(5.0), kSagRounding_mm));
}

TEST_CASE("conic_profile gives dz/du = dz/dr / 2r, and nothing beyond the rim", "[prescription][sag]") {
  const double a[2] = {0.0, 1e-5};
  double z = 0.0, dz_du = 0.0;
  REQUIRE(conic_profile(1.0 / 40.0, 1.0, a, 2, 100.0, z, dz_du));
  // Sphere plus a4 r^4 at r = 10: dz/dr = r / sqrt(R^2 - r^2) + 4 a4 r^3.
  const double dz_dr = 10.0 / std::sqrt(1600.0 - 100.0) + 4e-5 * 1000.0;
  CHECK_THAT(dz_du, WithinRel(dz_dr / 20.0, 1e-13));
  z = dz_du = -7.0;
  CHECK_FALSE(conic_profile(1.0 / 40.0, 1.0, a, 2, 1601.0, z, dz_du));
  CHECK(z == -7.0);  // nothing set
  CHECK(std::isnan(conic_sag(1.0 / 40.0, 1.0, a, 2, 1601.0)));
}
