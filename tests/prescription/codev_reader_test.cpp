// CODE V .seq reader: one test per rule. The Sasian triplet and Smith's Cooke triplet are checked
// surface by surface against the shipped lensmith JSON of the same published designs (ray-optics docs,
// SasianTriplet.rst; Smith, Modern Optical Engineering, 4th ed., ch. 6; ../shared/lens-data/
// REFERENCE-VALUES.md sections 1 and 2). Their first-order data: tests/paraxial/codev_first_order_test.cpp.
#include "lensmith/prescription/codev_reader.h"

#include <catch2/catch.hpp>
#include <cmath>
#include <stdexcept>
#include <string>

#include "lensmith/core/errors.h"
#include "lensmith/core/text_file.h"
#include "lensmith/prescription/lens_json.h"
#include "lens_file_checks.h"

using Catch::Matchers::Contains;
using Catch::Matchers::WithinRel;
using namespace lensmith;
using lensmith::testing::has_diagnostic;
using lensmith::testing::line_of;

namespace {

// Converting inches to millimetres multiplies by 25.4 and powers of it: a few ulps per step.
constexpr double kUnitConversion = 1e-12;

std::string data_file(const std::string& name) { return std::string(LENSMITH_TEST_DATA_DIR) + "/codev/" + name; }

LensReadResult read_data(const std::string& name) {
  const std::string path = data_file(name);
  return read_codev(read_file_bytes(path), path);
}

Prescription shipped_lens(const std::string& name) {
  const std::string path = std::string(LENSMITH_SOURCE_DIR) + "/lenses/" + name;
  return read_lens_json(read_file_bytes(path), path).prescription;
}

// A small valid lens as CODE V saves one: a stop, an N-BK7 singlet, the image. `system_extra` goes
// before SO, `lens_extra` after the singlet's front surface (the current surface there).
// clang-format off
std::string mini_seq(const std::string& system_extra = "", const std::string& lens_extra = "",
                     const std::string& object = "SO 0 1e10") {
  return "RDM;LEN \"mini\"\n"
         "TITLE 'MINI'\n"
         "EPD 10\n"
         "DIM M\n"
         "WL 587.5618 550\n"
         "REF 1\n"
         "YAN 0 5\n" +
         system_extra +
         object + "\n"
         "S 0 2\n"
         "  STO\n"
         "S 50 5 NBK7_SCHOTT\n"
         "  CIR 8\n" +
         lens_extra +
         "S -200 90\n"
         "  CIR 8\n"
         "SI 0 0\n"
         "GO\n";
}
// clang-format on

FileError codev_error(const std::string& text) {
  try {
    read_codev(text, "t.seq");
  } catch (const FileError& e) {
    return e;
  }
  FAIL("expected a FileError");
  throw std::logic_error("unreachable");
}

// Replaces the first `from` in `text` by `to` (the test fails loudly when `from` is missing).
std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto pos = text.find(from);
  if (pos == std::string::npos) throw std::logic_error("test text lacks " + from);
  return text.replace(pos, from.size(), to);
}

}  // namespace

TEST_CASE("CODE V: the Sasian triplet reads as the shipped JSON of the same published lens", "[prescription][codev]") {
  const LensReadResult r = read_data("sasian_triplet.seq");
  INFO(r.prescription);
  CHECK(r.diagnostics.empty());
  const Prescription json = shipped_lens("sasian-triplet.json");
  CHECK(r.prescription.surfaces == json.surfaces);
  CHECK(r.prescription.aperture == json.aperture);
  CHECK(r.prescription.field == json.field);
  CHECK(r.prescription.wavelengths_nm == json.wavelengths_nm);
  CHECK(r.prescription.primary_wavelength_index == json.primary_wavelength_index);
  CHECK(std::isinf(r.prescription.object_distance_mm));
  CHECK(r.prescription.name == "Sasian triplet");
  CHECK(r.prescription.surfaces[2].is_stop);
  CHECK(r.prescription.surfaces[0].material == MaterialSpec::catalog("N-LAK9", "SCHOTT"));
}

TEST_CASE("CODE V: Smith's Cooke triplet with fictitious glass codes reads as the shipped JSON", "[prescription][codev]") {
  // Glass code 61272.5863349282296652 is nd 1.61272, Vd 58.63349282296652: Smith's SK4 with Vd =
  // (nd - 1) / dn, the same digits as the JSON, so the model glasses are equal exactly.
  const LensReadResult r = read_data("smith_cooke_triplet.seq");
  const Prescription json = shipped_lens("smith-cooke-triplet.json");
  INFO(r.prescription);
  CHECK(r.prescription.surfaces == json.surfaces);
  CHECK(r.prescription.surfaces[0].material == MaterialSpec::model(1.61272, 58.63349282296652));
  // One warning per fictitious glass (SK4 is used twice), saying lensmith's model glass is Cauchy.
  REQUIRE(r.diagnostics.size() == 2);
  CHECK_THAT(r.diagnostics[0].message, Contains("fictitious glass") && Contains("Cauchy"));
  CHECK(r.prescription.field->values.back() == json.field->values.back());
}

