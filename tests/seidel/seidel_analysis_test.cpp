// Welford's Seidel sums against published third-order listings: Smith's Cooke triplet (Modern
// Optical Engineering, 4th ed., ch. 6) and the Sasian triplet (ray-optics documentation), both in
// ../shared/lens-data/REFERENCE-VALUES.md; and identities that hold for any lens.
#include "lensmith/seidel/seidel_analysis.h"

#include <catch2/catch.hpp>
#include <cmath>

#include "lensmith/core/errors.h"
#include "lensmith/glass/glass_catalog.h"
#include "reference_lenses.h"

using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;
using namespace lensmith;
using lensmith::testing::make_surface;

namespace {

// ray-optics prints the Sasian sums with 6 decimals: half a unit of rounding, and the same again for
// the two programs' glass formulas (both Schott Sellmeier, evaluated independently).
constexpr double kSixDecimals = 1e-6;
// Smith prints 6 decimals and works from his rounded ray table (heights off by up to 1e-5, see the
// paraxial tests): the per-surface transverse contributions agree to a few units in the 6th decimal.
constexpr double kSmithRounding = 5e-6;
// Smith's colour contributions rest on his rounded n_F - n_C (REFERENCE-VALUES.md: about 0.1 % per
// surface and 3 % on the PAC sum, which is a small difference of large terms).
constexpr double kSmithColourPerSurface = 1e-3;
constexpr double kSmithColourSum = 0.03;

struct SmithRow {
  double SA3, CMA3, AST3, PTZ3, DIS3, PAC, PLC;
};

// Smith's table of third-order and primary colour contributions (transverse, mm).
constexpr SmithRow kSmithRows[] = {
    {-0.709019, -0.070068, -0.006924, -0.330897, -0.033385, -0.255960, -0.025295},
    {-0.755360, 0.844458, -0.944066, -0.036241, 1.095939, -0.187385, 0.209488},
    {2.049816, -1.416428, 0.978756, 0.300215, -0.883772, 0.419729, -0.290034},
    {0.493011, 0.393733, 0.314447, 0.351763, 0.532055, 0.287842, 0.229879},
    {0, 0, 0, 0, 0, 0, 0},
    {-0.035845, -0.087854, -0.215325, -0.060510, -0.676055, -0.063021, -0.154461},
    {-1.229178, 0.317877, -0.082206, -0.334022, 0.107641, -0.223595, 0.057824},
};
constexpr SmithRow kSmithSum = {-0.186575, -0.018282, 0.044681, -0.109691, 0.142422, -0.022389, 0.027401};

}  // namespace

TEST_CASE("Seidel: the Sasian triplet's Welford sums per surface match ray-optics' listing", "[seidel]") {
  const SeidelAnalysis s(testing::sasian_triplet());
  // REFERENCE-VALUES.md section 2: S-I .. S-V per surface.
  const double expected[6][5] = {
      {0.027654, 0.019379, 0.013581, 0.089174, 0.072010},   {0.022082, -0.059501, 0.160327, -0.000288, -0.431229},
      {-0.105156, 0.137692, -0.180295, -0.085097, 0.347506}, {-0.045358, -0.076796, -0.130024, -0.095046, -0.381069},
      {0.007942, 0.028382, 0.101431, 0.024373, 0.449596},   {0.103810, -0.050068, 0.024148, 0.103180, -0.061411},
  };
  REQUIRE(s.surfaces().size() == 6);
  for (std::size_t k = 0; k < 6; ++k) {
    INFO("surface " << k + 1);
    const SeidelSums& t = s.surfaces()[k];
    CHECK_THAT(t.S1, WithinAbs(expected[k][0], kSixDecimals));
    CHECK_THAT(t.S2, WithinAbs(expected[k][1], kSixDecimals));
    CHECK_THAT(t.S3, WithinAbs(expected[k][2], kSixDecimals));
    CHECK_THAT(t.S4, WithinAbs(expected[k][3], kSixDecimals));
    CHECK_THAT(t.S5, WithinAbs(expected[k][4], kSixDecimals));
  }
  CHECK_THAT(s.sums().S1, WithinAbs(0.010973, kSixDecimals));
  CHECK_THAT(s.sums().S2, WithinAbs(-0.000912, kSixDecimals));
  CHECK_THAT(s.sums().S3, WithinAbs(-0.010832, kSixDecimals));
  CHECK_THAT(s.sums().S4, WithinAbs(0.036297, kSixDecimals));
  CHECK_THAT(s.sums().S5, WithinAbs(-0.004597, kSixDecimals));
}

