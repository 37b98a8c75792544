// Zemax .agf glass catalogues (GlassCatalog::from_agf) against the same glasses in lensmith's
// catalogues and against the dispersion formulas as the OpticStudio manual writes them.
#include <catch2/catch.hpp>

#include <cmath>
#include <string>

#include "lensmith/core/errors.h"
#include "lensmith/glass/glass_catalog.h"

using Catch::Matchers::Contains;
using Catch::Matchers::WithinRel;
using lensmith::Glass;
using lensmith::GlassCatalog;
using lensmith::FileError;

namespace {

// One glass in AGF form: NM name formula MIL nd Vd exclude status melt, CD, LD.
std::string agf(const std::string& name, int formula, const std::string& coefficients, const std::string& range = "0.3 2.5") {
  return "NM " + name + " " + std::to_string(formula) + " 0 1.5 50 0 0 0\nED 7 8 2.5 0 0\nCD " + coefficients + "\nLD " + range + "\n";
}

double n_of(const std::string& text, double wavelength_nm) {
  return GlassCatalog::from_agf(text, "t.agf", "T").glasses().front().index(wavelength_nm);
}

}  // namespace

TEST_CASE("AGF: SCHOTT's N-BK7 as Sellmeier 1 (formula 2) is the built-in N-BK7", "[glass][agf]") {
  // SCHOTT's data sheet coefficients B1..3, C1..3 (the built-in catalogue holds the same).
  const std::string text = "CC SCHOTT sample\nNM N-BK7 2 517642 1.5168 64.17 0 1 0\n"
                           "CD 1.03961212 0.00600069867 0.231792344 0.0200179144 1.01046945 103.560653 0 0 0 0\nLD 0.3 2.5\n";
  const GlassCatalog catalogue = GlassCatalog::from_agf(text, "schott.agf", "SCHOTT_SAMPLE");
  const Glass& read = catalogue.get("N-BK7");
  const Glass& shipped = GlassCatalog::builtin().get("N-BK7", "SCHOTT");
  for (const double nm : {365.0, 486.1327, 587.5618, 656.2725, 1014.0}) CHECK(read.index(nm) == shipped.index(nm));
  CHECK(read.catalog_nd() == 1.5168);
  CHECK(read.catalog_vd() == 64.17);
  CHECK(read.status() == Glass::Status::Preferred);
  CHECK(read.vendor() == "SCHOTT_SAMPLE");
  CHECK(read.valid_range_nm().min_nm == 300.0);
}

TEST_CASE("AGF: the Schott formula (1) is the polynomial of HOYA's built-in BAC4", "[glass][agf]") {
  // HOYA BAC4: n^2 = A0 + A1 l^2 + A2 l^-2 + A3 l^-4 + A4 l^-6 + A5 l^-8 (the built-in data).
  const std::string text = agf("BAC4", 1, "2.4196645 -0.0083329314 0.01539739 -0.00017391654 6.218322e-05 -3.062131e-06 0 0 0 0", "0.36501 1.01398");
  const Glass& shipped = GlassCatalog::builtin().get("BAC4", "HOYA");
  for (const double nm : {400.0, 587.5618, 900.0}) CHECK_THAT(n_of(text, nm), WithinRel(shipped.index(nm), 1e-15));
}