TEST_CASE("CODE V: catalogue glasses are found by CODE V's NAME_VENDOR form without the dash", "[prescription][codev]") {
  const LensReadResult r = read_data("double_gauss_f2.seq");
  const Prescription& p = r.prescription;
  REQUIRE(p.surfaces.size() == 11);
  CHECK(p.surfaces[0].material == MaterialSpec::catalog("N-SSK2", "SCHOTT"));
  CHECK(p.surfaces[2].material == MaterialSpec::catalog("N-SK2", "SCHOTT"));
  CHECK(p.surfaces[3].material == MaterialSpec::catalog("F5", "SCHOTT"));
  CHECK(p.surfaces[7].material == MaterialSpec::catalog("N-SK16", "SCHOTT"));
  const std::string ohara = replaced(mini_seq(), "NBK7_SCHOTT", "SLAL8_OHARA");
  CHECK(read_codev(ohara, "t.seq").prescription.surfaces[1].material == MaterialSpec::catalog("S-LAL8", "OHARA"));
  const std::string lower = replaced(mini_seq(), "NBK7_SCHOTT", "nbk7_Schott");
  CHECK(read_codev(lower, "t.seq").prescription.surfaces[1].material == MaterialSpec::catalog("N-BK7", "SCHOTT"));
}

TEST_CASE("CODE V: the glass listing of CODE V 10.7 for the double Gauss matches the catalogue to 6 decimals",
          "[prescription][codev]") {
  // ag_dblgauss.lis (ray-optics src/rayoptics/codev/tests), REFRACTIVE INDICES at 656.3, 587.6, 486.1 nm.
  constexpr double kPrinted = 5e-7 + 2e-7;  // 6 printed decimals, plus catalogue editions that differ in the 7th
  const Prescription p = read_data("double_gauss_f2.seq").prescription;
  struct Row {
    std::size_t surface;
    double n_c, n_d, n_f;
  };
  const Row listing[] = {{0, 1.618769, 1.622292, 1.630455}, {2, 1.604134, 1.607379, 1.614860},
                         {3, 1.598744, 1.603417, 1.614617}, {7, 1.617271, 1.620408, 1.627559}};
  for (const Row& row : listing) {
    const Glass& g = p.surfaces[row.surface].medium;
    INFO(g.name());
    CHECK(std::abs(g.index(656.3) - row.n_c) < kPrinted);
    CHECK(std::abs(g.index(587.6) - row.n_d) < kPrinted);
    CHECK(std::abs(g.index(486.1) - row.n_f) < kPrinted);
  }
}

TEST_CASE("CODE V: without TITLE the lens is named after its file", "[prescription][codev]") {
  const std::string text = replaced(mini_seq(), "TITLE 'MINI'\n", "");
  CHECK(read_codev(text, "lenses/US2701982.seq").prescription.name == "US2701982");
}

TEST_CASE("CODE V: RDM N reads curvatures and RDM Y radii: the same lens either way", "[prescription][codev]") {
  std::string curvatures = replaced(mini_seq(), "RDM;", "RDM N;");
  curvatures = replaced(curvatures, "S 50 5", "S 0.02 5");
  curvatures = replaced(curvatures, "S -200 90", "S -0.005 90");
  const LensReadResult r = read_codev(curvatures, "t.seq");
  CHECK(r.prescription == read_codev(mini_seq(), "t.seq").prescription);
  CHECK(r.diagnostics.empty());
}

TEST_CASE("CODE V: without RDM the S lines hold curvatures, with a note", "[prescription][codev]") {
  std::string text = replaced(mini_seq(), "RDM;", "");
  text = replaced(text, "S 50 5", "S 0.02 5");
  text = replaced(text, "S -200 90", "S -0.005 90");
  const LensReadResult r = read_codev(text, "t.seq");
  CHECK(r.prescription.surfaces[1].curvature_per_mm == 0.02);
  CHECK(has_diagnostic(r.diagnostics, Diagnostic::Severity::Note, line_of(text, "S 0.02"), "curvature"));
}

TEST_CASE("CODE V: RDY and CUY after the S line replace its radius", "[prescription][codev]") {
  const Prescription rdy = read_codev(mini_seq("", "  RDY 40\n"), "t.seq").prescription;
  CHECK(rdy.surfaces[1].curvature_per_mm == 1.0 / 40.0);
  const Prescription cuy = read_codev(mini_seq("", "  CUY 0.025\n"), "t.seq").prescription;
  CHECK(cuy.surfaces[1].curvature_per_mm == 0.025);
  CHECK(read_codev(mini_seq("", "  RDY 0\n"), "t.seq").prescription.surfaces[1].is_plane());
}

