// Zemax .zmx reader: one test per rule. The Sasian triplet is checked against its published table
// (ray-optics docs, SasianTriplet.rst; ../shared/lens-data/REFERENCE-VALUES.md section 2) and
// Smith's Cooke triplet against Modern Optical Engineering, 4th ed., ch. 6 (section 1 there).
#include "lensmith/prescription/zemax_reader.h"

#include <catch2/catch.hpp>
#include <cmath>
#include <stdexcept>
#include <string>

#include "lensmith/core/errors.h"
#include "lensmith/core/text_file.h"
#include "lens_file_checks.h"

using Catch::Matchers::Contains;
using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;
using namespace lensmith;
using lensmith::testing::has_diagnostic;
using lensmith::testing::line_of;

namespace {

// The test files print 16 significant digits of 1/R; R comes back to a few units in the 15th digit.
constexpr double kPrintedDigits = 1e-13;
// Converting inches to millimetres multiplies by 25.4 and powers of it: a few ulps per step.
constexpr double kUnitConversion = 1e-12;

std::string data_file(const std::string& name) { return std::string(LENSMITH_TEST_DATA_DIR) + "/zemax/" + name; }

LensReadResult read_data(const std::string& name) {
  const std::string path = data_file(name);
  return read_zemax(read_file_bytes(path), path);
}

// A small valid lens in OpticStudio's layout: a stop, an N-BK7 singlet, the image. `system_extra`
// lines go at the end of the system block, `lens_extra` lines into SURF 2 (the singlet's front).
// clang-format off
std::string mini_zmx(const std::string& system_extra = "", const std::string& lens_extra = "",
                     const std::string& object_disz = "INFINITY") {
  return "VERS 190513 80 123457 L123457\n"
         "MODE SEQ\n"
         "NAME MINI\n"
         "UNIT MM X W X CM MR CPMM\n"
         "ENPD 10\n"
         "GCAT SCHOTT\n"
         "FTYP 0 0 2 1 0 0 0\n"
         "XFLN 0 0 0 0\n"
         "YFLN 0 5 0 0\n"
         "WAVM 1 0.5875618 1\n"
         "WAVM 2 0.55 1\n"
         "PWAV 1\n" +
         system_extra +
         "SURF 0\n"
         "  TYPE STANDARD\n"
         "  CURV 0.0 0 0 0 0 \"\"\n"
         "  DISZ " + object_disz + "\n"
         "SURF 1\n"
         "  STOP\n"
         "  TYPE STANDARD\n"
         "  CURV 0.0 0 0 0 0 \"\"\n"
         "  DISZ 2\n"
         "  DIAM 5 0 0 0 1 \"\"\n"
         "SURF 2\n"
         "  TYPE STANDARD\n"
         "  CURV 0.02 0 0 0 0 \"\"\n"
         "  DISZ 5\n"
         "  GLAS N-BK7 0 0 1.5 40 0 0 0 0 0 0\n"
         "  DIAM 8 1 0 0 1 \"\"\n" +
         lens_extra +
         "SURF 3\n"
         "  TYPE STANDARD\n"
         "  CURV -0.005 0 0 0 0 \"\"\n"
         "  DISZ 90\n"
         "  DIAM 8 1 0 0 1 \"\"\n"
         "SURF 4\n"
         "  TYPE STANDARD\n"
         "  CURV 0.0 0 0 0 0 \"\"\n"
         "  DISZ 0\n";
}
// clang-format on

FileError zemax_error(const std::string& text) {
  try {
    read_zemax(text, "t.zmx");
  } catch (const FileError& e) {
    return e;
  }
  FAIL("expected a FileError");
  throw std::logic_error("unreachable");
}

}  // namespace

TEST_CASE("Zemax: the Sasian triplet reads surface by surface as published", "[prescription][zemax]") {
  const LensReadResult r = read_data("sasian_triplet.zmx");
  const Prescription& p = r.prescription;
  CHECK(r.diagnostics.empty());
  CHECK(p.name == "SASIAN TRIPLET");
  CHECK_THAT(p.notes, Contains("SasianTriplet.rst"));
  struct Row {
    double radius_mm, thickness_mm;
    const char* glass;
    double semi_diameter_mm;
  };
  // ray-optics docs, SasianTriplet.rst (REFERENCE-VALUES.md section 2).
  const Row published[] = {{23.713, 4.831, "N-LAK9", 10.009}, {7331.288, 5.86, "", 8.9482},
                           {-24.456, 0.975, "N-SF5", 4.7919}, {21.896, 4.822, "", 4.7761},
                           {86.759, 3.127, "N-LAK9", 8.0217}, {-20.4942, 41.2365, "", 8.3321}};
  REQUIRE(p.surfaces.size() == 6);
  for (std::size_t i = 0; i < 6; ++i) {
    INFO("surface " << i + 1);
    const Surface& s = p.surfaces[i];
    CHECK_THAT(s.radius_mm(), WithinRel(published[i].radius_mm, kPrintedDigits));
    CHECK(s.thickness_mm == published[i].thickness_mm);
    CHECK(*s.semi_diameter_mm == published[i].semi_diameter_mm);
    if (std::string(published[i].glass).empty()) {
      CHECK(s.material.kind == MaterialSpec::Kind::Air);
    } else {
      CHECK(s.material == MaterialSpec::catalog(published[i].glass, "SCHOTT"));
      CHECK(s.medium.name() == published[i].glass);
    }
    CHECK(s.is_stop == (i == 2));
  }
  CHECK(std::isinf(p.object_distance_mm));
  CHECK_FALSE(p.image_at_paraxial_focus);
  CHECK(p.aperture == ApertureSpec{ApertureSpec::Kind::EntrancePupilDiameter, 12.5});
  REQUIRE(p.field);
  CHECK(p.field->kind == FieldSpec::Kind::AngleDeg);
  CHECK(p.field->values == std::vector<double>{0.0, 14.0, 20.0});
  REQUIRE(p.wavelengths_nm.size() == 3);
  CHECK_THAT(p.wavelengths_nm[0], WithinRel(kWavelengthF_nm, 1e-15));
  CHECK_THAT(p.primary_wavelength_nm(), WithinRel(kWavelengthD_nm, 1e-15));
  CHECK_THAT(p.wavelengths_nm[2], WithinRel(kWavelengthC_nm, 1e-15));
}

