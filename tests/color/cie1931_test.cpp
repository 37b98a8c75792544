// The CIE 1931 2-degree observer fit (Wyman, Sloan & Shirley, JCGT 2(2), 2013) against the CIE
// 1931 tabulated colour-matching functions (CIE 015:2004, Table T.4, 5 nm steps) and the
// IEC 61966-2-1 XYZ -> sRGB matrix against the D65 white it is built for.
#include "lensmith/color/cie1931.h"

#include <catch2/catch.hpp>

#include "lensmith/color/rgb.h"
#include "lensmith/core/errors.h"

using Catch::Matchers::WithinAbs;
using namespace lensmith;

namespace {
// The multi-lobe fit tracks the 1931 table to about 0.01 absolute at the wavelengths checked
// (largest here: x-bar(445 nm) = 0.358 fitted vs 0.3481 tabulated); 0.02 leaves margin, not slack.
constexpr double kWymanFit = 0.02;
// The equal-energy chromaticity integrates the fit's errors over the spectrum; they largely
// cancel (observed 3e-4 from 1/3), and 2e-3 is still well below a visible white shift.
constexpr double kEqualEnergyChromaticity = 2e-3;
// IEC 61966-2-1 prints its matrix to 4 decimals, so D65 maps to (1, 1, 1) only to ~1e-4.
constexpr double kIecRounding = 5e-4;
}  // namespace

TEST_CASE("CIE 1931 fit: matches the tabulated colour-matching functions at 445, 450, 555 and 600 nm", "[color][cie]") {
  struct Row {
    double wavelength_nm;
    Xyz table;  // CIE 015:2004 Table T.4
  };
  const Row rows[] = {
      {445.0, {0.34810, 0.02980, 1.78260}},
      {450.0, {0.33620, 0.03800, 1.77211}},
      {555.0, {0.51205, 1.00000, 0.00575}},
      {600.0, {1.06220, 0.63100, 0.00080}},
  };
  for (const auto& row : rows) {
    const Xyz fit = cie1931_cmf(row.wavelength_nm);
    INFO("lambda " << row.wavelength_nm << " nm: fit " << fit << ", table " << row.table);
    CHECK_THAT(fit.x, WithinAbs(row.table.x, kWymanFit));
    CHECK_THAT(fit.y, WithinAbs(row.table.y, kWymanFit));
    CHECK_THAT(fit.z, WithinAbs(row.table.z, kWymanFit));
  }
}

TEST_CASE("CIE 1931 fit: y-bar peaks between 550 and 560 nm, as the photopic V(lambda) at 555 nm", "[color][cie]") {
  double peak_nm = 0.0;
  double peak = -1.0;
  for (int tenth_nm = 3800; tenth_nm <= 7800; ++tenth_nm) {
    const double wavelength_nm = tenth_nm / 10.0;
    const double y = cie1931_cmf(wavelength_nm).y;
    if (y > peak) {
      peak = y;
      peak_nm = wavelength_nm;
    }
  }
  INFO("peak y-bar " << peak << " at " << peak_nm << " nm");
  CHECK(peak_nm > 550.0);
  CHECK(peak_nm < 560.0);
  CHECK_THAT(peak, WithinAbs(1.0, kWymanFit));
}

TEST_CASE("CIE 1931 fit: the equal-energy spectrum has chromaticity x = y = 1/3", "[color][cie]") {
  // Illuminant E is the observer's white by construction of the 1931 system (equal CMF areas).
  Xyz sum;
  for (int tenth_nm = 3600; tenth_nm <= 8300; ++tenth_nm) {
    const Xyz c = cie1931_cmf(tenth_nm / 10.0);
    sum.x += c.x;
    sum.y += c.y;
    sum.z += c.z;
  }
  const Chromaticity xy = chromaticity(sum);
  INFO(xy);
  CHECK_THAT(xy.x, WithinAbs(1.0 / 3.0, kEqualEnergyChromaticity));
  CHECK_THAT(xy.y, WithinAbs(1.0 / 3.0, kEqualEnergyChromaticity));
}

TEST_CASE("chromaticity: refuses a tristimulus value with X + Y + Z = 0", "[color][cie]") {
  CHECK_THROWS_AS(chromaticity(Xyz{0.0, 0.0, 0.0}), ComputationError);
}

TEST_CASE("IEC 61966-2-1 matrix: the D65 white (0.9505, 1, 1.0890) maps to linear RGB (1, 1, 1)", "[color][rgb]") {
  // D65 white point XYZ from its IEC chromaticity x = 0.3127, y = 0.3290 with Y = 1.
  const Xyz d65{0.3127 / 0.3290, 1.0, (1.0 - 0.3127 - 0.3290) / 0.3290};
  const Rgb rgb = rec709_from_xyz(d65);
  INFO(rgb);
  CHECK_THAT(rgb.r, WithinAbs(1.0, kIecRounding));
  CHECK_THAT(rgb.g, WithinAbs(1.0, kIecRounding));
  CHECK_THAT(rgb.b, WithinAbs(1.0, kIecRounding));
}

TEST_CASE("IEC 61966-2-1 matrix: monochromatic 550 nm light is green, outside the gamut in red and blue", "[color][rgb]") {
  const Rgb rgb = rec709_from_xyz(cie1931_cmf(550.0));
  INFO(rgb);
  CHECK(rgb.g > 1.0);
  CHECK(rgb.r < 0.0);
  CHECK(rgb.b < 0.0);
}

TEST_CASE("Matrix3: the inverse times the matrix is the identity, and a singular matrix is refused", "[color][rgb]") {
  constexpr double kRoundoff = 1e-14;  // a 3x3 with entries of order 1: a few ulps
  const Matrix3 product = kRec709FromXyz.inverse() * kRec709FromXyz;
  const Matrix3 identity = Matrix3::identity();
  INFO(product);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) CHECK_THAT(product.m[i][j], WithinAbs(identity.m[i][j], kRoundoff));
  const Matrix3 singular{{{{1.0, 2.0, 3.0}, {2.0, 4.0, 6.0}, {0.0, 1.0, 1.0}}}};
  CHECK_THROWS_AS(singular.inverse(), ComputationError);
}
