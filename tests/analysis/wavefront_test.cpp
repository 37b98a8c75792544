// The wavefront (OPD against the reference sphere at the exit pupil) against closed forms: a perfect
// imager (an ellipsoid of eccentricity 1 / n focuses a parallel beam without aberration: Born & Wolf,
// Principles of Optics, sec. 4.2.3) has none; moved off its focus by dz it has the defocus of a spherical
// wave, W = n' dz (1 - cos a) for a ray at angle a to the axis (Welford, Aberrations of Optical Systems,
// sec. 5.4); and at a small aperture the fitted primary spherical aberration is Seidel's W040 = S_I / 8.
#include <catch2/catch.hpp>
#include <cmath>

#include "lensmith/analysis/wavefront.h"
#include "lensmith/core/units.h"
#include "lensmith/glass/glass_catalog.h"
#include "lensmith/paraxial/paraxial_system.h"
#include "lensmith/prescription/lens_file.h"
#include "lensmith/seidel/seidel_analysis.h"
#include "reference_lenses.h"

using namespace lensmith;
using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;

namespace {

constexpr double kIndex = testing::CartesianEllipsoid::kIndex;
constexpr double kFocusMm = testing::CartesianEllipsoid::kFocusMm;

Prescription perfect_imager(double defocus_mm) { return testing::cartesian_ellipsoid(defocus_mm); }

AnalysisOptions on_axis() {
  AnalysisOptions o;
  o.relative_fields = {0.0};
  return o;
}

}  // namespace

TEST_CASE("A perfect imager's wavefront is the reference sphere", "[analysis][wavefront]") {
  const AnalysisContext context(perfect_imager(0.0), on_axis());
  WavefrontOptions options;
  options.grid = 32;
  const Wavefront w = compute_wavefront(context, options);
  REQUIRE(w.maps.size() == 1);
  const WavefrontMap& m = w.maps.front();
  // Rounding of optical paths of ~200 mm (1e-13 mm) in waves of 5.9e-4 mm: 1e-9 waves; 1e-7 allows for
  // the intersections' iterations.
  constexpr double kPerfect_waves = 1e-7;
  CHECK(m.samples > 700);
  CHECK(m.lost.total() == 0);
  CHECK(m.rms_waves < kPerfect_waves);
  CHECK(m.pv_waves < kPerfect_waves);
  // The sphere: from the stop (the exit pupil, at the vertex) to the focus.
  CHECK_THAT(m.reference_radius_mm, WithinRel(kFocusMm, 1e-9));
}

TEST_CASE("An off-axis paraboloid's wavefront is perfect on axis, through its fold and turned image plane", "[analysis][wavefront]") {
  // Edmund Optics' 90-degree off-axis paraboloid (tests/data/zemax/real/zmax_37992.zmx): one mirror, a
  // decentre and tilts; a paraboloid images a point at infinity on its axis without aberration.
  const Prescription lens = read_lens_file(std::string(LENSMITH_TEST_DATA_DIR) + "/zemax/real/zmax_37992.zmx").prescription;
  const AnalysisContext context(lens, on_axis());
  WavefrontOptions options;
  options.grid = 16;
  options.zernike_terms = 9;
  const Wavefront w = compute_wavefront(context, options);
  for (const WavefrontMap& m : w.maps) {
    CHECK(m.lost.total() == 0);
    CHECK(m.rms_waves < 1e-6);  // rounding of ~200-mm paths through frame changes, in waves
  }
}