TEST_CASE("Zemax: a UTF-16LE file with a byte-order mark reads exactly like its UTF-8 copy", "[prescription][zemax]") {
  const LensReadResult utf8 = read_data("sasian_triplet.zmx");
  const LensReadResult utf16 = read_data("sasian_triplet_utf16.zmx");
  CHECK(utf16.prescription == utf8.prescription);
  CHECK(utf16.diagnostics.size() == utf8.diagnostics.size());
}

TEST_CASE("Zemax: an ANSI (Windows-1252) file reads like its UTF-8 copy, its name decoded to UTF-8", "[prescription][zemax]") {
  // OpticStudio's "ANSI" encoding: NAME with a diameter sign and a degree sign, 0xD8 and 0xB0 in
  // Windows-1252 (U+00D8 and U+00B0), and a right single quote, 0x92 (U+2019).
  std::string ansi = mini_zmx();
  const std::size_t at = ansi.find("NAME MINI");
  ansi.replace(at, 9, "NAME \xD8" "25 mm 45\xB0 lens\x92s");
  const LensReadResult r = read_zemax(ansi, "ansi.zmx");
  CHECK(r.prescription.name == "\xC3\x98" "25 mm 45\xC2\xB0 lens\xE2\x80\x99s");
  CHECK(is_valid_utf8(r.prescription.name));
  CHECK(r.prescription.surfaces == read_zemax(mini_zmx(), "t.zmx").prescription.surfaces);
}

TEST_CASE("Zemax: UTF-16LE without a byte-order mark is recognised by its zero bytes", "[prescription][zemax]") {
  const std::string plain = mini_zmx();
  std::string utf16;
  for (const char c : plain) utf16 += std::string{c, '\0'};
  CHECK(read_zemax(utf16, "t.zmx").prescription == read_zemax(plain, "t.zmx").prescription);
}

TEST_CASE("UTF-8 validation follows RFC 3629: overlong forms, surrogates and bytes past U+10FFFF are not UTF-8", "[core][text]") {
  CHECK(is_valid_utf8("plain ASCII"));
  CHECK(is_valid_utf8("\xC3\x98 \xE2\x82\xAC \xF0\x9F\x93\xB7"));  // Ø € 📷
  CHECK_FALSE(is_valid_utf8("\xD8" "25"));                                // Windows-1252 Ø
  CHECK_FALSE(is_valid_utf8("\xC0\xAF"));                                // overlong '/'
  CHECK_FALSE(is_valid_utf8("\xED\xA0\x80"));                           // a surrogate, U+D800
  CHECK_FALSE(is_valid_utf8("\xF4\x90\x80\x80"));                      // U+110000
  CHECK_FALSE(is_valid_utf8("\xE2\x82"));                                // cut off
}

TEST_CASE("Zemax: a UTF-8 byte-order mark is skipped", "[prescription][zemax]") {
  const std::string plain = mini_zmx();
  CHECK(read_zemax("\xEF\xBB\xBF" + plain, "t.zmx").prescription == read_zemax(plain, "t.zmx").prescription);
}

TEST_CASE("Zemax: GLAS ___BLANK is a model glass from the nd and Vd on its line, without a warning",
          "[prescription][zemax]") {
  // Smith's Cooke triplet with SK4 (nd 1.61272, dn 0.010450) and SF2 (nd 1.64769, dn 0.019151).
  const LensReadResult r = read_data("smith_cooke_triplet.zmx");
  CHECK(r.diagnostics.empty());
  const Prescription& p = r.prescription;
  REQUIRE(p.surfaces.size() == 7);
  const MaterialSpec& sk4 = p.surfaces[0].material;
  CHECK(sk4.kind == MaterialSpec::Kind::Model);
  CHECK(sk4.nd == 1.61272);
  REQUIRE(sk4.vd);
  CHECK_THAT(*sk4.vd, WithinRel(0.61272 / 0.010450, 1e-15));
  CHECK_THAT(p.surfaces[0].medium.principal_dispersion(), WithinRel(0.010450, 1e-9));
  CHECK_THAT(p.surfaces[2].medium.principal_dispersion(), WithinRel(0.019151, 1e-9));
  CHECK(p.surfaces[4].is_stop);
  CHECK(p.surfaces[4].is_plane());
  CHECK(p.surfaces[6].thickness_mm == 77.405);  // Smith's BFL: the last DISZ is the image distance
}

TEST_CASE("Zemax: GLAS ___BLANK with Vd 0 is an index without dispersion", "[prescription][zemax]") {
  std::string text = mini_zmx();
  text.replace(text.find("N-BK7 0 0 1.5 40"), 16, "___BLANK 1 0 1.7 0");
  const Prescription p = read_zemax(text, "t.zmx").prescription;
  CHECK(p.surfaces[1].material == MaterialSpec::model(1.7, std::nullopt));
}

TEST_CASE("Zemax: EVENASPH PARM 1..8 are the r^2..r^16 coefficients, CONI the conic", "[prescription][zemax]") {
  const Prescription p = read_data("even_asphere_singlet.zmx").prescription;
  REQUIRE(p.surfaces.size() == 3);
  const Surface& s = p.surfaces[1];
  CHECK(s.conic == -0.62);
  CHECK(s.even_asphere[0] == 2.0e-5);
  CHECK(s.even_asphere[1] == -1.25e-6);
  CHECK(s.even_asphere[2] == 3.4e-10);
  CHECK(s.even_asphere[3] == -2.2e-13);
  CHECK(s.even_asphere[4] == 0.0);
  CHECK(s.comment == "aspheric front");
  CHECK(p.surfaces[0].comment == "stop in front");
  CHECK_FALSE(p.surfaces[2].has_asphere());
}