TEST_CASE("CODE V: DIM I converts lengths, curvatures, aspheric terms, EPD and heights to millimetres", "[prescription][codev]") {
  const std::string asphere = "  ASP\n  K -0.5\n  A 1e-5; B -2e-8\n";
  const std::string object = "SO 0 400";
  const Prescription mm = read_codev(replaced(mini_seq("", asphere, object), "YAN", "YOB"), "t.seq").prescription;
  const Prescription inch = read_codev(replaced(replaced(mini_seq("", asphere, object), "YAN", "YOB"), "DIM M", "DIM I"), "t.seq").prescription;
  REQUIRE(inch.surfaces.size() == mm.surfaces.size());
  for (std::size_t i = 0; i < mm.surfaces.size(); ++i) {
    INFO("surface " << i + 1);
    CHECK_THAT(inch.surfaces[i].curvature_per_mm, WithinRel(mm.surfaces[i].curvature_per_mm / 25.4, kUnitConversion));
    CHECK_THAT(inch.surfaces[i].thickness_mm, WithinRel(mm.surfaces[i].thickness_mm * 25.4, kUnitConversion));
  }
  CHECK_THAT(*inch.surfaces[1].semi_diameter_mm, WithinRel(8.0 * 25.4, kUnitConversion));
  CHECK_THAT(inch.surfaces[1].even_asphere[1], WithinRel(1e-5 * std::pow(25.4, -3.0), kUnitConversion));
  CHECK_THAT(inch.surfaces[1].even_asphere[2], WithinRel(-2e-8 * std::pow(25.4, -5.0), kUnitConversion));
  CHECK(inch.surfaces[1].conic == -0.5);
  CHECK_THAT(inch.aperture.value, WithinRel(254.0, kUnitConversion));
  CHECK_THAT(inch.object_distance_mm, WithinRel(400.0 * 25.4, kUnitConversion));
  CHECK_THAT(inch.field->values[1], WithinRel(5.0 * 25.4, kUnitConversion));
  CHECK(read_codev(replaced(mini_seq(), "DIM M", "DIM C"), "t.seq").prescription.surfaces[1].thickness_mm == 50.0);
}

TEST_CASE("CODE V: an unknown DIM is an error naming it", "[prescription][codev]") {
  const std::string text = replaced(mini_seq(), "DIM M", "DIM FURLONG");
  const FileError e = codev_error(text);
  CHECK(e.where().line == line_of(text, "DIM"));
  CHECK_THAT(e.what(), Contains("FURLONG"));
}

TEST_CASE("CODE V: ASP with K and A..G gives the conic and the r^4..r^16 coefficients", "[prescription][codev]") {
  const std::string asphere = "  ASP\n  K -0.62\n  A 1.1e-5; B -2.2e-8; C 3.3e-11; D -4.4e-14\n  E 5.5e-17; F -6.6e-20; G 7.7e-23\n";
  const Surface s = read_codev(mini_seq("", asphere), "t.seq").prescription.surfaces[1];
  CHECK(s.conic == -0.62);
  CHECK(s.even_asphere[0] == 0.0);  // CODE V's A is the r^4 term: lensmith's r^2 slot stays zero
  CHECK(s.even_asphere[1] == 1.1e-5);
  CHECK(s.even_asphere[2] == -2.2e-8);
  CHECK(s.even_asphere[3] == 3.3e-11);
  CHECK(s.even_asphere[4] == -4.4e-14);
  CHECK(s.even_asphere[5] == 5.5e-17);
  CHECK(s.even_asphere[6] == -6.6e-20);
  CHECK(s.even_asphere[7] == 7.7e-23);
}

TEST_CASE("CODE V: CON with K alone gives a conic, and SPH drops conic and aspheric terms", "[prescription][codev]") {
  CHECK(read_codev(mini_seq("", "  CON\n  K -1\n"), "t.seq").prescription.surfaces[1].conic == -1.0);
  const Surface s = read_codev(mini_seq("", "  ASP\n  K -1; A 1e-6\n  SPH\n"), "t.seq").prescription.surfaces[1];
  CHECK(s.conic == 0.0);
  CHECK_FALSE(s.has_asphere());
}

TEST_CASE("CODE V: the r^18 and r^20 terms (H, J) are refused unless zero", "[prescription][codev]") {
  CHECK_NOTHROW(read_codev(mini_seq("", "  ASP\n  H 0; J 0\n"), "t.seq"));
  const std::string text = mini_seq("", "  ASP\n  H 1e-25\n");
  const FileError e = codev_error(text);
  CHECK(e.where().line == line_of(text, "H 1e-25"));
  CHECK_THAT(e.what(), Contains("r^18"));
}

TEST_CASE("CODE V: SO's thickness is the object distance, 1e10 or more an object at infinity", "[prescription][codev]") {
  CHECK(std::isinf(read_codev(mini_seq(), "t.seq").prescription.object_distance_mm));
  CHECK(std::isinf(read_codev(mini_seq("", "", "SO 0 993938392063.0"), "t.seq").prescription.object_distance_mm));
  CHECK(read_codev(mini_seq("", "", "SO 0 9.99e9"), "t.seq").prescription.object_distance_mm == 9.99e9);
  CHECK(read_codev(mini_seq("", "", "SO 0 250"), "t.seq").prescription.object_distance_mm == 250.0);
}

TEST_CASE("CODE V: a virtual object and a curved object at a finite distance are refused", "[prescription][codev]") {
  const std::string virtual_object = mini_seq("", "", "SO 0 -50");
  CHECK(codev_error(virtual_object).where().line == line_of(virtual_object, "SO 0 -50"));
  const std::string curved = mini_seq("", "", "SO 100 500");
  CHECK_THAT(codev_error(curved).what(), Contains("curved object"));
  CHECK_NOTHROW(read_codev(mini_seq("", "", "SO 100 1e11"), "t.seq"));  // at infinity the object's shape is moot
}

TEST_CASE("CODE V: a glass on SO is the object-space medium", "[prescription][codev]") {
  const Prescription p = read_codev(mini_seq("", "", "SO 0 100 333.558"), "t.seq").prescription;
  CHECK(p.object_material == MaterialSpec::model(1.333, 55.8));
}

