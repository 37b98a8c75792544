// Paraxial longitudinal chromatic focal shift: zero at the reference wavelength; for a thin lens
// the back focus is f(lambda) = 1 / ((n(lambda) - 1) (c1 - c2)), so f_C - f_F ~ f / V (W. J. Smith,
// Modern Optical Engineering, 4th ed., sec. 5.3, longitudinal chromatic aberration of a thin lens).
#include "lensmith/analysis/chromatic_focal_shift.h"

#include <catch2/catch.hpp>
#include <cmath>

#include "lensmith/core/errors.h"
#include "lensmith/core/units.h"
#include "reference_lenses.h"

using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;
using namespace lensmith;
using lensmith::testing::make_surface;

namespace {

// A zero-thickness biconvex singlet of a model crown (nd 1.5168, Vd 64.17), radii 100 and -100.
Prescription thin_singlet() {
  Prescription p;
  p.name = "thin singlet";
  p.surfaces = {make_surface(100.0, 0.0, MaterialSpec::model(1.5168, 64.17)), make_surface(-100.0, 100.0, MaterialSpec::air())};
  p.surfaces[0].is_stop = true;
  p.aperture = ApertureSpec{ApertureSpec::Kind::EntrancePupilDiameter, 10.0};
  return p;
}

}  // namespace

TEST_CASE("the focal shift is zero at the primary wavelength and every shift is relative to it", "[analysis][focal-shift]") {
  const ChromaticFocalShift c = compute_chromatic_focal_shift(lensmith::testing::sasian_triplet());
  INFO(c);
  CHECK(c.reference_wavelength_nm == kWavelengthD_nm);
  bool seen_reference = false;
  for (const FocalShiftPoint& p : c.points) {
    CHECK(p.shift_mm == p.image_distance_mm - c.reference_image_distance_mm);
    if (p.wavelength_nm == kWavelengthD_nm) {
      seen_reference = true;
      CHECK(p.shift_mm == 0.0);
    }
  }
  CHECK(seen_reference);
  CHECK(c.points.front().wavelength_nm == kWavelengthF_nm);
  CHECK(c.points.back().wavelength_nm == kWavelengthC_nm);
}

TEST_CASE("a thin singlet's focal shift is the thin-lens formula, and f_C - f_F is about f / V", "[analysis][focal-shift]") {
  const Prescription lens = thin_singlet();
  const ChromaticFocalShift c = compute_chromatic_focal_shift(lens);
  const Glass& glass = lens.surfaces[0].medium;
  const double curvature_sum = 1.0 / 100.0 + 1.0 / 100.0;
  auto focal_length = [&](double wavelength_nm) { return 1.0 / ((glass.index(wavelength_nm) - 1.0) * curvature_sum); };
  // Two vertex-to-focus distances computed by different routes (matrix product vs closed form).
  constexpr double kArithmetic = 1e-9;
  for (const FocalShiftPoint& p : c.points) {
    INFO(p.wavelength_nm << " nm");
    CHECK_THAT(p.shift_mm, WithinAbs(focal_length(p.wavelength_nm) - focal_length(kWavelengthD_nm), kArithmetic));
  }
  // f / V is first order in the dispersion: the exact difference differs by about (nF - nC)/(nd - 1) = 1/V.
  const double f = focal_length(kWavelengthD_nm);
  CHECK_THAT(c.points.back().shift_mm - c.points.front().shift_mm, WithinRel(f / 64.17, 1.0 / 64.17));
  CHECK(c.range_mm() > 0.0);
}

TEST_CASE("focal shift options: a single wavelength needs a range", "[analysis][focal-shift]") {
  FocalShiftOptions o;
  o.wavelengths_nm = {550.0};
  CHECK_THROWS_WITH(compute_chromatic_focal_shift(thin_singlet(), o), Catch::Contains("range"));
  o.min_nm = 450.0;
  o.max_nm = 650.0;
  const ChromaticFocalShift c = compute_chromatic_focal_shift(thin_singlet(), o);
  CHECK(c.reference_wavelength_nm == 550.0);
  CHECK(c.points.front().wavelength_nm == 450.0);
  o.min_nm = 700.0;
  CHECK_THROWS_AS(o.validate(), OptionsError);
}