TEST_CASE("A wavefront off its focus is the defocus of a spherical wave, positive behind the focus", "[analysis][wavefront]") {
  const double dz = 0.2;  // mm behind the focus
  const AnalysisContext context(perfect_imager(dz), on_axis());
  WavefrontOptions options;
  options.grid = 16;
  const Wavefront w = compute_wavefront(context, options);
  const WavefrontMap& m = w.maps.front();
  const double wave_mm = mm_from_nm(kWavelengthD_nm);
  // The closed form holds to first order in dz: the next term, dz^2 sin^2 a / (2 R), is 0.1 % of it here.
  constexpr double kFirstOrder = 5e-3;
  int checked = 0;
  for (const OpdSample& s : m.map) {
    if (s.px * s.px + s.py * s.py > 1.0 || std::hypot(s.px, s.py) < 0.3) continue;
    const TracedRay r = context.trace(context.field_at(0.0), {s.px, s.py}, kWavelengthD_nm);
    REQUIRE(r.ok());
    const double expected = kIndex * dz * (1.0 - r.image_ray.direction.z()) / wave_mm;
    CHECK_THAT(s.opd_waves, WithinRel(expected, kFirstOrder));
    ++checked;
  }
  CHECK(checked > 100);
  // Its Zernike fit is defocus: Fringe Z4 = W020 / 2 with W020 = n' dz sin^2 a_max / 2 (a_max the marginal
  // ray's angle); nothing in the odd or azimuthal terms. 0.2 %: sin a is not quite linear in the pupil
  // coordinate (the ray leaves the surface's sag, 1 mm at the rim, nearer the focus) and 1 - cos a has a
  // sin^4 a / 8 part; both put a little rho^4 into the fit, which shares it with Z4 (measured 0.02 %).
  const TracedRay marginal = context.trace(context.field_at(0.0), {0.0, 1.0}, kWavelengthD_nm);
  REQUIRE(marginal.ok());
  const double sin2_a = 1.0 - marginal.image_ray.direction.z() * marginal.image_ray.direction.z();
  const double w020 = kIndex * dz * sin2_a / 2.0 / wave_mm;
  CHECK_THAT(m.zernike[3], WithinRel(w020 / 2.0, 2e-3));
  for (int j : {2, 3, 5, 6, 7, 8}) CHECK_THAT(m.zernike[static_cast<std::size_t>(j - 1)], WithinAbs(0.0, 1e-6));
}

TEST_CASE("At a small aperture the wavefront's primary spherical aberration is Seidel's W040", "[analysis][wavefront]") {
  // Smith's Cooke triplet stopped down, on axis at the paraxial focus: W = W040 rho^4 + W060 rho^6 + ...,
  // and with the Fringe terms Z9 = 6 rho^4 - ... and Z16 fitted, 6 Z9 = W040 + 1.5 W060 + ...: the
  // fifth-order share falls as the aperture squared, so halving the aperture must quarter the difference.
  auto compare = [](double aperture_share) {
    Prescription lens = testing::smith_cooke_triplet();
    lens.aperture = ApertureSpec{ApertureSpec::Kind::EntrancePupilDiameter, aperture_share * ParaxialSystem(lens).entrance_pupil().diameter_mm};
    AnalysisOptions o = on_axis();
    o.image_plane = TracerOptions::ImagePlane::ParaxialFocus;
    o.wavelengths_nm = {lens.primary_wavelength_nm()};
    const AnalysisContext context(lens, o);
    WavefrontOptions options;
    options.grid = 32;
    const double z9 = compute_wavefront(context, options).maps.front().zernike[8];
    const double w040 = SeidelAnalysis(lens).wavefront().in_waves(lens.primary_wavelength_nm()).W040;
    INFO("aperture " << aperture_share << ": Seidel W040 " << w040 << " waves, 6 Z9 " << 6.0 * z9);
    REQUIRE(std::abs(w040) > 1e-3);
    return 6.0 * z9 / w040 - 1.0;
  };
  const double quarter = compare(0.25), eighth = compare(0.125);
  INFO("relative difference at a quarter of the pupil " << quarter << ", at an eighth " << eighth);
  // Measured 4.3 % and 1.1 %: the ratio 0.25 within 0.02 (the seventh order's share).
  CHECK(std::abs(quarter) < 0.05);
  CHECK(std::abs(eighth) < 0.015);
  CHECK_THAT(eighth / quarter, WithinAbs(0.25, 0.02));
}
