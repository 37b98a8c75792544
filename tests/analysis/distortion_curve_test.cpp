// Real-ray distortion: zero for a system symmetric about its stop at unit magnification (the
// symmetry principle: Welford, Aberrations of Optical Systems, sec. 8.4; Kingslake, Lens Design
// Fundamentals, ch. 7), barrel for a positive lens behind its stop and pincushion in front of it
// (Hecht, Optics, 5th ed., sec. 6.3.1, "Distortion"), strongly barrel for a fisheye against f tan(theta).
#include "lensmith/analysis/distortion_curve.h"

#include <catch2/catch.hpp>
#include <cmath>

#include "lensmith/core/errors.h"
#include "lensmith/paraxial/paraxial_system.h"
#include "lensmith/prescription/lens_library.h"
#include "reference_lenses.h"

using Catch::Matchers::WithinAbs;
using namespace lensmith;
using lensmith::testing::make_surface;

namespace {

// Mirror-symmetric about a flat stop: R1, glass, R2, gap | stop | gap, -R2, glass, -R1.
Prescription symmetric_lens() {
  const MaterialSpec glass = MaterialSpec::model(1.62, std::nullopt);
  const MaterialSpec air = MaterialSpec::air();
  Prescription p;
  p.name = "symmetric doublet";
  p.surfaces = {make_surface(25.0, 4.0, glass), make_surface(-120.0, 3.0, air), make_surface(kInfinity, 3.0, air, 3.0),
                make_surface(120.0, 4.0, glass), make_surface(-25.0, 50.0, air)};
  p.surfaces[2].is_stop = true;
  p.aperture = ApertureSpec{ApertureSpec::Kind::FloatByStop, 0.0};
  p.wavelengths_nm = {587.5618};
  p.primary_wavelength_index = 0;
  return p;
}

// A biconvex singlet with a flat stop `gap_mm` in front of it or behind it.
Prescription singlet_with_stop(bool stop_in_front) {
  const MaterialSpec glass = MaterialSpec::model(1.5168, std::nullopt);
  const MaterialSpec air = MaterialSpec::air();
  Prescription p;
  if (stop_in_front) {
    p.surfaces = {make_surface(kInfinity, 20.0, air, 2.5), make_surface(50.0, 5.0, glass), make_surface(-50.0, 40.0, air)};
    p.surfaces[0].is_stop = true;
  } else {
    p.surfaces = {make_surface(50.0, 5.0, glass), make_surface(-50.0, 20.0, air), make_surface(kInfinity, 20.0, air, 2.5)};
    p.surfaces[2].is_stop = true;
  }
  p.image_at_paraxial_focus = true;
  p.aperture = ApertureSpec{ApertureSpec::Kind::FloatByStop, 0.0};
  p.field = FieldSpec{FieldSpec::Kind::AngleDeg, {20.0}};
  p.wavelengths_nm = {587.5618};
  p.primary_wavelength_index = 0;
  return p;
}

}  // namespace

TEST_CASE("a lens symmetric about its stop at magnification -1 has no distortion (symmetry principle)", "[analysis][distortion]") {
  Prescription lens = symmetric_lens();
  // Magnification -1: the object 2f in front of the front principal point (paraxial, then real:
  // the real chief ray through the stop centre is mirror-symmetric too).
  const ParaxialSystem at_infinity(lens);
  lens.object_distance_mm = 2.0 * at_infinity.efl_mm() - at_infinity.z_front_principal_mm();
  lens.field = FieldSpec{FieldSpec::Kind::ObjectHeightMm, {6.0}};
  AnalysisOptions options;
  options.image_plane = TracerOptions::ImagePlane::ParaxialFocus;
  // The chief ray must cross the real stop at its centre for the mirror symmetry to hold; aimed at
  // the paraxial entrance pupil it misses by the pupil's aberration (-0.003 % at 6 mm here).
  options.aiming = RayAiming::RealStop;
  const DistortionCurve d = compute_distortion(AnalysisContext(lens, options));
  INFO(d);
  // Mirror symmetry holds to rounding; 1e-8 % of a 6 mm height is 6e-10 mm.
  constexpr double kSymmetryPercent = 1e-8;
  CHECK_THAT(d.points.back().paraxial_height_mm, WithinAbs(-6.0, 1e-9));  // m = -1 of the object at y = +6
  for (const DistortionPoint& p : d.points) CHECK_THAT(p.distortion_percent, WithinAbs(0.0, kSymmetryPercent));

  // The control: the same lens with the object at infinity is not symmetric and distorts.
  Prescription far = symmetric_lens();
  far.field = FieldSpec{FieldSpec::Kind::AngleDeg, {15.0}};
  const DistortionCurve d_far = compute_distortion(AnalysisContext(far, options));
  INFO(d_far);
  CHECK(std::abs(d_far.points.back().distortion_percent) > 1e3 * kSymmetryPercent);
}

