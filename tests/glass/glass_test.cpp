// Glass: dispersion formulas 1-3 against hand-computed values and SCHOTT's published N-BK7 indices,
// the Cauchy model glass, constant indices and air, and the range policy of index_checked().
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "lensmith/core/errors.h"
#include "lensmith/core/units.h"
#include "lensmith/glass/glass.h"
#include "lensmith/glass/glass_catalog.h"

using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;
using lensmith::Glass;
using lensmith::GlassCatalog;
using lensmith::GlassError;
using lensmith::WavelengthRange;

namespace {

// Formulas 1-3 are a handful of double operations: hand-computed values agree to round-off.
constexpr double kRoundOff = 1e-14;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
const WavelengthRange kVisibleNm{400.0, 700.0};

Glass make(Glass::Formula formula, std::vector<double> coefficients) {
  return Glass::from_formula("TEST", "LAB", formula, std::move(coefficients), kVisibleNm, kNaN, kNaN);
}

}  // namespace

TEST_CASE("formula 1 (Sellmeier): n^2 - 1 = C1 + sum C(2i) l^2 / (l^2 - C(2i+1)^2)", "[glass]") {
  // At l = 1 um with C = {0, 1, 0.5}: n^2 - 1 = 1 / (1 - 0.25) = 4/3, so n^2 = 7/3.
  const Glass g = make(Glass::Formula::Sellmeier, {0.0, 1.0, 0.5});
  CHECK_THAT(g.index(1000.0), WithinRel(std::sqrt(7.0 / 3.0), kRoundOff));
  // C1 adds to n^2 directly: {0.25, 1, 0.5} gives n^2 = 1 + 0.25 + 4/3.
  const Glass offset = make(Glass::Formula::Sellmeier, {0.25, 1.0, 0.5});
  CHECK_THAT(offset.index(1000.0), WithinRel(std::sqrt(1.25 + 4.0 / 3.0), kRoundOff));
}

TEST_CASE("formula 2 (Sellmeier-2): the pole term is C(2i+1), not its square", "[glass]") {
  // Same coefficients as the formula 1 test: n^2 - 1 = 1 / (1 - 0.5) = 2, so n = sqrt(3).
  const Glass g = make(Glass::Formula::Sellmeier2, {0.0, 1.0, 0.5});
  CHECK_THAT(g.index(1000.0), WithinRel(std::sqrt(3.0), kRoundOff));
  // Two terms at l = 0.5 um: 1 + 0.5 * 0.25 / (0.25 - 0.05) + 2 * 0.25 / (0.25 - 0.125) = 5.625.
  const Glass two = make(Glass::Formula::Sellmeier2, {0.0, 0.5, 0.05, 2.0, 0.125});
  CHECK_THAT(two.index(500.0), WithinRel(std::sqrt(5.625), kRoundOff));
}

TEST_CASE("formula 3 (polynomial): n^2 = C1 + sum C(2i) l^C(2i+1)", "[glass]") {
  // At l = 0.5 um: n^2 = 2 + 0.25 * 0.5^2 + 0.01 * 0.5^-2 = 2.1025 = 1.45^2.
  const Glass g = make(Glass::Formula::Polynomial, {2.0, 0.25, 2.0, 0.01, -2.0});
  CHECK_THAT(g.index(500.0), WithinRel(1.45, kRoundOff));
  // A non-integer exponent takes the std::pow path: at l = 4 um, 2 + 0.25 * 4^0.5 = 2.5.
  const Glass root = make(Glass::Formula::Polynomial, {2.0, 0.25, 0.5});
  CHECK_THAT(root.index(4000.0), WithinRel(std::sqrt(2.5), kRoundOff));
}

TEST_CASE("a formula needs C1 followed by pairs: an even coefficient count is an error", "[glass]") {
  CHECK_THROWS_AS(make(Glass::Formula::Sellmeier2, {0.0, 1.0, 0.5, 2.0}), GlassError);
  CHECK_THROWS_WITH(make(Glass::Formula::Sellmeier2, {0.0, 1.0, 0.5, 2.0}),
                    Catch::Contains("LAB TEST") && Catch::Contains("odd count") && Catch::Contains("got 4"));
  CHECK_THROWS_WITH(make(Glass::Formula::Polynomial, {}), Catch::Contains("got 0"));
}

