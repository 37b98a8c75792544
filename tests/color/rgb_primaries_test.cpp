// Matrices between RGB spaces computed from primaries (SMPTE RP 177-1993) and Bradford adaptation,
// against matrices the Academy and the IEC published.
#include "lensmith/color/rgb_primaries.h"

#include <catch2/catch.hpp>

using Catch::Matchers::WithinAbs;
using namespace lensmith;

namespace {
// Academy S-2014-004 prints AP0 <-> AP1 to 10 decimals; the same white, so no adaptation: they
// agree with the primaries' own matrix to the printed digits.
constexpr double kAcademyTenDecimals = 2e-10;
// MaterialX prints linear sRGB -> ACES2065-1 (Bradford) to 8 decimals.
constexpr double kMaterialXEightDecimals = 1e-8;
// IEC 61966-2-1 prints XYZ -> sRGB to 4 decimals, inverted from its sRGB -> XYZ matrix already
// rounded to 4 decimals: the exact matrix of the primaries differs by up to 3.4e-4 (the -0.9689
// printed for -0.96924).
constexpr double kIecFourDecimals = 5e-4;

void check_matrix(const Matrix3& computed, const double (&published)[3][3], double tolerance) {
  INFO("computed " << computed);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) CHECK_THAT(computed.m[i][j], WithinAbs(published[i][j], tolerance));
}
}  // namespace

TEST_CASE("ACEScg to ACES2065-1 from the AP1 and AP0 primaries is the Academy's published matrix", "[color][primaries]") {
  // Academy S-2014-004 (ACEScg), 4.1.3 and 4.1.4.
  const double ap1_to_ap0[3][3] = {{0.6954522414, 0.1406786965, 0.1638690622},
                                   {0.0447945634, 0.8596711185, 0.0955343182},
                                   {-0.0055258826, 0.0040252103, 1.0015006723}};
  const double ap0_to_ap1[3][3] = {{1.4514393161, -0.2365107469, -0.2149285693},
                                   {-0.0765537734, 1.1762296998, -0.0996759264},
                                   {0.0083161484, -0.0060324498, 0.9977163014}};
  check_matrix(rgb_conversion(kAcesAp1Primaries, kAcesAp0Primaries), ap1_to_ap0, kAcademyTenDecimals);
  check_matrix(rgb_conversion(kAcesAp0Primaries, kAcesAp1Primaries), ap0_to_ap1, kAcademyTenDecimals);
}

TEST_CASE("linear Rec.709 to ACES2065-1 with Bradford adaptation from D65 is the matrix MaterialX publishes", "[color][primaries]") {
  // MaterialX (Academy Software Foundation), mx_srgb_texture_to_aces_2065_1_color3.glsl (a GLSL
  // mat3 is column-major: its first three numbers are the first column here).
  const double rec709_to_ap0[3][3] = {
      {0.43963298, 0.38298870, 0.17737832}, {0.08977644, 0.81343943, 0.09678413}, {0.01754117, 0.11154655, 0.87091228}};
  check_matrix(rgb_conversion(kRec709Primaries, kAcesAp0Primaries), rec709_to_ap0, kMaterialXEightDecimals);
}

TEST_CASE("the Rec.709 primaries give the IEC 61966-2-1 XYZ to sRGB matrix, and white goes to white", "[color][primaries]") {
  const double iec[3][3] = {{3.2406, -1.5372, -0.4986}, {-0.9689, 1.8758, 0.0415}, {0.0557, -0.2040, 1.0570}};
  check_matrix(xyz_from_rgb(kRec709Primaries).inverse(), iec, kIecFourDecimals);
  // RGB (1, 1, 1) of any space is its white at Y = 1, and a conversion keeps white white.
  const auto white = xyz_from_rgb(kAcesAp0Primaries) * std::array<double, 3>{1.0, 1.0, 1.0};
  CHECK_THAT(white[0], WithinAbs(0.32168 / 0.33767, 1e-12));
  CHECK_THAT(white[1], WithinAbs(1.0, 1e-12));
  const auto grey = rgb_conversion(kRec709Primaries, kAcesAp1Primaries) * std::array<double, 3>{0.18, 0.18, 0.18};
  for (const double v : grey) CHECK_THAT(v, WithinAbs(0.18, 1e-12));
}

TEST_CASE("Bradford adaptation is the identity between equal whites and inverts when the whites swap", "[color][primaries]") {
  const Chromaticity d65 = kRec709Primaries.white, aces = kAcesAp0Primaries.white;
  const Matrix3 there = bradford_adaptation(d65, aces), back = bradford_adaptation(aces, d65);
  const Matrix3 round = back * there;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) CHECK_THAT(round.m[i][j], WithinAbs(i == j ? 1.0 : 0.0, 1e-12));
  const Matrix3 same = bradford_adaptation(d65, d65);
  CHECK(same.m[0][0] == 1.0);
  CHECK(same.m[0][1] == 0.0);
}