TEST_CASE("AGF: every formula evaluates as the OpticStudio manual writes it", "[glass][agf]") {
  const double l = 0.55, l2 = l * l;  // micrometres
  SECTION("3 Herzberger") {
    const double L = 1.0 / (l2 - 0.028);
    const double n = 1.5 + 0.004 * L + 0.0001 * L * L - 0.002 * l2 + 1e-5 * l2 * l2 + 1e-6 * l2 * l2 * l2;
    CHECK_THAT(n_of(agf("H", 3, "1.5 0.004 0.0001 -0.002 1e-5 1e-6 0 0 0 0"), 550.0), WithinRel(n, 1e-14));
  }
  SECTION("4 Sellmeier 2") {
    const double n = std::sqrt(1.0 + 0.02 + 1.1 * l2 / (l2 - 0.09 * 0.09) + 0.01 / (l2 - 10.0 * 10.0));
    CHECK_THAT(n_of(agf("S2", 4, "0.02 1.1 0.09 0.01 10 0 0 0 0 0"), 550.0), WithinRel(n, 1e-14));
  }
  SECTION("5 Conrady") {
    const double n = 1.48 + 0.01 / l + 0.0005 / std::pow(l, 3.5);
    CHECK_THAT(n_of(agf("C", 5, "1.48 0.01 0.0005 0 0 0 0 0 0 0"), 550.0), WithinRel(n, 1e-14));
  }
  SECTION("6 Sellmeier 3 and 11 Sellmeier 5: more terms of Sellmeier 1") {
    const double n3 = std::sqrt(1.0 + 1.0 * l2 / (l2 - 0.006) + 0.2 * l2 / (l2 - 0.02) + 1.0 * l2 / (l2 - 100.0) + 0.01 * l2 / (l2 - 200.0));
    CHECK_THAT(n_of(agf("S3", 6, "1 0.006 0.2 0.02 1 100 0.01 200 0 0"), 550.0), WithinRel(n3, 1e-14));
    const double n5 = std::sqrt(n3 * n3 + 0.001 * l2 / (l2 - 300.0));
    CHECK_THAT(n_of(agf("S5", 11, "1 0.006 0.2 0.02 1 100 0.01 200 0.001 300"), 550.0), WithinRel(n5, 1e-14));
  }
  SECTION("7 and 8 Handbook of Optics") {
    const double n1 = std::sqrt(2.2 + 0.01 / (l2 - 0.02) - 0.01 * l2), n2 = std::sqrt(2.2 + 0.01 * l2 / (l2 - 0.02) - 0.01 * l2);
    CHECK_THAT(n_of(agf("H1", 7, "2.2 0.01 0.02 0.01 0 0 0 0 0 0"), 550.0), WithinRel(n1, 1e-14));
    CHECK_THAT(n_of(agf("H2", 8, "2.2 0.01 0.02 0.01 0 0 0 0 0 0"), 550.0), WithinRel(n2, 1e-14));
  }
  SECTION("9 Sellmeier 4: n^2 = A + ... (A = 1 is Sellmeier 1's two terms)") {
    CHECK_THAT(n_of(agf("S4", 9, "1 1.04 0.006 0.23 0.02 0 0 0 0 0"), 550.0),
               WithinRel(n_of(agf("S1", 2, "1.04 0.006 0.23 0.02 0 0 0 0 0 0"), 550.0), 1e-15));
  }
  SECTION("10, 12, 13: extended polynomials") {
    const double e1 = std::sqrt(2.3 - 0.01 * l2 + 0.01 / l2 + 1e-4 / (l2 * l2) + 1e-5 / std::pow(l, 6) + 1e-6 / std::pow(l, 8) + 1e-7 / std::pow(l, 10) +
                                1e-8 / std::pow(l, 12));
    CHECK_THAT(n_of(agf("E1", 10, "2.3 -0.01 0.01 1e-4 1e-5 1e-6 1e-7 1e-8 0 0"), 550.0), WithinRel(e1, 1e-14));
    const double e2 = std::sqrt(2.3 - 0.01 * l2 + 0.01 / l2 + 1e-4 / (l2 * l2) + 1e-5 / std::pow(l, 6) + 1e-6 / std::pow(l, 8) + 1e-3 * l2 * l2 +
                                1e-4 * std::pow(l, 6));
    CHECK_THAT(n_of(agf("E2", 12, "2.3 -0.01 0.01 1e-4 1e-5 1e-6 1e-3 1e-4 0 0"), 550.0), WithinRel(e2, 1e-14));
    const double e3 = std::sqrt(2.3 - 0.01 * l2 + 1e-3 * l2 * l2 + 0.01 / l2 + 1e-4 / (l2 * l2) + 1e-5 / std::pow(l, 6) + 1e-6 / std::pow(l, 8) +
                                1e-7 / std::pow(l, 10) + 1e-8 / std::pow(l, 12));
    CHECK_THAT(n_of(agf("E3", 13, "2.3 -0.01 1e-3 0.01 1e-4 1e-5 1e-6 1e-7 1e-8 0"), 550.0), WithinRel(e3, 1e-14));
  }
}

TEST_CASE("AGF: malformed records are errors at their line, saying what was expected", "[glass][agf]") {
  const auto error_line = [](const std::string& text) {
    try {
      (void)GlassCatalog::from_agf(text, "bad.agf", "BAD");
    } catch (const FileError& e) {
      return e.where().line;
    }
    FAIL("expected a FileError");
    return -1;
  };
  CHECK(error_line("CC ok\nNM G 14 0 1.5 50 0 0 0\nCD 1\nLD 0.4 0.7\n") == 2);   // no formula 14
  CHECK(error_line("CD 1 2 3\n") == 1);                                           // coefficients of no glass
  CHECK(error_line(agf("G", 2, "1 0.006 0 0 0 0 0 0 0 0", "0.7 0.4")) == 4);      // range backwards
  CHECK(error_line("NM G 2 0 1.5 50 0 0 0\nLD 0.4 0.7\n") == 1);                  // no CD line
  CHECK(error_line(agf("G", 2, "1 x 0 0 0 0 0 0 0 0")) == 3);                     // not a number
  CHECK(error_line("NM G 2 0 1.5 50 0 0 0\nXX 1\n") == 2);                        // unknown record
  CHECK_THROWS_WITH(GlassCatalog::from_agf("CC only a comment\n", "empty.agf", "E"), Contains("no glass"));
}