TEST_CASE("Zemax: UNIT IN converts lengths, curvatures and aspheric coefficients to millimetres",
          "[prescription][zemax]") {
  const Prescription mm = read_data("even_asphere_singlet.zmx").prescription;
  const Prescription inch = read_data("even_asphere_singlet_inch.zmx").prescription;
  REQUIRE(inch.surfaces.size() == mm.surfaces.size());
  for (std::size_t i = 0; i < mm.surfaces.size(); ++i) {
    INFO("surface " << i + 1);
    const Surface& a = inch.surfaces[i];
    const Surface& b = mm.surfaces[i];
    CHECK_THAT(a.curvature_per_mm, WithinRel(b.curvature_per_mm, kUnitConversion));
    CHECK_THAT(a.thickness_mm, WithinRel(b.thickness_mm, kUnitConversion));
    CHECK_THAT(*a.semi_diameter_mm, WithinRel(*b.semi_diameter_mm, kUnitConversion));
    for (std::size_t j = 0; j < a.even_asphere.size(); ++j) {
      INFO("r^" << 2 * (j + 1) << " term");
      CHECK_THAT(a.even_asphere[j], WithinRel(b.even_asphere[j], kUnitConversion));
    }
  }
  CHECK_THAT(inch.aperture.value, WithinRel(20.0, kUnitConversion));
  CHECK(inch.field == mm.field);  // angles do not scale
}

TEST_CASE("Zemax: an unknown UNIT is an error naming it", "[prescription][zemax]") {
  const std::string text = mini_zmx("UNIT FURLONG\n");
  const FileError e = zemax_error(text);
  CHECK(e.where().line == line_of(text, "UNIT FURLONG"));
  CHECK_THAT(e.what(), Contains("FURLONG"));
}

TEST_CASE("Zemax: a STOP on a coordinate break is an error naming its line", "[prescription][zemax]") {
  const std::string path = data_file("coordbrk.zmx");
  try {
    read_zemax(read_file_bytes(path), path);
    FAIL("expected a FileError");
  } catch (const FileError& e) {
    CHECK(e.where().file == path);
    CHECK(e.where().line == 15);  // the STOP line of SURF 1, a COORDBRK
    CHECK_THAT(e.what(), Contains("coordinate break"));
  }
}

TEST_CASE("Zemax: a surface type other than STANDARD, EVENASPH, TOROIDAL, BICONICX and COORDBRK is refused", "[prescription][zemax]") {
  for (const char* type : {"PARAXIAL", "GRID_SAG", "XOSPHERE", "BICONICZ"}) {
    std::string text = mini_zmx();
    text.replace(text.find("  TYPE STANDARD\n  CURV 0.02"), 15, std::string("  TYPE ") + type);
    const FileError e = zemax_error(text);
    CHECK(e.where().line == line_of(text, std::string("TYPE ") + type));
    CHECK_THAT(e.what(), Contains(type));
  }
}

TEST_CASE("Zemax: COORDBRK reads its decentres, tilts and order from PARM 1-6", "[prescription][zemax]") {
  std::string text = mini_zmx();
  text.replace(text.find("SURF 3\n"), 7,
               "SURF 3\n  TYPE COORDBRK\n  CURV 0.0 0 0.0 0.0 0\n  PARM 1 1.5\n  PARM 2 -2\n  PARM 3 45\n  PARM 4 -3\n"
               "  PARM 5 10\n  PARM 6 1\n  DISZ 0\nSURF 99\n");
  text.replace(text.find("SURF 99"), 7, "SURF 4");
  text.replace(text.rfind("SURF 4\n  TYPE STANDARD\n  CURV 0.0"), 6, "SURF 5");
  const Prescription p = read_zemax(text, "t.zmx").prescription;
  REQUIRE(p.surfaces.size() == 4);
  REQUIRE(p.surfaces[2].is_coordinate_break());
  CHECK(p.surfaces[2].coordinate_break == CoordinateBreak{1.5, -2.0, 45.0, -3.0, 10.0, true});
  // A PARM beyond 6 on a break is an error naming it.
  std::string bad = text;
  bad.replace(bad.find("  PARM 6 1\n"), 11, "  PARM 7 1\n");
  CHECK(zemax_error(bad).where().line == line_of(bad, "PARM 7"));
}

TEST_CASE("Zemax: TOROIDAL and BICONICX read their x radius, conic and y terms", "[prescription][zemax]") {
  std::string text = mini_zmx("", "  PARM 1 80\n  PARM 2 1e-5\n");
  text.replace(text.find("  TYPE STANDARD\n  CURV 0.02"), 15, "  TYPE TOROIDAL");
  const Prescription toroid = read_zemax(text, "t.zmx").prescription;
  CHECK(toroid.surfaces[1].kind == SurfaceKind::Toroidal);
  CHECK(toroid.surfaces[1].curvature_x_per_mm == 1.0 / 80.0);
  CHECK(toroid.surfaces[1].even_asphere[0] == 1e-5);  // PARM 2: the y^2 term
  std::string biconic = mini_zmx("", "  PARM 1 0\n  PARM 2 -1\n");
  biconic.replace(biconic.find("  TYPE STANDARD\n  CURV 0.02"), 15, "  TYPE BICONICX");
  const Prescription b = read_zemax(biconic, "t.zmx").prescription;
  CHECK(b.surfaces[1].kind == SurfaceKind::Biconic);
  CHECK(b.surfaces[1].curvature_x_per_mm == 0.0);  // x radius 0: flat in x, a cylinder
  CHECK(b.surfaces[1].conic_x == -1.0);
  // Zernike terms on a toroid are refused.
  std::string zernike = mini_zmx("", "  XDAT 1 3 0 0 1 0 0 \"\"\n");
  zernike.replace(zernike.find("  TYPE STANDARD\n  CURV 0.02"), 15, "  TYPE TOROIDAL");
  CHECK(zemax_error(zernike).where().line == line_of(zernike, "XDAT 1"));
}

TEST_CASE("Zemax: a glass in no catalogue falls back to the nd/Vd on its GLAS line, with a warning",
          "[prescription][zemax]") {
  std::string text = mini_zmx();
  text.replace(text.find("N-BK7 0 0 1.5 40"), 16, "MYGLASS 0 0 1.62 36.3");
  const LensReadResult r = read_zemax(text, "t.zmx");
  CHECK(r.prescription.surfaces[1].material == MaterialSpec::model(1.62, 36.3));
  CHECK(has_diagnostic(r.diagnostics, Diagnostic::Severity::Warning, line_of(text, "MYGLASS"), "MYGLASS"));
}