TEST_CASE("Seidel: the Sasian triplet's wavefront, transverse and curvature forms match ray-optics", "[seidel]") {
  const SeidelAnalysis s(testing::sasian_triplet());
  const WavefrontCoefficients w = s.wavefront().in_waves(587.5618);
  // ray-optics prints 6 decimals of waves; the sums behind them carry 6 decimals of mm, so the
  // waves agree to about 5e-7 mm / 5.9e-4 mm = 1e-3 waves.
  constexpr double kWaves = 2e-3;
  CHECK_THAT(w.W040, WithinAbs(2.334457, kWaves));
  CHECK_THAT(w.W131, WithinAbs(-0.776108, kWaves));
  CHECK_THAT(w.W222, WithinAbs(-9.218154, kWaves));
  CHECK_THAT(w.W220, WithinAbs(10.834770, kWaves));
  CHECK_THAT(w.W311, WithinAbs(-3.911650, kWaves));
  const TransverseAberrations t = s.transverse();
  constexpr double kTransverse = 1e-5;  // sums of 6-decimal numbers divided by 2u' = -0.25
  CHECK_THAT(t.TSA, WithinAbs(-0.043893, kTransverse));
  CHECK_THAT(t.TCO, WithinAbs(0.010944, kTransverse));
  CHECK_THAT(t.TAS, WithinAbs(-0.015198, kTransverse));
  CHECK_THAT(t.SAS, WithinAbs(-0.101860, kTransverse));
  CHECK_THAT(t.PTB, WithinAbs(-0.145190, kTransverse));
  CHECK_THAT(t.DST, WithinAbs(0.018387, kTransverse));
  const FieldCurvatures f = s.field_curvatures();
  constexpr double kCurvature = 5e-7;  // printed with 6 decimals
  CHECK_THAT(f.tangential_per_mm, WithinAbs(0.000734, kCurvature));
  CHECK_THAT(f.sagittal_per_mm, WithinAbs(0.004921, kCurvature));
  CHECK_THAT(f.petzval_per_mm, WithinAbs(0.007014, kCurvature));
}

TEST_CASE("Seidel: on the axis (field 0) the field curvatures are still the lens's, ray-optics' values", "[seidel]") {
  // Petzval, sagittal and tangential curvature do not depend on the field (S_III and S_IV grow as
  // H^2); at field 0 both are 0 and the ratio must come from the lens, not be 0 / 0.
  SeidelOptions axis;
  axis.field_angle_deg = 0.0;
  const SeidelAnalysis s(testing::sasian_triplet(), axis);
  CHECK(s.lagrange_invariant() == 0.0);
  const FieldCurvatures f = s.field_curvatures();
  constexpr double kCurvature = 5e-7;  // ray-optics prints 6 decimals
  CHECK_THAT(f.tangential_per_mm, WithinAbs(0.000734, kCurvature));
  CHECK_THAT(f.sagittal_per_mm, WithinAbs(0.004921, kCurvature));
  CHECK_THAT(f.petzval_per_mm, WithinAbs(0.007014, kCurvature));
  CHECK(std::isfinite(f.petzval_radius_mm()));
}

