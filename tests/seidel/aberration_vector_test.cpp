// Born & Wolf's aberration vector from Welford's sums: the relations between B..F and S_I..S_V,
// consistency with the transverse forms, and the tabulated coefficients over wavelength and distance.
#include "lensmith/seidel/aberration_vector.h"

#include <catch2/catch.hpp>
#include <cmath>

#include "lensmith/core/units.h"
#include "lensmith/seidel/aberration_table.h"
#include "reference_lenses.h"

using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;
using namespace lensmith;

namespace {
constexpr double kArithmetic = 1e-12;  // a few products of doubles
}

TEST_CASE("aberration vector: B, C, D, E, F are S_I, S_III, S_III + S_IV, -S_V, -S_II over 2 n'u'", "[seidel][bornwolf]") {
  const SeidelAnalysis s(testing::sasian_triplet());
  const AberrationCoefficients c = AberrationCoefficients::from(s);
  const double k = 1.0 / (2.0 * s.image_index() * s.image_slope());
  CHECK_THAT(c.B_mm, WithinRel(k * s.sums().S1, kArithmetic));
  CHECK_THAT(c.C_mm, WithinRel(k * s.sums().S3, kArithmetic));
  CHECK_THAT(c.D_mm, WithinRel(k * (s.sums().S3 + s.sums().S4), kArithmetic));
  CHECK_THAT(c.E_mm, WithinRel(-k * s.sums().S5, kArithmetic));
  CHECK_THAT(c.F_mm, WithinRel(-k * s.sums().S2, kArithmetic));
}

TEST_CASE("aberration vector: at the pupil edge it reproduces the transverse third-order aberrations", "[seidel][bornwolf]") {
  const SeidelAnalysis s(testing::sasian_triplet());
  const AberrationCoefficients c = AberrationCoefficients::from(s);
  const TransverseAberrations t = s.transverse();
  // Axial point, top of the pupil: transverse spherical aberration.
  CHECK_THAT(c.displacement(1.0, 0.0, 0.0).y_mm, WithinAbs(t.TSA, kArithmetic));
  // Chief ray (rho = 0) at full field: distortion.
  CHECK_THAT(c.displacement(0.0, 0.0, 1.0).y_mm, WithinAbs(t.DST, kArithmetic));
  // Sagittal ray at full field without the spherical and coma parts: the sagittal focus error.
  const double sagittal = c.displacement(1.0, kPi / 2.0, 1.0).x_mm - c.displacement(1.0, kPi / 2.0, 0.0).x_mm;
  CHECK_THAT(sagittal, WithinAbs(t.SAS, kArithmetic));
  // Meridional ray pair at +-rho: the difference of the upper and lower rays is twice the
  // astigmatic (tangential) term plus spherical; their mean is the tangential coma.
  const double up = c.displacement(1.0, 0.0, 1.0).y_mm;
  const double down = c.displacement(1.0, kPi, 1.0).y_mm;
  CHECK_THAT(0.5 * (up + down) - t.DST, WithinAbs(t.TCO, kArithmetic));
  CHECK_THAT(0.5 * (up - down) - t.TSA, WithinAbs(t.TAS, kArithmetic));
}

TEST_CASE("aberration vector: Born & Wolf's units divide by D1 and the powers of pupil radius and field tangent", "[seidel][bornwolf]") {
  const SeidelAnalysis s(testing::sasian_triplet());
  const AberrationCoefficients c = AberrationCoefficients::from(s);
  const BornWolfUnits u = c.in_born_wolf_units();
  const double r = 6.25;                         // EP radius of the Sasian triplet
  const double t = std::tan(rad_from_deg(20.0)); // its maximum field
  CHECK_THAT(c.pupil_radius_mm, WithinRel(r, 1e-12));
  CHECK_THAT(c.max_field_tangent, WithinRel(t, 1e-12));
  // The same displacement computed both ways: B&W coordinates rho_BW = r, y0_BW = t, dp = mm / D1.
  const double rho_bw = r;
  const double y0_bw = t;
  const double dy_bw = u.B * rho_bw * rho_bw * rho_bw - u.F * y0_bw * rho_bw * rho_bw * 3.0 + (2.0 * u.C + u.D) * y0_bw * y0_bw * rho_bw -
                       u.E * y0_bw * y0_bw * y0_bw;
  CHECK_THAT(dy_bw * u.D1_mm, WithinRel(c.displacement(1.0, 0.0, 1.0).y_mm, 1e-12));
  CHECK(std::isinf(u.D0_mm));
}

TEST_CASE("aberration table: 64 wavelengths by the given distances, exact at the samples, smooth between", "[seidel][bornwolf]") {
  AberrationTableOptions o;
  o.object_distances_mm = {kInfinity, 2000.0, 500.0};
  const AberrationTable table(testing::sasian_triplet(), o);
  CHECK(table.wavelengths_nm().size() == 64);
  CHECK(table.object_distances_mm().size() == 3);
  SeidelOptions so;
  so.wavelength_nm = table.wavelengths_nm()[10];
  so.object_distance_mm = 2000.0;
  const AberrationCoefficients direct = AberrationCoefficients::from(SeidelAnalysis(testing::sasian_triplet(), so));
  const AberrationSample sampled = table.at(table.wavelengths_nm()[10], 2000.0);
  CHECK_THAT(sampled.coefficients.B_mm, WithinRel(direct.B_mm, 1e-12));
  CHECK_THAT(sampled.coefficients.E_mm, WithinRel(direct.E_mm, 1e-12));
  // Halfway between two samples: interpolation error of a smooth curve over 6.3 nm is tiny compared
  // with the change across the spectrum.
  so.wavelength_nm = 0.5 * (table.wavelengths_nm()[10] + table.wavelengths_nm()[11]);
  const AberrationCoefficients mid = AberrationCoefficients::from(SeidelAnalysis(testing::sasian_triplet(), so));
  const double span = std::abs(table.sample(0, 1).coefficients.B_mm - table.sample(63, 1).coefficients.B_mm);
  CHECK(std::abs(table.at(so.wavelength_nm, 2000.0).coefficients.B_mm - mid.B_mm) < 1e-3 * span);
  // Spherical aberration changes with wavelength (spherochromatism): the table is not flat.
  CHECK(span > 0.0);
}