TEST_CASE("Zemax: a glass in no catalogue and without nd on its line is an error listing close names",
          "[prescription][zemax]") {
  std::string text = mini_zmx();
  text.replace(text.find("N-BK7 0 0 1.5 40 0 0 0 0 0 0"), 28, "NBK7");  // newer OpticStudio writes the name only
  const FileError e = zemax_error(text);
  CHECK(e.where().line == line_of(text, "GLAS NBK7"));
  CHECK_THAT(e.what(), Contains("NBK7") && Contains("closest catalogue names") && Contains("N-BK7"));
}

TEST_CASE("Zemax: OpticStudio's placeholder nd 1.5 / Vd 40 never stands in for an unknown glass",
          "[prescription][zemax]") {
  std::string text = mini_zmx();
  text.replace(text.find("N-BK7 0 0 1.5 40"), 16, "ACME-42 0 0 1.5 40");
  const FileError e = zemax_error(text);
  CHECK(e.where().line == line_of(text, "GLAS ACME-42"));
  CHECK_THAT(e.what(), Contains("ACME-42") && Contains("placeholder"));
}

TEST_CASE("Zemax: an obsolete SCHOTT name is read as its lead-free successor, with a warning naming both", "[prescription][zemax]") {
  std::string text = mini_zmx();
  text.replace(text.find("N-BK7 0 0 1.5 40"), 16, "BK7 0 0 1.5 40");
  const LensReadResult r = read_zemax(text, "t.zmx");
  CHECK(r.prescription.surfaces[1].material == MaterialSpec::catalog("N-BK7", "SCHOTT"));
  REQUIRE(r.diagnostics.size() == 1);
  CHECK_THAT(r.diagnostics[0].message, Contains("\"BK7\" is an obsolete name") && Contains("SCHOTT N-BK7"));
  CHECK(r.diagnostics[0].where.line == line_of(text, "GLAS BK7"));
}

TEST_CASE("Zemax: fused silica, CaF2 and plastics are found by their OpticStudio names", "[prescription][zemax]") {
  for (const char* name : {"F_SILICA", "SILICA", "CAF2", "POLYCARB", "PMMA"}) {
    std::string text = mini_zmx();
    text.replace(text.find("GCAT SCHOTT"), 11, "GCAT SCHOTT MISC");  // OpticStudio's MISC catalogue has them
    text.replace(text.find("N-BK7 0 0 1.5 40"), 16, std::string(name) + " 0 0 1.5 40");
    const LensReadResult r = read_zemax(text, "t.zmx");
    INFO(name);
    CHECK(r.prescription.surfaces[1].material == MaterialSpec::catalog(name, "MISC"));
    CHECK(r.diagnostics.empty());
  }
}

TEST_CASE("Zemax: GCAT sets the vendor searched first", "[prescription][zemax]") {
  // BAF10 is in both the HOYA and the HIKARI catalogue.
  std::string text = mini_zmx();
  text.replace(text.find("GCAT SCHOTT"), 11, "GCAT HIKARI_2019 MISC");
  text.replace(text.find("N-BK7 0 0 1.5 40"), 16, "BAF10 0 0 1.5 40");
  const Prescription p = read_zemax(text, "t.zmx").prescription;
  CHECK(p.surfaces[1].material == MaterialSpec::catalog("BAF10", "HIKARI"));
}

TEST_CASE("Zemax: GLAS MIRROR makes a mirror, in the medium before it", "[prescription][zemax]") {
  std::string text = mini_zmx();
  text.replace(text.find("N-BK7 0 0 1.5 40"), 16, "MIRROR 0 0 1.5 40");
  text.replace(text.find("  DISZ 90\n"), 10, "  DISZ -90\n");
  const Prescription p = read_zemax(text, "t.zmx").prescription;
  CHECK(p.surfaces[1].mirror);
  CHECK(p.surfaces[1].medium.index(550.0) == 1.0);
  CHECK(p.has_mirrors());
}

TEST_CASE("Zemax: MIRR (the mirror substrate drawn) alone does not make a mirror", "[prescription][zemax]") {
  const LensReadResult r = read_zemax(mini_zmx("", "  MIRR 2 0\n"), "t.zmx");
  CHECK(r.diagnostics.empty());
}

TEST_CASE("Zemax: a surface without GLAS is air, and GLAS on SURF 0 is the object medium", "[prescription][zemax]") {
  std::string text = mini_zmx();
  text.replace(text.find("  DISZ INFINITY\n"), 16, "  DISZ 100\n  GLAS ___BLANK 1 0 1.333 55.8\n");
  const Prescription p = read_zemax(text, "t.zmx").prescription;
  CHECK(p.surfaces[0].material.kind == MaterialSpec::Kind::Air);
  CHECK(p.surfaces[2].material.kind == MaterialSpec::Kind::Air);
  CHECK(p.object_material == MaterialSpec::model(1.333, 55.8));
}

TEST_CASE("Zemax: DISZ on SURF 0 is the object distance, INFINITY an object at infinity", "[prescription][zemax]") {
  CHECK(std::isinf(read_zemax(mini_zmx(), "t.zmx").prescription.object_distance_mm));
  CHECK(read_zemax(mini_zmx("", "", "250"), "t.zmx").prescription.object_distance_mm == 250.0);
}

TEST_CASE("Zemax: a negative object distance is an error", "[prescription][zemax]") {
  const std::string text = mini_zmx("", "", "-50");
  const FileError e = zemax_error(text);
  CHECK(e.where().line == line_of(text, "DISZ -50"));
}