TEST_CASE("from_formula accepts only catalogue formulas, finite coefficients and a positive range", "[glass]") {
  CHECK_THROWS_WITH(make(Glass::Formula::ModelCauchy, {1.5}), Catch::Contains("formula 100"));
  CHECK_THROWS_WITH(make(Glass::Formula::Sellmeier2, {0.0, kNaN, 0.5}), Catch::Contains("C2"));
  CHECK_THROWS_WITH(Glass::from_formula("X", "LAB", Glass::Formula::Sellmeier2, {1.0}, {700.0, 400.0}, kNaN, kNaN),
                    Catch::Contains("700-400 nm") && Catch::Contains("0 < min < max"));
  CHECK_THROWS_AS(Glass::from_formula("", "LAB", Glass::Formula::Sellmeier2, {1.0}, kVisibleNm, kNaN, kNaN), GlassError);
}

TEST_CASE("N-BK7 reproduces SCHOTT's published indices from the ultraviolet to the infrared", "[glass]") {
  // SCHOTT optical glass data sheet N-BK7 (2017, refractiveindex.info download schott_2017-01-20.pdf),
  // "Refractive Indices" table. The sheet prints 5 decimals (rounding 5e-6); SCHOTT's Sellmeier
  // fit adds a few 1e-6 (measured worst here 4.6e-6, at g).
  constexpr double kDatasheetDigits = 1e-5;
  struct Line {
    const char* name;
    double wavelength_nm;
    double n;
  };
  const Line lines[] = {
      {"i", 365.0146, 1.53627},   {"h", 404.6561, 1.53024},    {"g", 435.8343, 1.52668},
      {"F'", 479.9914, 1.52283},  {"F", 486.1327, 1.52238},    {"e", 546.0740, 1.51872},
      {"d", 587.5618, 1.51680},   {"He-Ne 632.8", 632.8, 1.51509}, {"C'", 643.8469, 1.51472},
      {"C", 656.2725, 1.51432},   {"r", 706.5188, 1.51289},    {"s", 852.11, 1.50980},
      {"t", 1013.98, 1.50731},    {"Nd:YAG 1060", 1060.0, 1.50669}, {"1529.6", 1529.582, 1.50091},
  };
  const Glass& bk7 = GlassCatalog::builtin().get("N-BK7", "SCHOTT");
  for (const Line& line : lines) {
    INFO("N-BK7 at the " << line.name << " line, " << line.wavelength_nm << " nm");
    CHECK_THAT(bk7.index_checked(line.wavelength_nm), WithinAbs(line.n, kDatasheetDigits));
  }
  // The data sheet's principal dispersion nF - nC = 0.008054 (6 decimals printed).
  CHECK_THAT(bk7.principal_dispersion(), WithinAbs(0.008054, 1e-6));
}

TEST_CASE("index_checked throws outside the catalogue range, naming glass, wavelength and range", "[glass]") {
  const Glass& bk7 = GlassCatalog::builtin().get("N-BK7");
  REQUIRE(bk7.valid_range_nm() == WavelengthRange{300.0, 2500.0});
  CHECK_THROWS_AS(bk7.index_checked(250.0), GlassError);
  CHECK_THROWS_WITH(bk7.index_checked(250.0),
                    Catch::Contains("SCHOTT N-BK7") && Catch::Contains("250 nm") && Catch::Contains("300-2500 nm"));
  CHECK_THROWS_WITH(bk7.index_checked(2600.0), Catch::Contains("2600 nm") && Catch::Contains("300-2500 nm"));
  // The range is inclusive, and index() still answers outside it (it extrapolates).
  CHECK(bk7.covers(300.0));
  CHECK(bk7.covers(2500.0));
  CHECK_FALSE(bk7.covers(299.999));
  CHECK(bk7.index_checked(300.0) == bk7.index(300.0));
  CHECK(std::isfinite(bk7.index(250.0)));
}

