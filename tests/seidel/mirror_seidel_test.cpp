// Seidel sums of mirrors, with the mirror unfolded as n' = -n (Welford, Aberrations of Optical Systems, 1986,
// ch. 8 and 15): a concave mirror of curvature c with the stop at it and the object at infinity has
// S_I = -A^2 h delta(u/n) + h^4 k c^3 (n' - n) = -2 h^4 c^3 (1 + k) for a marginal ray at height h, so a
// paraboloid (k = -1) has no spherical aberration. A system that is not rotationally symmetric has no Seidel
// sums: lensmith says so instead of computing them.
#include <catch2/catch.hpp>
#include <cmath>

#include "lensmith/core/errors.h"
#include "lensmith/glass/glass_catalog.h"
#include "lensmith/seidel/seidel_analysis.h"

using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;
using namespace lensmith;

namespace {

Prescription concave_mirror(double radius_mm, double conic, double epd_mm) {
  Prescription p;
  p.name = "concave mirror";
  Surface m;
  m.curvature_per_mm = 1.0 / radius_mm;
  m.conic = conic;
  m.mirror = true;
  m.is_stop = true;
  m.thickness_mm = radius_mm / 2.0;
  p.surfaces = {m};
  p.aperture = ApertureSpec{ApertureSpec::Kind::EntrancePupilDiameter, epd_mm};
  p.field = FieldSpec{FieldSpec::Kind::AngleDeg, {0.5}};
  p.resolve_materials(GlassCatalog::builtin());
  return p;
}

}  // namespace

TEST_CASE("A concave mirror's spherical aberration sum is -2 h^4 c^3 (1 + k): none for a paraboloid", "[seidel][mirror]") {
  const double radius = -400.0, h = 25.0;
  const double c = 1.0 / radius;
  for (double k : {0.0, -0.5, -1.0, -2.0}) {
    const SeidelAnalysis s(concave_mirror(radius, k, 2.0 * h));
    // The sums are of order h^4 c^3 = 6e-3 mm; double rounding over one surface is far below 1e-15 mm of that.
    CHECK_THAT(s.sums().S1, WithinAbs(-2.0 * std::pow(h, 4) * c * c * c * (1.0 + k), 1e-15));
  }
}

TEST_CASE("Seidel sums are refused for a toroidal surface, naming it", "[seidel][toroid]") {
  Prescription p = concave_mirror(-400.0, 0.0, 50.0);
  p.surfaces[0].kind = SurfaceKind::Toroidal;
  p.surfaces[0].curvature_x_per_mm = 1.0 / -300.0;
  CHECK_THROWS_WITH(SeidelAnalysis(p), Catch::Contains("not rotationally symmetric") && Catch::Contains("surface 1 is toroidal"));
}