TEST_CASE("Zemax: PWAV picks the primary wavelength, counting from 1", "[prescription][zemax]") {
  std::string text = mini_zmx();
  text.replace(text.find("FTYP 0 0 2 1"), 12, "FTYP 0 0 2 2");
  text.replace(text.find("PWAV 1"), 6, "PWAV 2");
  const Prescription p = read_zemax(text, "t.zmx").prescription;
  REQUIRE(p.wavelengths_nm.size() == 2);
  CHECK(p.primary_wavelength_index == 1);
  CHECK_THAT(p.primary_wavelength_nm(), WithinRel(550.0, 1e-15));
}

TEST_CASE("Zemax: PWAV beyond the wavelengths in use is an error", "[prescription][zemax]") {
  std::string text = mini_zmx();
  text.replace(text.find("PWAV 1"), 6, "PWAV 2");  // FTYP says one wavelength is in use
  const FileError e = zemax_error(text);
  CHECK(e.where().line == line_of(text, "PWAV 2"));
}

TEST_CASE("Zemax: old-style WAVL lists the wavelengths in micrometres", "[prescription][zemax]") {
  std::string text = mini_zmx();
  text.replace(text.find("WAVM 1 0.5875618 1\nWAVM 2 0.55 1\n"), 33,
               "WAVL 0.4861327 0.5875618 0.6562725\nWWGT 1 1 1\n");
  text.replace(text.find("FTYP 0 0 2 1"), 12, "FTYP 0 0 2 3");
  text.replace(text.find("PWAV 1"), 6, "PWAV 2");
  const Prescription p = read_zemax(text, "t.zmx").prescription;
  REQUIRE(p.wavelengths_nm.size() == 3);
  CHECK_THAT(p.primary_wavelength_nm(), WithinRel(kWavelengthD_nm, 1e-15));
}

TEST_CASE("Zemax: FTYP 1 gives an object-height field, converted with the lens unit", "[prescription][zemax]") {
  std::string text = mini_zmx("", "", "400");
  text.replace(text.find("FTYP 0"), 6, "FTYP 1");
  text.replace(text.find("UNIT MM"), 7, "UNIT CM");
  const Prescription p = read_zemax(text, "t.zmx").prescription;
  REQUIRE(p.field);
  CHECK(p.field->kind == FieldSpec::Kind::ObjectHeightMm);
  CHECK(p.field->values == std::vector<double>{0.0, 50.0});
  CHECK(p.object_distance_mm == 4000.0);
}

TEST_CASE("Zemax: FTYP 2 gives a paraxial image-height field", "[prescription][zemax]") {
  std::string text = mini_zmx();
  text.replace(text.find("FTYP 0"), 6, "FTYP 2");
  const Prescription p = read_zemax(text, "t.zmx").prescription;
  CHECK(p.field->kind == FieldSpec::Kind::ImageHeightMm);
}

TEST_CASE("Zemax: FTYP 3 gives a real image-height field, in lens units", "[prescription][zemax]") {
  std::string text = mini_zmx();
  text.replace(text.find("FTYP 0"), 6, "FTYP 3");
  text.replace(text.find("UNIT MM"), 7, "UNIT CM");
  const Prescription p = read_zemax(text, "t.zmx").prescription;
  REQUIRE(p.field);
  CHECK(p.field->kind == FieldSpec::Kind::RealImageHeightMm);
  CHECK(p.field->values == std::vector<double>{0.0, 50.0});
}

TEST_CASE("Zemax: FTYP's theodolite angle fields are refused on their line", "[prescription][zemax]") {
  std::string text = mini_zmx();
  text.replace(text.find("FTYP 0"), 6, "FTYP 4");
  const FileError e = zemax_error(text);
  CHECK(e.where().line == line_of(text, "FTYP 4"));
  CHECK_THAT(e.what(), Contains("theodolite"));
}

TEST_CASE("Zemax: FTYP's telecentric flag makes the lens object-space telecentric", "[prescription][zemax]") {
  std::string text = mini_zmx("", "", "400");
  text.replace(text.find("FTYP 0 0"), 8, "FTYP 1 1");
  text.replace(text.find("ENPD 10"), 7, "OBNA 0.05 0");
  const Prescription p = read_zemax(text, "t.zmx").prescription;
  CHECK(p.object_space_telecentric);
}

TEST_CASE("Zemax: a telecentric lens with an entrance-pupil aperture is refused on a located line", "[prescription][zemax]") {
  std::string text = mini_zmx("", "", "400");
  text.replace(text.find("FTYP 0 0"), 8, "FTYP 1 1");
  const FileError e = zemax_error(text);
  CHECK_THAT(e.what(), Contains("telecentric"));
  CHECK(e.where().line == line_of(text, "ENPD"));
}

TEST_CASE("Zemax: XFLN components fold into radial fields with a note", "[prescription][zemax]") {
  std::string text = mini_zmx();
  text.replace(text.find("FTYP 0"), 6, "FTYP 2");
  text.replace(text.find("XFLN 0 0"), 8, "XFLN 0 3");
  text.replace(text.find("YFLN 0 5"), 8, "YFLN 0 4");
  const LensReadResult r = read_zemax(text, "t.zmx");
  CHECK(r.prescription.field->values == std::vector<double>{0.0, 5.0});
  CHECK(has_diagnostic(r.diagnostics, Diagnostic::Severity::Note, line_of(text, "YFLN"), "radial"));
}

TEST_CASE("Zemax: x and y field angles fold into the angle whose tangent is their tangents' length",
          "[prescription][zemax]") {
  std::string text = mini_zmx();
  text.replace(text.find("XFLN 0 0"), 8, "XFLN 0 10");
  text.replace(text.find("YFLN 0 5"), 8, "YFLN 0 10");
  const Prescription p = read_zemax(text, "t.zmx").prescription;
  const double expected = deg_from_rad(std::atan(std::sqrt(2.0) * std::tan(rad_from_deg(10.0))));
  CHECK_THAT(p.field->values[1], WithinRel(expected, 1e-14));
}