TEST_CASE("a catalogue range given in micrometres includes its printed end points in nanometres", "[glass]") {
  // HIKARI's i-line glasses start at 0.32611 um; 0.32611 * 1000 is not exactly 326.11 in binary.
  const Glass& iline = GlassCatalog::builtin().get("4786", "HIKARI");
  CHECK(iline.valid_range_nm().min_nm == 326.11);
  CHECK(iline.covers(326.11));
  CHECK_NOTHROW(iline.index_checked(326.11));
}

TEST_CASE("model glass: Cauchy n = A + B / l^2 reproduces nd and Vd exactly", "[glass][model]") {
  // Solving two linear equations leaves only round-off.
  constexpr double kSolveRoundOff = 1e-12;
  const double cases[][2] = {{1.5168, 64.17}, {1.80518, 25.43}, {1.43875, 94.93}, {1.0, 50.0}, {2.1, 17.0}};
  for (const auto& c : cases) {
    const Glass g = Glass::model(c[0], c[1]);
    INFO(g);
    CHECK(g.formula() == Glass::Formula::ModelCauchy);
    CHECK_THAT(g.nd(), WithinRel(c[0], kSolveRoundOff));
    CHECK_THAT(g.principal_dispersion(), WithinRel((c[0] - 1.0) / c[1], kSolveRoundOff));
    if (c[0] > 1.0) CHECK_THAT(g.vd(), WithinRel(c[1], kSolveRoundOff));
    CHECK(g.covers(200.0));
    CHECK(g.covers(5000.0));
    CHECK(g.catalog_nd() == c[0]);
    CHECK(g.catalog_vd() == c[1]);
    // Normal dispersion: the index falls with wavelength.
    CHECK(g.index(450.0) >= g.index(650.0));
  }
}

TEST_CASE("model glass: nd < 1, Vd <= 0 and non-finite values are errors naming the field", "[glass][model]") {
  CHECK_THROWS_WITH(Glass::model(0.9, 50.0), Catch::Contains("nd = 0.9: must be >= 1"));
  CHECK_THROWS_WITH(Glass::model(1.5, 0.0), Catch::Contains("Vd = 0: must be > 0"));
  CHECK_THROWS_AS(Glass::model(1.5, -30.0), GlassError);
  CHECK_THROWS_AS(Glass::model(kNaN, 50.0), GlassError);
  CHECK_THROWS_AS(Glass::model(1.5, std::numeric_limits<double>::infinity()), GlassError);
}

TEST_CASE("model glass is within a stated error of every real catalogue glass at 450 and 650 nm", "[glass][model]") {
  // The model is built from each glass's own formula nd and Vd, so the difference is only the
  // Cauchy shape versus the real dispersion curve. Bounds are the measured worst cases over the
  // built-in catalogues (all glasses whose formula covers 450-656 nm), rounded up:
  constexpr double kCrownBound = 2e-4;   // Vd >= 50: 657 glasses, worst 1.52e-4 (OHARA FTL8)
  constexpr double kMiddleBound = 1e-3;  // 35 <= Vd < 50: 597 glasses, worst 8.70e-4 (OHARA S-LAH93)
  constexpr double kFlintBound = 7e-3;   // Vd < 35: 373 glasses, worst 6.63e-3 (OHARA L-BBH1)
  std::size_t compared = 0;
  for (const Glass& real : GlassCatalog::builtin().glasses()) {
    if (!real.covers(450.0) || !real.covers(lensmith::kWavelengthC_nm)) continue;
    const Glass model = Glass::model(real.nd(), real.vd());
    const double vd = real.vd();
    const double bound = vd >= 50.0 ? kCrownBound : vd >= 35.0 ? kMiddleBound : kFlintBound;
    INFO(real << ": model " << model << ", bound " << bound);
    CHECK_THAT(model.index(450.0), WithinAbs(real.index(450.0), bound));
    CHECK_THAT(model.index(650.0), WithinAbs(real.index(650.0), bound));
    ++compared;
  }
  CHECK(compared == 1639);  // the vendors' 1627, SCHOTT B 270 and MISC's 11 (crystals and plastics)
  // N-BK7, the usual stand-in: the model is within 1e-4 at both ends (measured 9.1e-5 and 4.5e-5).
  const Glass& bk7 = GlassCatalog::builtin().get("N-BK7");
  const Glass model = Glass::model(1.5168, 64.17);
  CHECK_THAT(model.index(450.0), WithinAbs(bk7.index(450.0), 1e-4));
  CHECK_THAT(model.index(650.0), WithinAbs(bk7.index(650.0), 1e-4));
}