TEST_CASE("Seidel: Smith's Cooke triplet, surface by surface, in Smith's transverse forms", "[seidel]") {
  const SeidelAnalysis s(testing::smith_cooke_triplet());
  // Smith's transverse forms divide by 2 n'u' (n'u' for colour) of the final image space.
  const double k = 1.0 / (2.0 * s.image_index() * s.image_slope());
  for (std::size_t i = 0; i < 7; ++i) {
    INFO("surface " << i + 1);
    const SeidelSums& t = s.surfaces()[i];
    const SmithRow& r = kSmithRows[i];
    CHECK_THAT(t.S1 * k, WithinAbs(r.SA3, kSmithRounding * (1.0 + std::abs(r.SA3))));
    CHECK_THAT(t.S2 * k, WithinAbs(r.CMA3, kSmithRounding * (1.0 + std::abs(r.CMA3))));
    CHECK_THAT(t.S3 * k, WithinAbs(r.AST3, kSmithRounding * (1.0 + std::abs(r.AST3))));
    CHECK_THAT(t.S4 * k, WithinAbs(r.PTZ3, kSmithRounding * (1.0 + std::abs(r.PTZ3))));
    CHECK_THAT(t.S5 * k, WithinAbs(r.DIS3, kSmithRounding * (1.0 + std::abs(r.DIS3))));
    CHECK_THAT(t.C1 * 2.0 * k, WithinAbs(r.PAC, kSmithRounding + kSmithColourPerSurface * std::abs(r.PAC)));
    CHECK_THAT(t.C2 * 2.0 * k, WithinAbs(r.PLC, kSmithRounding + kSmithColourPerSurface * std::abs(r.PLC)));
  }
  const SeidelSums& sum = s.sums();
  CHECK_THAT(sum.S1 * k, WithinAbs(kSmithSum.SA3, 2e-5));
  CHECK_THAT(sum.S2 * k, WithinAbs(kSmithSum.CMA3, 2e-5));
  CHECK_THAT(sum.S3 * k, WithinAbs(kSmithSum.AST3, 2e-5));
  CHECK_THAT(sum.S4 * k, WithinAbs(kSmithSum.PTZ3, 2e-5));
  CHECK_THAT(sum.S5 * k, WithinAbs(kSmithSum.DIS3, 2e-5));
  CHECK_THAT(sum.C1 * 2.0 * k, WithinRel(kSmithSum.PAC, kSmithColourSum));
  CHECK_THAT(sum.C2 * 2.0 * k, WithinRel(kSmithSum.PLC, kSmithColourSum));
  // Smith: Petzval radius / EFL = -2.935.
  CHECK_THAT(s.field_curvatures().petzval_radius_mm() / s.paraxial().efl_mm(), WithinAbs(-2.935, 5e-4));
}

TEST_CASE("Seidel: a positive plano-convex singlet is undercorrected, S_I > 0 (Welford's sign)", "[seidel]") {
  Prescription p;
  p.surfaces = {make_surface(50.0, 5.0, MaterialSpec::model(1.5168, 64.17), 12.0), make_surface(kInfinity, 95.0, MaterialSpec::air(), 12.0)};
  p.surfaces[0].is_stop = true;
  p.aperture = {ApertureSpec::Kind::EntrancePupilDiameter, 20.0};
  p.field = FieldSpec{FieldSpec::Kind::AngleDeg, {5.0}};
  const SeidelAnalysis s(p);
  CHECK(s.sums().S1 > 0.0);
  CHECK(s.transverse().TSA < 0.0);      // marginal ray lands below the axis on the paraxial image plane
  CHECK(s.longitudinal().LSA < 0.0);    // and focuses in front of the paraxial focus
  CHECK(s.sums().C1 > 0.0);             // blue focuses first: undercorrected axial colour
  CHECK(s.sums().S4 > 0.0);             // inward-curving Petzval surface
}

TEST_CASE("Seidel: the colour sums use the lens's own shortest and longest wavelengths, as CODE V does", "[seidel]") {
  // A thin singlet in air with the stop at the lens: C_I = y^2 phi dn / (n - 1) (Welford eq. 8.46 summed over
  // both surfaces), dn the index difference at the two wavelengths. A 1-mm-thick lens stands in for thin.
  const MaterialSpec bk7 = MaterialSpec::catalog("N-BK7", "SCHOTT");
  Prescription p;
  p.surfaces = {make_surface(50.0, 0.001, bk7, 12.0), make_surface(-50.0, 95.0, MaterialSpec::air(), 12.0)};
  p.surfaces[0].is_stop = true;
  p.aperture = {ApertureSpec::Kind::EntrancePupilDiameter, 20.0};
  p.field = FieldSpec{FieldSpec::Kind::AngleDeg, {5.0}};
  p.wavelengths_nm = {450.0, 550.0, 650.0};
  p.primary_wavelength_index = 1;
  p.resolve_materials(GlassCatalog::builtin());
  const Glass& g = p.surfaces[0].medium;
  const SeidelAnalysis own(p);
  CHECK(own.colour_wavelengths_nm() == std::array<double, 2>{450.0, 650.0});
  const double n = g.index(550.0);
  const double phi = (n - 1.0) * (2.0 / 50.0);
  const double thin = 10.0 * 10.0 * phi * (g.index(450.0) - g.index(650.0)) / (n - 1.0);
  // 1 mm of thickness changes y at the second surface by 1e-3 of its value: a 1e-3 relative allowance.
  CHECK_THAT(own.sums().C1, WithinRel(thin, 2e-3));
  SeidelOptions fc;
  fc.colour_wavelengths_nm = std::array<double, 2>{kWavelengthF_nm, kWavelengthC_nm};
  const SeidelAnalysis principal(p, fc);
  CHECK_THAT(principal.sums().C1 / own.sums().C1,
             WithinRel((g.index(kWavelengthF_nm) - g.index(kWavelengthC_nm)) / (g.index(450.0) - g.index(650.0)), 1e-12));
  // A lens at F, d, C gets n_F - n_C, the textbook C_I.
  p.wavelengths_nm = {kWavelengthF_nm, kWavelengthD_nm, kWavelengthC_nm};
  CHECK(SeidelAnalysis(p).colour_wavelengths_nm() == std::array<double, 2>{kWavelengthF_nm, kWavelengthC_nm});
}