TEST_CASE("Zemax: ENPD is the entrance-pupil diameter, FNUM an image-space F/#, FLOA floats by the stop",
          "[prescription][zemax]") {
  CHECK(read_zemax(mini_zmx(), "t.zmx").prescription.aperture ==
        ApertureSpec{ApertureSpec::Kind::EntrancePupilDiameter, 10.0});
  std::string fnum = mini_zmx();
  fnum.replace(fnum.find("ENPD 10"), 7, "FNUM 4.5 0");
  CHECK(read_zemax(fnum, "t.zmx").prescription.aperture == ApertureSpec{ApertureSpec::Kind::ImageSpaceFNumber, 4.5});
  std::string floa = mini_zmx();
  floa.replace(floa.find("ENPD 10"), 7, "FLOA");
  CHECK(read_zemax(floa, "t.zmx").prescription.aperture.kind == ApertureSpec::Kind::FloatByStop);
}

TEST_CASE("Zemax: FNUM type 1 is a paraxial working F/#, OBNA an object-space NA (type 0) or cone angle (type 1)",
          "[prescription][zemax]") {
  std::string working = mini_zmx();
  working.replace(working.find("ENPD 10"), 7, "FNUM 4.5 1");
  CHECK(read_zemax(working, "t.zmx").prescription.aperture == ApertureSpec{ApertureSpec::Kind::ParaxialWorkingFNumber, 4.5});
  std::string na = mini_zmx("", "", "400");
  na.replace(na.find("ENPD 10"), 7, "OBNA 1.5E-1 0");
  CHECK(read_zemax(na, "t.zmx").prescription.aperture == ApertureSpec{ApertureSpec::Kind::ObjectSpaceNA, 0.15});
  std::string cone = mini_zmx("", "", "400");
  cone.replace(cone.find("ENPD 10"), 7, "OBNA 3 1");
  CHECK(read_zemax(cone, "t.zmx").prescription.aperture == ApertureSpec{ApertureSpec::Kind::ObjectConeAngleDeg, 3.0});
}

TEST_CASE("Zemax: an object-space NA with the object at infinity is refused on the OBNA line", "[prescription][zemax]") {
  std::string na = mini_zmx();
  na.replace(na.find("ENPD 10"), 7, "OBNA 1.5E-1 0");
  const FileError e = zemax_error(na);
  CHECK(e.where().line == line_of(na, "OBNA"));
  CHECK_THAT(e.what(), Contains("finite object"));
}

TEST_CASE("Zemax: DIAM sizes a surface without clipping, FLAP makes it a clear aperture (OpticStudio's rule)",
          "[prescription][zemax]") {
  const Prescription plain = read_zemax(mini_zmx(), "t.zmx").prescription;
  CHECK(*plain.surfaces[1].semi_diameter_mm == 8.0);
  CHECK_FALSE(plain.surfaces[1].clips_rays);
  CHECK_FALSE(plain.surfaces[1].aperture);
  const Prescription floating = read_zemax(mini_zmx("", "  FLAP 0 8 0\n"), "t.zmx").prescription;
  CHECK(floating.surfaces[1].clips_rays);
  CHECK(*floating.surfaces[1].semi_diameter_mm == 8.0);
}

TEST_CASE("Zemax: a centred CLAP is the clear semi-diameter, over DIAM", "[prescription][zemax]") {
  const Prescription p = read_zemax(mini_zmx("", "  CLAP 0 6.5 0\n"), "t.zmx").prescription;
  CHECK(*p.surfaces[1].semi_diameter_mm == 6.5);
  CHECK(p.surfaces[1].clips_rays);
  CHECK(*p.surfaces[2].semi_diameter_mm == 8.0);
  CHECK_FALSE(p.surfaces[2].clips_rays);
}

TEST_CASE("Zemax: annular, rectangular and elliptical apertures and obscurations become surface apertures, decentred by OBDC",
          "[prescription][zemax]") {
  using Shape = SurfaceAperture::Shape;
  struct Case {
    const char* lines;
    SurfaceAperture expected;
  };
  const Case cases[] = {
      {"  CLAP 1 6 0\n", {Shape::Circular, false, 1.0, 6.0, 6.0, 0.0, 0.0}},
      {"  OBSC 0 2.5 0\n", {Shape::Circular, true, 0.0, 2.5, 2.5, 0.0, 0.0}},
      {"  SQAP 3 2 0\n  OBDC 0.5 -1\n", {Shape::Rectangular, false, 0.0, 3.0, 2.0, 0.5, -1.0}},
      {"  ELAP 3 2 0\n", {Shape::Elliptical, false, 0.0, 3.0, 2.0, 0.0, 0.0}},
      {"  OBSQ 1 1.5 0\n", {Shape::Rectangular, true, 0.0, 1.0, 1.5, 0.0, 0.0}},
      {"  ELOB 1 0.5 0\n", {Shape::Elliptical, true, 0.0, 1.0, 0.5, 0.0, 0.0}},
  };
  for (const Case& c : cases) {
    INFO(c.lines);
    const Surface s = read_zemax(mini_zmx("", c.lines), "t.zmx").prescription.surfaces[1];
    REQUIRE(s.aperture);
    CHECK(*s.aperture == c.expected);
    CHECK(*s.semi_diameter_mm == 8.0);  // DIAM still sizes the surface
    CHECK_FALSE(s.clips_rays);
  }
}

TEST_CASE("Zemax: two apertures on one surface are refused on the second's line", "[prescription][zemax]") {
  const std::string text = mini_zmx("", "  CLAP 0 6 0\n  OBSC 0 1 0\n");
  const FileError e = zemax_error(text);
  CHECK(e.where().line == line_of(text, "OBSC"));
  CHECK_THAT(e.what(), Contains("CLAP"));
}

TEST_CASE("Zemax: spiders and user-defined apertures are refused, naming the keyword and line", "[prescription][zemax]") {
  for (const char* line : {"  SPID 1 4 0\n", "  UDAD 0 0 0\n"}) {
    const std::string text = mini_zmx("", line);
    INFO(line);
    const FileError e = zemax_error(text);
    CHECK(e.where().line == line_of(text, line));
    CHECK_THAT(e.what(), Contains(std::string(line).substr(2, 4)));
  }
}