TEST_CASE("CODE V: SI's thickness is a defocus added to the last thickness, with a note", "[prescription][codev]") {
  const std::string text = replaced(mini_seq(), "SI 0 0", "SI 0 -0.4");
  const LensReadResult r = read_codev(text, "t.seq");
  CHECK(r.prescription.surfaces.back().thickness_mm == 90.0 - 0.4);
  CHECK(has_diagnostic(r.diagnostics, Diagnostic::Severity::Note, line_of(text, "SI 0 -0.4"), "defocus"));
}

TEST_CASE("CODE V: a curved image surface is a warning", "[prescription][codev]") {
  const std::string text = replaced(mini_seq(), "SI 0 0", "SI -100 0");
  const LensReadResult r = read_codev(text, "t.seq");
  CHECK(has_diagnostic(r.diagnostics, Diagnostic::Severity::Warning, line_of(text, "SI -100"), "curved"));
}

TEST_CASE("CODE V: REFL makes a mirror, on the S line, in GLA and in RMD, not on SO or SI", "[prescription][codev]") {
  for (const std::string& mirror : {std::string("S -200 -90 REFL"), std::string("S -200 -90\n  RMD REFL"),
                                    std::string("S -200 -90\n  GLA REFL")}) {
    const std::string text = replaced(mini_seq(), "S -200 90", mirror);
    INFO(mirror);
    const Prescription p = read_codev(text, "t.seq").prescription;
    CHECK(p.surfaces[2].mirror);
    CHECK(p.surfaces[2].medium.index(587.5618) == p.surfaces[1].medium.index(587.5618));  // back into the glass
  }
  CHECK_FALSE(read_codev(mini_seq("", "  RMD REFR\n"), "t.seq").prescription.surfaces[1].mirror);
  const std::string image = replaced(mini_seq(), "SI 0 0", "SI 0 0 REFL");
  CHECK(codev_error(image).where().line == line_of(image, "SI 0 0 REFL"));
}

TEST_CASE("CODE V: decentres and tilts are accepted when zero and refused otherwise", "[prescription][codev]") {
  CHECK_NOTHROW(read_codev(mini_seq("", "  XDE 0.0; YDE 0.0; ZDE 0.0\n  ADE 0; BDE 0; CDE 0\n  DAR\n"), "t.seq"));
  for (const char* line : {"  YDE 2.5\n", "  ADE 45\n", "  CDE -1\n"}) {
    const std::string text = mini_seq("", line);
    INFO(line);
    const FileError e = codev_error(text);
    CHECK(e.where().line == line_of(text, line));
    CHECK(e.where().column == 7);
    CHECK_THAT(e.what(), Contains("decentres and tilts"));
  }
}

TEST_CASE("CODE V: commands that change the optics beyond lensmith's model are refused, naming the feature and line",
          "[prescription][codev]") {
  struct Case {
    const char* line;
    const char* feature;
  };
  const Case cases[] = {{"ZOO 3\n", "zoom"},         {"NA 0.1\n", "NA"},          {"YRI 0 5\n", "real image height"},
                        {"  RET S1\n", "RET"},       {"  XTO\n", "toroidal"},      {"  DIF DOE\n", "diffractive"},
                        {"  RDX 40\n", "toroidal"},  {"  CUF 0.01\n", "Fresnel"}};
  for (const Case& c : cases) {
    const std::string line(c.line);
    const bool system = line.front() != ' ';
    const std::string text = system ? mini_seq(line) : mini_seq("", line);
    INFO(line);
    const FileError e = codev_error(text);
    CHECK(e.where().line == line_of(text, line));
    CHECK_THAT(e.what(), Contains(c.feature));
  }
}

TEST_CASE("CODE V: CIR is a clear aperture that clips rays", "[prescription][codev]") {
  const Surface s = read_codev(mini_seq(), "t.seq").prescription.surfaces[1];
  CHECK(*s.semi_diameter_mm == 8.0);
  CHECK(s.clips_rays);
  CHECK_FALSE(s.aperture);
  CHECK_FALSE(read_codev(mini_seq(), "t.seq").prescription.surfaces[0].semi_diameter_mm);
}

TEST_CASE("CODE V: CIR EDG alone sizes the surface without clipping", "[prescription][codev]") {
  std::string text = replaced(mini_seq(), "  CIR 8\nS -200", "  CIR EDG 9\nS -200");
  const Surface s = read_codev(text, "t.seq").prescription.surfaces[1];
  CHECK(*s.semi_diameter_mm == 9.0);
  CHECK_FALSE(s.clips_rays);
  // Next to a clear aperture the edge changes nothing.
  const Surface both = read_codev(mini_seq("", "  CIR EDG 9\n"), "t.seq").prescription.surfaces[1];
  CHECK(*both.semi_diameter_mm == 8.0);
  CHECK(both.clips_rays);
}

TEST_CASE("CODE V: CIR OBS is a central obscuration, and with CIR an annulus", "[prescription][codev]") {
  std::string alone = replaced(mini_seq(), "  CIR 8\nS -200", "  CIR OBS L'A' 2.5\nS -200");
  const Surface o = read_codev(alone, "t.seq").prescription.surfaces[1];
  REQUIRE(o.aperture);
  CHECK(o.aperture->obscuration);
  CHECK(o.aperture->half_x_mm == 2.5);
  const Surface annulus = read_codev(mini_seq("", "  CIR OBS 2.5\n"), "t.seq").prescription.surfaces[1];
  REQUIRE(annulus.aperture);
  CHECK(annulus.aperture->shape == SurfaceAperture::Shape::Circular);
  CHECK_FALSE(annulus.aperture->obscuration);
  CHECK(annulus.aperture->half_x_mm == 8.0);
  CHECK(annulus.aperture->min_radius_mm == 2.5);
}