TEST_CASE("a positive singlet behind its stop shows barrel distortion, in front of its stop pincushion", "[analysis][distortion]") {
  const DistortionCurve front = compute_distortion(AnalysisContext(singlet_with_stop(true)));
  const DistortionCurve behind = compute_distortion(AnalysisContext(singlet_with_stop(false)));
  INFO(front << behind);
  CHECK(front.points.back().distortion_percent < 0.0);   // stop in front of the lens: barrel
  CHECK(behind.points.back().distortion_percent > 0.0);  // stop behind the lens: pincushion
  // Third-order distortion grows as the cube of the field, so the percentage as its square: at
  // half field about a quarter of the full-field value (higher orders move it by a few percent).
  const double ratio = front.points[10].distortion_percent / front.points.back().distortion_percent;
  CHECK(ratio > 0.2);
  CHECK(ratio < 0.3);
  // With the image plane at the paraxial focus the on-axis limit is 0 (distortion grows as h^2).
  CHECK_THAT(front.points.front().distortion_percent, WithinAbs(0.0, 1e-6));
}

TEST_CASE("the 10 mm fisheye is strongly barrel against f tan(theta), more so at every larger field", "[analysis][distortion]") {
  const Prescription fisheye = LensLibrary::load("pbrt-fisheye-10mm").prescription;
  AnalysisOptions options;
  options.aiming = RayAiming::RealStop;  // the paraxial pupil means nothing 60 degrees off axis
  options.max_field_angle_deg = 60.0;
  DistortionOptions o;
  o.field_samples = 7;
  const DistortionCurve d = compute_distortion(AnalysisContext(fisheye, options), o);
  INFO(d);
  // f tan(60 deg) = 1.73 f, while a fisheye maps angles about linearly (f theta = 1.05 f): -39 %.
  CHECK(d.points.back().distortion_percent < -25.0);
  for (std::size_t i = 1; i < d.points.size(); ++i) CHECK(d.points[i].distortion_percent < d.points[i - 1].distortion_percent);
}

TEST_CASE("on axis, distortion measured on a defocused image plane tends to the chief ray's slope times the defocus", "[analysis][distortion]") {
  // The Sasian triplet's image plane sits dz = 1.1 um before its paraxial focus. Near the axis the
  // real chief ray lands at y_p (1 - dz / L), L the distance from the exit pupil to the paraxial
  // image (a paraxial chief ray seen from the exit pupil), so D(0) = -100 dz / L %.
  const Prescription lens = lensmith::testing::sasian_triplet();
  const DistortionCurve d = compute_distortion(AnalysisContext(lens));
  const ParaxialSystem p(lens);
  const double dz = p.z_image_mm() - d.image_plane_z_mm;
  const double exit_pupil_to_image = p.z_image_mm() - p.exit_pupil().z_mm;
  INFO(d);
  REQUIRE(dz > 0.0);
  // Pupil aberration and third-order distortion at 1e-4 of the field: far below 1e-6 %.
  CHECK_THAT(d.points.front().distortion_percent, WithinAbs(-100.0 * dz / exit_pupil_to_image, 1e-6));
  CHECK_THAT(d.points.front().distortion_percent, WithinAbs(d.points[1].distortion_percent, 1e-3));  // continuous
}

TEST_CASE("distortion needs a field: a lens without one asks for the field angle", "[analysis][distortion]") {
  Prescription lens = lensmith::testing::angenieux_double_gauss();
  lens.field.reset();
  AnalysisOptions on_axis;
  on_axis.relative_fields = {0.0};
  CHECK_THROWS_WITH(compute_distortion(AnalysisContext(lens, on_axis)), Catch::Contains("--field-angle"));
  AnalysisOptions options;
  options.max_field_angle_deg = 10.0;
  const DistortionCurve d = compute_distortion(AnalysisContext(lens, options));
  CHECK(d.points.back().field_value == 10.0);
  CHECK(d.field_unit == "deg");
}