TEST_CASE("Seidel: the aplanatic ellipsoid (k = -1/n^2, air to glass) has zero spherical aberration", "[seidel]") {
  // A refracting ellipsoid of eccentricity 1/n images infinity onto its far focus without any
  // spherical aberration (Descartes' ovals; Welford sec. 8.5): the conic term cancels the sphere's.
  const double n = 1.8;
  Surface ellipsoid = make_surface(20.0, 45.0, MaterialSpec::model(n, {}), 8.0);
  ellipsoid.conic = -1.0 / (n * n);
  Prescription p;
  p.surfaces = {ellipsoid};
  p.surfaces[0].is_stop = true;
  p.aperture = {ApertureSpec::Kind::EntrancePupilDiameter, 10.0};
  p.field = FieldSpec{FieldSpec::Kind::AngleDeg, {1.0}};
  const SeidelAnalysis s(p);
  CHECK(s.aspheric_parts()[0].S1 != 0.0);
  CHECK_THAT(s.sums().S1, WithinAbs(0.0, 1e-15));
}

TEST_CASE("Seidel: a stop at the centre of curvature of a single surface gives no coma, astigmatism or distortion", "[seidel]") {
  // With the stop at the centre of curvature the chief ray is normal to the surface: A-bar = 0, so
  // S_II = S_III = S_V = 0 and only S_I and S_IV remain (Welford sec. 8.3).
  Prescription p;
  Surface stop = make_surface(kInfinity, 30.0, MaterialSpec::air(), 4.0);
  stop.is_stop = true;
  p.surfaces = {stop, make_surface(-30.0, 60.0, MaterialSpec::model(1.6, 40.0), 20.0)};
  p.aperture = {ApertureSpec::Kind::EntrancePupilDiameter, 8.0};
  p.field = FieldSpec{FieldSpec::Kind::AngleDeg, {10.0}};
  const SeidelAnalysis s(p);
  constexpr double kZero = 1e-15;
  CHECK_THAT(s.surfaces()[1].S2, WithinAbs(0.0, kZero));
  CHECK_THAT(s.surfaces()[1].S3, WithinAbs(0.0, kZero));
  CHECK_THAT(s.surfaces()[1].S5, WithinAbs(0.0, kZero));
  CHECK(s.surfaces()[1].S1 != 0.0);
}

TEST_CASE("Seidel: halving aperture and field divides S_I, S_III and S_V by 16 (a^4, a^2 h^2, a h^3)", "[seidel]") {
  const Prescription lens = testing::sasian_triplet();
  SeidelOptions half;
  half.entrance_pupil_diameter_mm = 6.25;
  half.field_angle_deg = std::atan(std::tan(20.0 * kPi / 180.0) / 2.0) * 180.0 / kPi;
  const SeidelAnalysis full(lens);
  const SeidelAnalysis reduced(lens, half);
  constexpr double kExactScaling = 1e-12;  // the paraxial rays scale exactly; only rounding differs
  CHECK_THAT(reduced.sums().S1, WithinRel(full.sums().S1 / 16.0, kExactScaling));
  CHECK_THAT(reduced.sums().S5, WithinRel(full.sums().S5 / 16.0, kExactScaling));
  CHECK_THAT(reduced.sums().S2, WithinRel(full.sums().S2 / 16.0, kExactScaling));
  CHECK_THAT(reduced.sums().S3, WithinRel(full.sums().S3 / 16.0, kExactScaling));
}

TEST_CASE("Seidel: a lens without a field needs one to be given", "[seidel]") {
  Prescription p = testing::sasian_triplet();
  p.field.reset();
  CHECK_THROWS_AS(SeidelAnalysis(p), PrescriptionError);
  SeidelOptions o;
  o.field_angle_deg = 10.0;
  CHECK_NOTHROW(SeidelAnalysis(p, o));
  o.f_number = 2.0;
  o.entrance_pupil_diameter_mm = 10.0;
  CHECK_THROWS_WITH(SeidelAnalysis(p, o), Catch::Contains("give one"));
}