TEST_CASE("CODE V: REX/REY and ELX/ELY with ADX/ADY give decentred rectangular and elliptical apertures",
          "[prescription][codev]") {
  std::string rect = replaced(mini_seq(), "  CIR 8\nS -200", "  REX 6; REY 4; ADY 1.5\nS -200");
  const Surface r = read_codev(rect, "t.seq").prescription.surfaces[1];
  REQUIRE(r.aperture);
  CHECK(r.aperture->shape == SurfaceAperture::Shape::Rectangular);
  CHECK(r.aperture->half_x_mm == 6.0);
  CHECK(r.aperture->half_y_mm == 4.0);
  CHECK(r.aperture->decenter_y_mm == 1.5);
  CHECK(r.clips_rays);
  CHECK_THAT(*r.semi_diameter_mm, WithinRel(std::hypot(6.0, 5.5), 1e-15));  // the circle holding the rectangle
  std::string ellipse = replaced(mini_seq(), "  CIR 8\nS -200", "  ELX 6\n  ELY 4\n  ADX -1\nS -200");
  const Surface e = read_codev(ellipse, "t.seq").prescription.surfaces[1];
  REQUIRE(e.aperture);
  CHECK(e.aperture->shape == SurfaceAperture::Shape::Elliptical);
  CHECK(e.aperture->decenter_x_mm == -1.0);
}

TEST_CASE("CODE V: apertures lensmith cannot model are refused", "[prescription][codev]") {
  const std::string half = replaced(mini_seq(), "  CIR 8\nS -200", "  REX 6\nS -200");
  CHECK_THAT(codev_error(half).what(), Contains("REY"));
  const std::string hole = mini_seq("", "  CIR HOL 1\n");
  CHECK(codev_error(hole).where().line == line_of(hole, "HOL"));
  const std::string rotated = replaced(mini_seq(), "  CIR 8\nS -200", "  REX 6; REY 4; ARO 10\nS -200");
  CHECK_THAT(codev_error(rotated).what(), Contains("rotated"));
  const std::string mixed = mini_seq("", "  REX 6\n");
  CHECK(codev_error(mixed).where().line == line_of(mixed, "REX"));
  const std::string decentred_pair = mini_seq("", "  CIR OBS 2\n  ADY OBS 1\n");
  CHECK_THAT(codev_error(decentred_pair).what(), Contains("annulus"));
}

TEST_CASE("CODE V: YAN gives angle fields, XAN components fold into radial fields with a note", "[prescription][codev]") {
  const std::string text = mini_seq("XAN 0 10\n");
  const LensReadResult r = read_codev(replaced(text, "YAN 0 5", "YAN 0 10"), "t.seq");
  const double expected = deg_from_rad(std::atan(std::sqrt(2.0) * std::tan(rad_from_deg(10.0))));
  CHECK(r.prescription.field->kind == FieldSpec::Kind::AngleDeg);
  CHECK_THAT(r.prescription.field->values[1], WithinRel(expected, 1e-14));
  CHECK(has_diagnostic(r.diagnostics, Diagnostic::Severity::Note, line_of(text, "XAN"), "radial"));
}

TEST_CASE("CODE V: YOB gives object heights, YIM paraxial image heights", "[prescription][codev]") {
  const Prescription object = read_codev(replaced(mini_seq("", "", "SO 0 400"), "YAN 0 5", "YOB 0 50"), "t.seq").prescription;
  CHECK(object.field == FieldSpec{FieldSpec::Kind::ObjectHeightMm, {0.0, 50.0}});
  const Prescription image = read_codev(replaced(mini_seq("XIM 0 3\n"), "YAN 0 5", "YIM 0 4"), "t.seq").prescription;
  CHECK(image.field == FieldSpec{FieldSpec::Kind::ImageHeightMm, {0.0, 5.0}});
}

TEST_CASE("CODE V: x and y fields of different types or counts are errors", "[prescription][codev]") {
  const std::string types = mini_seq("XOB 0 1\n");
  CHECK(codev_error(types).where().line == line_of(types, "XOB"));
  const std::string counts = mini_seq("XAN 0 0 0\n");
  CHECK_THAT(codev_error(counts).what(), Contains("same number"));
}

TEST_CASE("CODE V: WL lists wavelengths in nanometres and REF picks the reference, counting from 1", "[prescription][codev]") {
  const Prescription p = read_codev(replaced(mini_seq(), "REF 1", "REF 2"), "t.seq").prescription;
  CHECK(p.wavelengths_nm == std::vector<double>{587.5618, 550.0});
  CHECK(p.primary_wavelength_index == 1);
  const std::string beyond = replaced(mini_seq(), "REF 1", "REF 3");
  CHECK(codev_error(beyond).where().line == line_of(beyond, "REF 3"));
}

