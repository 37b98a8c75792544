// The RGB -> spectrum basis: three smooth non-negative functions summing to 1 (a partition of
// unity), so that grey is a flat spectrum and non-negative RGB a non-negative spectrum.
#include "lensmith/color/spectral_basis.h"

#include <catch2/catch.hpp>
#include <limits>

#include "lensmith/core/errors.h"

using Catch::Matchers::WithinAbs;
using namespace lensmith;

namespace {
// b_b + b_g + b_r = (1 - S1) + (S1 - S2) + S2 is exact in real arithmetic; three roundings.
constexpr double kPartitionRoundoff = 1e-15;
}  // namespace

TEST_CASE("spectral basis: b_r + b_g + b_b = 1 at 1000 wavelengths from 380 to 780 nm", "[color][basis]") {
  const SpectralBasis basis;
  for (int i = 0; i < 1000; ++i) {
    const double wavelength_nm = 380.0 + 400.0 * i / 999.0;
    const Rgb b = basis.basis_values(wavelength_nm);
    INFO("lambda " << wavelength_nm << " nm: " << b);
    CHECK_THAT(b.r + b.g + b.b, WithinAbs(1.0, kPartitionRoundoff));
    CHECK(b.r >= 0.0);
    CHECK(b.g >= 0.0);
    CHECK(b.b >= 0.0);
  }
}

TEST_CASE("spectral basis: blue dominates at 450 nm, green at 540 nm, red at 650 nm, equal at the crossovers", "[color][basis]") {
  const SpectralBasis basis;
  const Rgb blue = basis.basis_values(450.0);
  const Rgb green = basis.basis_values(540.0);
  const Rgb red = basis.basis_values(650.0);
  INFO("450 nm " << blue << ", 540 nm " << green << ", 650 nm " << red);
  CHECK(blue.b > 0.9);
  CHECK(green.g > 0.9);
  CHECK(red.r > 0.9);
  // At a crossover the two neighbours are equal up to the far step's tail (exp(-100/12) ~ 2.4e-4).
  constexpr double kFarTail = 1e-3;
  const Rgb bg = basis.basis_values(490.0);
  const Rgb gr = basis.basis_values(590.0);
  INFO("490 nm " << bg << ", 590 nm " << gr);
  CHECK_THAT(bg.b - bg.g, WithinAbs(0.0, kFarTail));
  CHECK_THAT(gr.r - gr.g, WithinAbs(0.0, kFarTail));
}

TEST_CASE("spectral basis: grey (0.18, 0.18, 0.18) is the flat spectrum 0.18", "[color][basis]") {
  constexpr double kRoundoff = 1e-16;  // 0.18 times a partition of unity: a few ulps of 0.18
  const SpectralBasis basis;
  for (int nm = 380; nm <= 780; nm += 5) {
    INFO("lambda " << nm << " nm");
    CHECK_THAT(basis.spectrum_value(Rgb{0.18, 0.18, 0.18}, nm), WithinAbs(0.18, kRoundoff));
  }
}

TEST_CASE("spectral basis: non-negative RGB gives a non-negative spectrum, also for saturated primaries", "[color][basis]") {
  const SpectralBasis basis;
  const Rgb colours[] = {{1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 1.0}, {0.9, 0.0, 0.05}, {0.0, 2.0, 0.0}};
  for (const auto& rgb : colours) {
    for (int tenth_nm = 3800; tenth_nm <= 7800; ++tenth_nm) {
      const double wavelength_nm = tenth_nm / 10.0;
      const double s = basis.spectrum_value(rgb, wavelength_nm);
      if (s < 0.0) FAIL(rgb << " at " << wavelength_nm << " nm: spectrum " << s);
    }
  }
  SUCCEED();
}

TEST_CASE("spectral basis options: each bad field is named with its constraint", "[color][basis]") {
  SpectralBasisOptions o;
  o.green_red_crossover_nm = 480.0;
  CHECK_THROWS_WITH(SpectralBasis(o), Catch::Contains("green_red_crossover_nm = 480") && Catch::Contains("must be >"));
  o = {};
  o.transition_width_nm = 0.0;
  CHECK_THROWS_AS(SpectralBasis(o), OptionsError);
  CHECK_THROWS_WITH(o.validate(), Catch::Contains("transition_width_nm = 0"));
  o = {};
  o.blue_green_crossover_nm = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_AS(o.validate(), OptionsError);
}