TEST_CASE("Zemax: RAIM's second field sets the ray aiming (0 off, 1 paraxial, 2 real)", "[prescription][zemax]") {
  CHECK(read_zemax(mini_zmx(), "t.zmx").prescription.ray_aiming == RayAiming::ParaxialEntrancePupil);
  CHECK(read_zemax(mini_zmx("RAIM 0 0 1 1 0 0 0 0 0\n"), "t.zmx").prescription.ray_aiming == RayAiming::ParaxialEntrancePupil);
  CHECK(read_zemax(mini_zmx("RAIM 0 2 1 1 0 1 0 0 0\n"), "t.zmx").prescription.ray_aiming == RayAiming::RealStop);
  const LensReadResult paraxial_aiming = read_zemax(mini_zmx("RAIM 0 1 1 1 0 0 0 0 0 1\n"), "t.zmx");
  CHECK(paraxial_aiming.prescription.ray_aiming == RayAiming::RealStop);
  CHECK(has_diagnostic(paraxial_aiming.diagnostics, Diagnostic::Severity::Note, line_of(mini_zmx("RAIM 0 1 1 1 0 0 0 0 0 1\n"), "RAIM"),
                       "paraxial ray aiming"));
  const std::string bad = mini_zmx("RAIM 0 7 1 1 0 0 0 0 0\n");
  CHECK(zemax_error(bad).where().line == line_of(bad, "RAIM"));
}

TEST_CASE("Zemax: DIAM 0 leaves a surface unlimited", "[prescription][zemax]") {
  std::string text = mini_zmx();
  text.replace(text.find("  DIAM 8 1 0 0 1 \"\"\nSURF 3"), 19, "  DIAM 0 0 0 0 1 \"\"");
  CHECK_FALSE(read_zemax(text, "t.zmx").prescription.surfaces[1].semi_diameter_mm);
}

TEST_CASE("Zemax: a surface tilt before the surface (SCBD 1) is a coordinate break, others are refused unless zero",
          "[prescription][zemax]") {
  const std::string tilted = mini_zmx("", "  SCBD 1 0 0 0.0 0.0 90 0 0\n");
  const LensReadResult r = read_zemax(tilted, "t.zmx");
  REQUIRE(r.prescription.surfaces.size() == 4);
  CHECK(r.prescription.surfaces[1].is_coordinate_break());
  CHECK(r.prescription.surfaces[1].coordinate_break.tilt_x_deg == 90.0);
  CHECK(r.prescription.surfaces[2].curvature_per_mm == 0.02);
  CHECK(has_diagnostic(r.diagnostics, Diagnostic::Severity::Note, line_of(tilted, "SCBD"), "coordinate break"));
  const std::string after = mini_zmx("", "  SCBD 2 0 0 0.0 0.0 90 0 0\n");
  CHECK(zemax_error(after).where().line == line_of(after, "SCBD"));
  CHECK_NOTHROW(read_zemax(mini_zmx("", "  SCBD 1 0 0 0 0 0 0 0\n"), "t.zmx"));
  const std::string decentred = mini_zmx("", "  DECX 1.906000000000E+02\n");
  CHECK(zemax_error(decentred).where().line == line_of(decentred, "DECX"));
}

TEST_CASE("Zemax: PARM with a non-zero value on a STANDARD surface is an error", "[prescription][zemax]") {
  const std::string text = mini_zmx("", "  PARM 2 1.0E-6\n");
  const FileError e = zemax_error(text);
  CHECK(e.where().line == line_of(text, "PARM 2"));
  CHECK_THAT(e.what(), Contains("EVENASPH"));
  CHECK_NOTHROW(read_zemax(mini_zmx("", "  PARM 2 0\n"), "t.zmx"));
}

TEST_CASE("Zemax: MODE NSC is refused", "[prescription][zemax]") {
  std::string text = mini_zmx();
  text.replace(text.find("MODE SEQ"), 8, "MODE NSC");
  CHECK(zemax_error(text).where().line == 2);
}

TEST_CASE("Zemax: an unknown keyword is a warning naming it and its line, and the file still reads",
          "[prescription][zemax]") {
  const std::string text = mini_zmx("FROB 1 2 3\nFROB 4\n");
  const LensReadResult r = read_zemax(text, "t.zmx");
  REQUIRE(r.diagnostics.size() == 1);
  CHECK(has_diagnostic(r.diagnostics, Diagnostic::Severity::Warning, line_of(text, "FROB"), "FROB"));
}

TEST_CASE("Zemax: a curved image surface is a warning", "[prescription][zemax]") {
  std::string text = mini_zmx();
  const auto image = text.find("SURF 4");
  text.replace(text.find("CURV 0.0", image), 8, "CURV -0.01");
  const LensReadResult r = read_zemax(text, "t.zmx");
  CHECK(has_diagnostic(r.diagnostics, Diagnostic::Severity::Warning, line_of(text, "CURV -0.01"), "curved"));
}

TEST_CASE("Zemax: NOTE lines join into the notes, NOTE 0 pieces continue the same line", "[prescription][zemax]") {
  const std::string text = mini_zmx("NOTE 0 first half of a long li\nNOTE 0 ne\nNOTE 4\nNOTE 0 second line\nNOTE 4\n");
  CHECK(read_zemax(text, "t.zmx").prescription.notes == "first half of a long line\nsecond line");
}

TEST_CASE("Zemax: numbers such as 1.#INF, nan and 1e999 are errors naming their line", "[prescription][zemax]") {
  for (const char* bad : {"1.#INF", "nan", "inf", "1e999", "0x1p3", "4.2E"}) {
    std::string text = mini_zmx();
    text.replace(text.find("CURV 0.02"), 9, std::string("CURV ") + bad);
    INFO(bad);
    const FileError e = zemax_error(text);
    CHECK(e.where().line == line_of(text, std::string("CURV ") + bad));
    CHECK(e.where().column == 8);
  }
}

TEST_CASE("Zemax: DISZ INFINITY on a lens surface is an error", "[prescription][zemax]") {
  std::string text = mini_zmx();
  text.replace(text.find("DISZ 90"), 7, "DISZ INFINITY");
  CHECK(zemax_error(text).where().line == line_of(text, "DISZ INFINITY\n  DIAM 8"));
}

TEST_CASE("Zemax: a second STOP is an error", "[prescription][zemax]") {
  const std::string text = mini_zmx("", "  STOP\n");
  CHECK(zemax_error(text).where().line == line_of(text, "  STOP\nSURF 3"));
}