TEST_CASE("CODE V: without REF the middle wavelength is the reference, with a warning", "[prescription][codev]") {
  std::string text = replaced(mini_seq(), "REF 1\n", "");
  text = replaced(text, "WL 587.5618 550", "WL 656.3 587.6 486.1");
  const LensReadResult r = read_codev(text, "t.seq");
  CHECK(r.prescription.primary_wavelength_nm() == 587.6);
  CHECK(has_diagnostic(r.diagnostics, Diagnostic::Severity::Warning, line_of(text, "WL"), "REF"));
}

TEST_CASE("CODE V: without WL lensmith's F, d, C are used with a note", "[prescription][codev]") {
  const std::string text = replaced(replaced(mini_seq(), "WL 587.5618 550\n", ""), "REF 1\n", "");
  const LensReadResult r = read_codev(text, "t.seq");
  CHECK(r.prescription.primary_wavelength_nm() == kWavelengthD_nm);
  CHECK(has_diagnostic(r.diagnostics, Diagnostic::Severity::Note, 0, "WL"));
}

TEST_CASE("CODE V: EPD is the entrance-pupil diameter, FNO an image-space F/#", "[prescription][codev]") {
  CHECK(read_codev(mini_seq(), "t.seq").prescription.aperture == ApertureSpec{ApertureSpec::Kind::EntrancePupilDiameter, 10.0});
  const Prescription fno = read_codev(replaced(mini_seq(), "EPD 10", "FNO 4.5"), "t.seq").prescription;
  CHECK(fno.aperture == ApertureSpec{ApertureSpec::Kind::ImageSpaceFNumber, 4.5});
  const std::string zero = replaced(mini_seq(), "EPD 10", "EPD 0");
  CHECK(codev_error(zero).where().line == line_of(zero, "EPD 0"));
}

TEST_CASE("CODE V: without EPD or FNO the stop's CIR sets the aperture, with a warning", "[prescription][codev]") {
  const std::string text = replaced(replaced(mini_seq(), "EPD 10\n", ""), "  STO\n", "  STO; CIR 4\n");
  const LensReadResult r = read_codev(text, "t.seq");
  CHECK(r.prescription.aperture.kind == ApertureSpec::Kind::FloatByStop);
  CHECK(has_diagnostic(r.diagnostics, Diagnostic::Severity::Warning, 0, "EPD"));
}

TEST_CASE("CODE V: rays are aimed at the real stop, as CODE V does", "[prescription][codev]") {
  CHECK(read_codev(mini_seq(), "t.seq").prescription.ray_aiming == RayAiming::RealStop);
}

TEST_CASE("CODE V: without STO surface 1 is the stop, with a note, and a second STO moves it", "[prescription][codev]") {
  const std::string none = replaced(mini_seq(), "  STO\n", "");
  const LensReadResult r = read_codev(none, "t.seq");
  CHECK(r.prescription.surfaces[0].is_stop);
  CHECK(has_diagnostic(r.diagnostics, Diagnostic::Severity::Note, line_of(none, "S 0 2"), "STO"));
  const Prescription moved = read_codev(mini_seq("", "  STO\n"), "t.seq").prescription;
  CHECK_FALSE(moved.surfaces[0].is_stop);
  CHECK(moved.surfaces[1].is_stop);
  const std::string on_image = replaced(mini_seq(), "SI 0 0", "SI 0 0\n  STO");
  CHECK(codev_error(on_image).where().line == line_of(on_image, "  STO\nGO"));
}

TEST_CASE("CODE V: a fictitious glass code nnn.vvv is a model glass nd 1.nnn, Vd vv.v, with a warning", "[prescription][codev]") {
  for (const auto& [code, vd] : {std::pair<std::string, double>{"517.642", 64.2}, {"517642", 64.2}, {"'1.517:64.2'", 64.2},
                                  {"517000.642", 64.2}}) {
    const std::string text = replaced(mini_seq(), "NBK7_SCHOTT", code);
    const LensReadResult r = read_codev(text, "t.seq");
    INFO(code);
    CHECK(r.prescription.surfaces[1].material == MaterialSpec::model(1.517, vd));
    CHECK(has_diagnostic(r.diagnostics, Diagnostic::Severity::Warning, line_of(text, code), "model glass"));
  }
}

TEST_CASE("CODE V: an obsolete SCHOTT name reads as its N- successor with a warning naming both", "[prescription][codev]") {
  const std::string text = replaced(mini_seq(), "NBK7_SCHOTT", "SK16_SCHOTT");
  const LensReadResult r = read_codev(text, "t.seq");
  CHECK(r.prescription.surfaces[1].material == MaterialSpec::catalog("N-SK16", "SCHOTT"));
  CHECK(has_diagnostic(r.diagnostics, Diagnostic::Severity::Warning, line_of(text, "SK16"), "N-SK16"));
}

TEST_CASE("CODE V: an unknown glass is an error naming it, its line and the closest catalogue names", "[prescription][codev]") {
  const std::string text = replaced(mini_seq(), "NBK7_SCHOTT", "UNOBTAINIUM7_SCHOTT");
  const FileError e = codev_error(text);
  CHECK(e.where().line == line_of(text, "UNOBTAINIUM"));
  CHECK(e.where().column == 8);
  CHECK_THAT(e.what(), Contains("UNOBTAINIUM7_SCHOTT") && Contains("closest catalogue names"));
}

