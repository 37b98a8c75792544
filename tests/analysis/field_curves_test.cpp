// Tangential and sagittal field curves from real-ray pairs around the chief ray: on axis both foci are
// the paraxial focus; for a refracting sphere with the stop at its centre of curvature every field
// is the axial one rotated, so T = S and the focal surface is a sphere about that centre (no
// astigmatism at a concentric surface: Welford, Aberrations of Optical Systems, sec. 7.3; Kingslake,
// Lens Design Fundamentals, ch. 9 on concentric systems).
#include "lensmith/analysis/field_curves.h"

#include <catch2/catch.hpp>
#include <cmath>

#include "lensmith/core/units.h"
#include "lensmith/paraxial/paraxial_system.h"
#include "reference_lenses.h"

using Catch::Matchers::WithinAbs;
using namespace lensmith;
using lensmith::testing::make_surface;

namespace {

// The ray pair spans +/-1e-3 of the pupil: spherical aberration of that pencil moves its focus by
// about (1e-3)^2 times the full-aperture longitudinal aberration (< 1 mm here): < 1e-6 mm.
constexpr double kPencilAberrationMm = 1e-6;

}  // namespace

TEST_CASE("on axis the tangential and sagittal foci are the paraxial focus (Sasian triplet)", "[analysis][field-curves]") {
  const Prescription lens = lensmith::testing::sasian_triplet();
  const FieldCurves fc = compute_field_curves(AnalysisContext(lens));
  const double expected = ParaxialSystem(lens).z_image_mm() - fc.image_plane_z_mm;
  INFO(fc);
  for (const FieldCurveSet& set : fc.curves) {
    if (set.wavelength_nm != lens.primary_wavelength_nm()) continue;
    CHECK_THAT(set.points.front().tangential_mm, WithinAbs(expected, kPencilAberrationMm));
    CHECK_THAT(set.points.front().sagittal_mm, WithinAbs(expected, kPencilAberrationMm));
  }
  // Off axis the triplet is astigmatic: the two curves part.
  const FieldCurvePoint& full = fc.curves[1].points.back();
  CHECK(std::abs(full.tangential_mm - full.sagittal_mm) > 0.1);
}

TEST_CASE("a sphere with the stop at its centre of curvature: T = S = R/(n-1) (cos(theta) - 1) at every field", "[analysis][field-curves]") {
  // Air to glass n through a sphere of radius R; the stop is a plane through the centre of
  // curvature inside the glass, so every chief ray is a radius and every field sees the axial
  // system turned by theta. The axial focus lies R / (n - 1) beyond the centre; turned by theta,
  // its z is R + R cos(theta) / (n - 1), i.e. (R / (n - 1)) (cos(theta) - 1) from the flat image plane.
  const double n = 1.5, radius = 20.0;
  const MaterialSpec glass = MaterialSpec::model(n, std::nullopt);
  Prescription p;
  p.name = "concentric surface";
  p.surfaces = {make_surface(radius, radius, glass), make_surface(kInfinity, n * radius / (n - 1.0) - radius, glass, 1.0)};
  p.surfaces[1].is_stop = true;
  p.aperture = ApertureSpec{ApertureSpec::Kind::EntrancePupilDiameter, 2.0};
  p.field = FieldSpec{FieldSpec::Kind::AngleDeg, {30.0}};
  p.wavelengths_nm = {587.5618};
  p.primary_wavelength_index = 0;
  FieldCurveOptions options;
  options.field_samples = 7;
  const FieldCurves fc = compute_field_curves(AnalysisContext(p), options);
  INFO(fc);
  for (const FieldCurvePoint& point : fc.curves.at(0).points) {
    const double expected = radius / (n - 1.0) * (std::cos(rad_from_deg(point.field_value)) - 1.0);
    INFO("field " << point.field_value << " deg");
    CHECK_THAT(point.tangential_mm, WithinAbs(expected, kPencilAberrationMm));
    CHECK_THAT(point.sagittal_mm, WithinAbs(expected, kPencilAberrationMm));
  }
}

TEST_CASE("field curve options name the field and the limit", "[analysis][field-curves]") {
  FieldCurveOptions o;
  o.pupil_step = 0.5;
  CHECK_THROWS_WITH(o.validate(), Catch::Contains("pupil_step") && Catch::Contains("(0, 0.1]"));
  o.pupil_step = 1e-3;
  o.field_samples = 1;
  CHECK_THROWS_WITH(o.validate(), Catch::Contains("field_samples = 1"));
}