TEST_CASE("Zemax: SURF blocks out of order are an error, and huge surface numbers are refused",
          "[prescription][zemax]") {
  std::string text = mini_zmx();
  text.replace(text.find("SURF 3"), 6, "SURF 7");
  CHECK(zemax_error(text).where().line == line_of(text, "SURF 7"));
  CHECK_THAT(zemax_error("SURF 0\nSURF 99999999999\n").what(), Contains("surface number"));
}

TEST_CASE("Zemax: a truncated file is an error", "[prescription][zemax]") {
  const std::string path = data_file("truncated.zmx");
  try {
    read_zemax(read_file_bytes(path), path);
    FAIL("expected a FileError");
  } catch (const FileError& e) {
    CHECK_THAT(e.what(), Contains("truncated"));
    CHECK(e.where().line > 0);
  }
}

TEST_CASE("Zemax: binary garbage and empty files are errors, not crashes", "[prescription][zemax]") {
  const std::string garbage("\x89PNG\r\n\x1a\n\0\0\0\rIHDR", 16);
  CHECK_THROWS_AS(read_zemax(garbage, "g.zmx"), FileError);
  CHECK_THROWS_AS(read_zemax("", "e.zmx"), FileError);
  CHECK_THROWS_AS(read_zemax("\xFF\xFE", "bom-only.zmx"), FileError);
  CHECK_THROWS_AS(read_zemax(std::string(100000, 'A'), "long.zmx"), FileError);
}

TEST_CASE("Zemax: a file needs an object, a lens surface and an image surface", "[prescription][zemax]") {
  CHECK_THAT(zemax_error("SURF 0\n  DISZ INFINITY\nSURF 1\n  DISZ 0\n").what(), Contains("at least one lens surface"));
}

TEST_CASE("Zemax: a wavelength used twice is an error naming its WAVM line", "[prescription][zemax]") {
  std::string text = mini_zmx();
  text.replace(text.find("FTYP 0 0 2 1"), 12, "FTYP 0 0 2 2");
  text.replace(text.find("WAVM 2 0.55 1"), 13, "WAVM 2 0.5875618 1");
  const FileError e = zemax_error(text);
  CHECK(e.where().line == line_of(text, "WAVM 2"));
  CHECK_THAT(e.what(), Contains("twice"));
}

TEST_CASE("Zemax: a blank NAME gives the lens the file's name", "[prescription][zemax]") {
  std::string text = mini_zmx();
  text.replace(text.find("NAME MINI"), 9, "NAME ");
  CHECK(read_zemax(text, "lenses/US8427765.zmx").prescription.name == "US8427765");
}

TEST_CASE("Zemax: extra surface data (XDAT) is refused unless its value is zero", "[prescription][zemax]") {
  CHECK_NOTHROW(read_zemax(mini_zmx("", "  XDAT 1 0 0 0\n"), "t.zmx"));
  const std::string text = mini_zmx("", "  XDAT 3 2.5E-3 0 0\n");
  CHECK(zemax_error(text).where().column == 10);
}

TEST_CASE("Zemax: a glass missing from the file's GCAT catalogues is taken from another, with a warning naming both", "[prescription][zemax]") {
  // OpticStudio looks only in the GCAT catalogues. SK4 is no longer in Schott's (N-SK4 is); lensmith
  // finds an SK4 elsewhere and must say whose, not take it silently.
  std::string text = mini_zmx();
  const std::string bk7 = "GLAS N-BK7";
  text.replace(text.find(bk7), bk7.size(), "GLAS SK4");
  const LensReadResult r = read_zemax(text, "t.zmx");
  REQUIRE(r.diagnostics.size() == 1);
  const std::string message = r.diagnostics.front().message;
  INFO(message);
  CHECK(message.find("\"SK4\" is in none of the file's GCAT catalogues (SCHOTT)") != std::string::npos);
  CHECK(message.find("using " + r.prescription.surfaces[1].material.vendor) != std::string::npos);
  // In its GCAT catalogue: no warning.
  CHECK(read_zemax(mini_zmx(), "t.zmx").diagnostics.empty());
}

TEST_CASE("Zemax: a moulding vendor's \"_MOLD\" glass reads as its base glass with a warning", "[prescription][zemax][glass]") {
  std::string text = mini_zmx();
  text.replace(text.find("GLAS N-BK7"), 10, "GLAS L-TIM28_MOLD");
  const LensReadResult r = read_zemax(text, "t.zmx");
  CHECK(r.prescription.surfaces[1].material == MaterialSpec::catalog("L-TIM28", "OHARA"));
  CHECK(has_diagnostic(r.diagnostics, Diagnostic::Severity::Warning, line_of(text, "L-TIM28_MOLD"), "moulded"));
}

TEST_CASE("Zemax: vignetting factors VDXN..VANN become the field's, one set per field in use", "[prescription][zemax]") {
  const std::string text = mini_zmx("VDXN 0 0.01 0 0\nVDYN 0 6.2E-2 0 0\nVCXN 0 2.4E-3 0 0\nVCYN 0 1.5E-1 0 0\nVANN 0 0 0 0\n");
  const LensReadResult r = read_zemax(text, "t.zmx");
  REQUIRE(r.prescription.field);
  REQUIRE(r.prescription.field->vignetting.size() == 2);
  CHECK(r.prescription.field->vignetting[0].is_none());
  CHECK(r.prescription.field->vignetting[1] == VignettingFactors{0.01, 0.062, 0.0024, 0.15, 0.0});
  CHECK(has_diagnostic(r.diagnostics, Diagnostic::Severity::Note, line_of(text, "VANN"), "vignetting factors"));
  // All zero (what OpticStudio writes for an unvignetted lens): none.
  CHECK(read_zemax(mini_zmx("VDYN 0 0 0 0\n"), "t.zmx").prescription.field->vignetting.empty());
  const std::string closed = mini_zmx("VCYN 0 1 0 0\n");
  CHECK_THAT(zemax_error(closed).what(), Contains("closes the pupil"));
}