TEST_CASE("CODE V: a PRV block's glass becomes a model glass from its index table, with a warning", "[prescription][codev]") {
  // A PMMA-like table: the reader interpolates nd, nF and nC in 1/lambda^2.
  const std::string prv = "PRV\n  PWL 700.0 656.3 587.6 486.1 450.0\n  'E48' 1.4886 1.4892 1.4918 1.4978 1.5010&\n\nEND\n";
  const std::string text = replaced(mini_seq(prv), "NBK7_SCHOTT", "'E48'");
  const LensReadResult r = read_codev(text, "t.seq");
  const MaterialSpec& m = r.prescription.surfaces[1].material;
  CHECK(m.kind == MaterialSpec::Kind::Model);
  CHECK_THAT(m.nd, WithinRel(1.4918, 1e-4));
  CHECK(has_diagnostic(r.diagnostics, Diagnostic::Severity::Warning, line_of(text, "'E48'\n"), "private glass E48"));
  const std::string formula = replaced(mini_seq("PRV\n  PWL 550\n  'NOA61' LAU 2.36 0.0 0.025\nEND\n"), "NBK7_SCHOTT", "'NOA61'");
  CHECK_THAT(codev_error(formula).what(), Contains("formula"));
  CHECK_NOTHROW(read_codev(mini_seq("PRV\n  PWL 550\n  'NOA61' LAU 2.36 0.0 0.025\nEND\n"), "t.seq"));  // defined, not used
}

TEST_CASE("CODE V: comments, semicolon separators, '&' continuations and quoted strings", "[prescription][codev]") {
  const std::string text = replaced(replaced(mini_seq(), "TITLE 'MINI'", "TITLE 'MINI! not a comment' ! a comment"),
                                    "S 50 5 NBK7_SCHOTT\n  CIR 8", "S 50 &\n 5 NBK7_SCHOTT ; CIR &\n8");
  const LensReadResult r = read_codev(text, "t.seq");
  CHECK(r.prescription.name == "MINI! not a comment");
  CHECK(r.prescription.surfaces == read_codev(mini_seq(), "t.seq").prescription.surfaces);
  CHECK_THAT(codev_error("TIT 'open\nSO 0 1e10\n").what(), Contains("unterminated"));
}

TEST_CASE("CODE V: long keywords match by their first three letters (TITLE, STOP)", "[prescription][codev]") {
  const std::string text = replaced(mini_seq(), "  STO\n", "  stop\n");
  CHECK(read_codev(text, "t.seq").prescription.surfaces[0].is_stop);
}

TEST_CASE("CODE V: S k, SO and SI qualifiers name the surface a command changes", "[prescription][codev]") {
  const Prescription p = read_codev(mini_seq("", "  THI S1 3\n  GLA S2 NSF5_SCHOTT\n"), "t.seq").prescription;
  CHECK(p.surfaces[0].thickness_mm == 3.0);
  CHECK(p.surfaces[1].material == MaterialSpec::catalog("N-SF5", "SCHOTT"));
  const std::string text = mini_seq("", "  THI S9 3\n");
  CHECK(codev_error(text).where().line == line_of(text, "S9"));
  const std::string range = mini_seq("", "  THI S1..2 3\n");
  CHECK_THAT(codev_error(range).what(), Contains("ranges"));
}

TEST_CASE("CODE V: solves, variable codes and pickups are skipped: the file holds the solved values", "[prescription][codev]") {
  const std::string extra = "  CCY 0; THC 0; THI HMY 0.0\n  PIM\nPIK THI S3 Z1 THI S2 Z1 -1.0\n";
  const LensReadResult r = read_codev(mini_seq("", extra), "t.seq");
  CHECK(r.diagnostics.empty());
  CHECK(r.prescription == read_codev(mini_seq(), "t.seq").prescription);
}

TEST_CASE("CODE V: an unknown keyword is a warning naming it once, and the file still reads", "[prescription][codev]") {
  const std::string text = mini_seq("FROB 1 2 3\nFROB 4\n");
  const LensReadResult r = read_codev(text, "t.seq");
  REQUIRE(r.diagnostics.size() == 1);
  CHECK(has_diagnostic(r.diagnostics, Diagnostic::Severity::Warning, line_of(text, "FROB"), "FROB"));
  CHECK_THAT(r.diagnostics[0].message, Contains("2 commands"));
}

TEST_CASE("CODE V: a rotated vignetted pupil (VRO) is noted as ignored", "[prescription][codev]") {
  const LensReadResult r = read_codev(mini_seq("VRO 0 10\n"), "t.seq");
  REQUIRE(r.diagnostics.size() == 1);
  CHECK_THAT(r.diagnostics[0].message, Contains("VRO"));
}

TEST_CASE("CODE V: TEM other than 20 C is a warning", "[prescription][codev]") {
  const std::string text = mini_seq("TEM 25\n");
  CHECK(has_diagnostic(read_codev(text, "t.seq").diagnostics, Diagnostic::Severity::Warning, line_of(text, "TEM"), "20 C"));
  CHECK(read_codev(mini_seq("TEM 20.0\n"), "t.seq").diagnostics.empty());
}

TEST_CASE("CODE V: commands after GO are not read, with a note", "[prescription][codev]") {
  const std::string text = mini_seq() + "EPD 99\n";
  const LensReadResult r = read_codev(text, "t.seq");
  CHECK(r.prescription.aperture.value == 10.0);
  CHECK(has_diagnostic(r.diagnostics, Diagnostic::Severity::Note, line_of(text, "EPD 99"), "after GO"));
}