TEST_CASE("constant index: the same n at every wavelength, infinite Vd, no range", "[glass]") {
  const Glass g = Glass::constant(1.5, "pbrt element 2");
  CHECK(g.index(400.0) == 1.5);
  CHECK(g.index(1000.0) == 1.5);
  CHECK(g.index_checked(10.0) == 1.5);
  CHECK(g.covers(1e6));
  CHECK(g.nd() == 1.5);
  CHECK(g.principal_dispersion() == 0.0);
  CHECK(std::isinf(g.vd()));
  CHECK(g.name() == "pbrt element 2");
  CHECK_FALSE(g.is_air());
  CHECK(g.to_string() == "pbrt element 2 (constant n = 1.5)");
  CHECK(Glass::constant(1.523).to_string() == "constant n = 1.523");
  CHECK_THROWS_WITH(Glass::constant(0.0), Catch::Contains("must be finite and > 0"));
  CHECK_THROWS_AS(Glass::constant(-1.5), GlassError);
  CHECK_THROWS_AS(Glass::constant(kNaN), GlassError);
}

TEST_CASE("air is n = 1 everywhere and is the only glass for which is_air() holds", "[glass]") {
  const Glass air = Glass::air();
  CHECK(air.is_air());
  CHECK(air.name() == "air");
  CHECK(air.index(300.0) == 1.0);
  CHECK(air.index_checked(20000.0) == 1.0);
  CHECK(std::isinf(air.vd()));
  CHECK(air == Glass::air());
  // An index of 1 that was not declared as air is a constant, not air.
  CHECK_FALSE(Glass::constant(1.0).is_air());
  CHECK_FALSE(Glass::model(1.0, 50.0).is_air());
  CHECK_FALSE(GlassCatalog::builtin().get("N-BK7").is_air());
}

TEST_CASE("a glass equals its copy, also when the catalogue gives no nd (NaN)", "[glass]") {
  const Glass& lf7 = GlassCatalog::builtin().get("LF7", "SCHOTT");
  REQUIRE(std::isnan(lf7.catalog_nd()));
  const Glass copy = lf7;
  CHECK(copy == lf7);
  CHECK_FALSE(copy == GlassCatalog::builtin().get("LF7", "HIKARI"));
  CHECK_FALSE(Glass::model(1.5168, 64.17) == Glass::model(1.5168, 64.2));
}

TEST_CASE("glasses print vendor, name, formula, range and catalogue nd, Vd", "[glass]") {
  const GlassCatalog& catalogue = GlassCatalog::builtin();
  CHECK(catalogue.get("N-BK7").to_string() == "SCHOTT N-BK7 (formula 2, 300-2500 nm, nd 1.51680, Vd 64.17)");
  CHECK(catalogue.get("SF15", "SCHOTT").to_string() ==
        "SCHOTT SF15 (formula 2, 370-2500 nm, nd 1.69895, Vd 30.07, obsolete, replaced by N-SF15)");
  // Without catalogue values, nd and Vd come from the formula and say so.
  CHECK(catalogue.get("LF7").to_string() ==
        "SCHOTT LF7 (formula 2, 334-700 nm, nd 1.57501, Vd 41.49 from the formula, obsolete)");
  // An infrared glass whose formula does not reach the d line prints no nd at all.
  CHECK(catalogue.get("IRG23").to_string() == "SCHOTT IRG23 (formula 1, 1000-12000 nm)");
  CHECK(Glass::model(1.5168, 64.17).to_string() == "model glass (Cauchy from nd 1.51680, Vd 64.17)");
  CHECK(Glass::air().to_string() == "air (constant n = 1)");
}