TEST_CASE("CODE V: numbers such as nan, inf and 1e999 are errors naming their line and column", "[prescription][codev]") {
  for (const char* bad : {"nan", "inf", "1e999", "1.#INF", "4.2E"}) {
    const std::string text = replaced(mini_seq(), "S 50 5", std::string("S ") + bad + " 5");
    INFO(bad);
    const FileError e = codev_error(text);
    CHECK(e.where().line == line_of(text, std::string("S ") + bad));
    CHECK(e.where().column == 3);
  }
}

TEST_CASE("CODE V: a file needs SO and a lens surface, in that order", "[prescription][codev]") {
  CHECK_THAT(codev_error("RDM\nEPD 10\n").what(), Contains("no SO"));
  CHECK_THAT(codev_error("SO 0 1e10\nSI 0 0\n").what(), Contains("at least one S line"));
  const std::string after = replaced(mini_seq(), "GO\n", "S 0 1\n");
  CHECK(codev_error(after).where().line == line_of(after, "S 0 1"));
  CHECK_THAT(codev_error("S 10 1\n").what(), Contains("before the object surface"));
}

TEST_CASE("CODE V: binary garbage, empty files and a lone byte-order mark are errors, not crashes", "[prescription][codev]") {
  const std::string garbage("\x89PNG\r\n\x1a\n\0\0\0\rIHDR", 16);
  CHECK_THROWS_AS(read_codev(garbage, "g.seq"), FileError);
  CHECK_THROWS_AS(read_codev("", "e.seq"), FileError);
  CHECK_THROWS_AS(read_codev("\xFF\xFE", "bom-only.seq"), FileError);
  CHECK_THROWS_AS(read_codev(std::string(100000, 'A'), "long.seq"), FileError);
  CHECK_THROWS_AS(read_codev(std::string(100000, '&'), "amp.seq"), FileError);
}

TEST_CASE("CODE V: UTF-16LE with a byte-order mark reads like UTF-8", "[prescription][codev]") {
  const std::string plain = mini_seq();
  std::string utf16 = "\xFF\xFE";
  for (const char c : plain) utf16 += std::string{c, '\0'};
  CHECK(read_codev(utf16, "t.seq").prescription == read_codev(plain, "t.seq").prescription);
}

TEST_CASE("CODE V: a .seq path reads through read_lens_file", "[prescription][codev]") {
  CHECK(lens_format_from_path("lens.SEQ") == LensFormat::CodeV);
  const LensReadResult r = read_lens_file(data_file("sasian_triplet.seq"));
  CHECK(r.prescription == read_data("sasian_triplet.seq").prescription);
  CHECK_THROWS_WITH(lens_format_from_path("lens.abc"), Contains(".seq (CODE V)"));
}

TEST_CASE("CODE V: a sequence without SI keeps CODE V's default image plane at the last thickness, with a note", "[prescription][codev]") {
  // Hand-written sequences insert S lines into CODE V's default lens, which already has an image surface.
  const std::string text = "dim m\nso 0 1e11\ns 0.1 1 nbk7_schott ! curvatures: no RDM\n"
                           "s -0.05 &\n2\nepd 2.5; wl 650 550 450\n";
  const LensReadResult r = read_codev(text, "t.seq");
  REQUIRE(r.prescription.surfaces.size() == 2);
  CHECK(r.prescription.surfaces.back().thickness_mm == 2.0);
  bool noted = false;
  for (const Diagnostic& d : r.diagnostics) noted = noted || d.message.find("no SI line") != std::string::npos;
  CHECK(noted);
}

TEST_CASE("CODE V: VUY/VLY/VUX/VLX become OpticStudio-style vignetting factors per field", "[prescription][codev]") {
  // The pupil spans [-(1 - VLY), 1 - VUY]: centre (VLY - VUY) / 2, compression (VUY + VLY) / 2.
  const std::string text = replaced(mini_seq(), "YAN 0 5\n", "YAN 0 5\nVUY 0 0.2\nVLY 0 0.3\nVUX 0 0.1\nVLX 0 0.1\n");
  const Prescription p = read_codev(text, "t.seq").prescription;
  REQUIRE(p.field->vignetting.size() == 2);
  CHECK(p.field->vignetting[0].is_none());
  const VignettingFactors& v = p.field->vignetting[1];
  CHECK_THAT(v.vdy, WithinRel(0.05, 1e-12));
  CHECK_THAT(v.vcy, WithinRel(0.25, 1e-12));
  CHECK(v.vdx == 0.0);
  CHECK_THAT(v.vcx, WithinRel(0.1, 1e-12));
}

TEST_CASE("CODE V: NAO is an object-space NA aperture, and with the object at infinity it is refused on its line", "[prescription][codev]") {
  const Prescription p = read_codev(replaced(mini_seq("NAO 0.05\n", "", "SO 0 400"), "EPD 10\n", ""), "t.seq").prescription;
  CHECK(p.aperture == ApertureSpec{ApertureSpec::Kind::ObjectSpaceNA, 0.05});
  const std::string at_infinity = replaced(mini_seq("NAO 0.05\n"), "EPD 10\n", "");
  const FileError e = codev_error(at_infinity);
  CHECK(e.where().line == line_of(at_infinity, "NAO"));
  CHECK_THAT(e.what(), Contains("finite object"));
}
