// lentil lenses.json reader, on the MIT-licensed database itself (tests/data/lentil, lentil commit
// 1492e9dc). Entry 0001 is the Angenieux double Gauss of US 2,701,982 (1953).
#include "lensmith/prescription/lentil_reader.h"

#include <catch2/catch.hpp>
#include <cmath>
#include <stdexcept>
#include <string>

#include "lensmith/core/errors.h"
#include "lensmith/core/text_file.h"

using Catch::Matchers::Contains;
using Catch::Matchers::WithinRel;
using namespace lensmith;

namespace {

const std::string& database_path() {
  static const std::string path = std::string(LENSMITH_TEST_DATA_DIR) + "/lentil/lenses.json";
  return path;
}

const std::string& database() {
  static const std::string text = read_file_bytes(database_path());
  return text;
}

LensReadResult read_entry(const std::string& id) { return read_lentil(database(), database_path(), id); }

FileError lentil_error(const std::string& text, const std::string& id) {
  try {
    read_lentil(text, "t.json", id);
  } catch (const FileError& e) {
    return e;
  }
  FAIL("expected a FileError");
  throw std::logic_error("unreachable");
}

// A one-entry database: a glass element, the iris, an air gap to the image. `first_element`
// replaces the glass element's JSON.
std::string tiny_database(const std::string& first_element) {
  return "{\n"
         " \"0100\": {\n"
         "  \"company\": \"acme\", \"product-name\": \"singlet\", \"year\": 2001,\n"
         "  \"patent-number\": null, \"patent-location\": null, \"notes\": null,\n"
         "  \"optical-elements-patent\": [\n" +
         first_element +
         ",\n"
         "   {\"radius\": -200, \"thickness\": 5, \"material\": \"air\", \"ior\": null, \"abbe\": null,\n"
         "    \"housing-radius\": 10, \"lens-geometry\": \"spherical\", \"aspherical-equation\": null},\n"
         "   {\"radius\": 99999, \"thickness\": 90, \"material\": \"iris\", \"ior\": null, \"abbe\": null,\n"
         "    \"housing-radius\": 6, \"lens-geometry\": \"spherical\", \"aspherical-equation\": null}\n"
         "  ]\n"
         " }\n"
         "}\n";
}

std::string glass_element(const std::string& material, const std::string& ior, const std::string& abbe,
                          const std::string& extra = "") {
  return "   {\"radius\": 50, \"thickness\": 4, \"material\": \"" + material + "\", \"ior\": " + ior +
         ", \"abbe\": " + abbe + ",\n    \"housing-radius\": 10, \"lens-geometry\": \"spherical\"," +
         " \"aspherical-equation\": null" + extra + "}";
}

}  // namespace

TEST_CASE("lentil: entry 0001, the Angenieux double Gauss, reads with its 15 surfaces and the iris as stop",
          "[prescription][lentil]") {
  const LensReadResult r = read_entry("0001");
  const Prescription& p = r.prescription;
  REQUIRE(p.surfaces.size() == 15);
  CHECK_THAT(p.surfaces[0].radius_mm(), WithinRel(164.13, 1e-15));
  CHECK(p.surfaces[0].thickness_mm == 10.99);
  CHECK(*p.surfaces[0].semi_diameter_mm == 54.0);  // housing-radius is a semi-aperture
  REQUIRE(p.flagged_stop_index());
  CHECK(*p.flagged_stop_index() == 7);
  CHECK(p.surfaces[7].is_plane());  // iris radius 99999
  CHECK(*p.surfaces[7].semi_diameter_mm == 25.5);
  CHECK(p.surfaces[7].material.kind == MaterialSpec::Kind::Air);
  CHECK(p.aperture.kind == ApertureSpec::Kind::FloatByStop);
  CHECK(std::isinf(p.object_distance_mm));
  CHECK_FALSE(p.field);
  // The last thickness is the entry's own image distance.
  CHECK_FALSE(p.image_at_paraxial_focus);
  CHECK(p.surfaces.back().thickness_mm == 55.724334716796875);
}

TEST_CASE("lentil: metadata gives name, source and notes", "[prescription][lentil]") {
  const Prescription p = read_entry("0001").prescription;
  CHECK(p.name == "angenieux double-gauss 1953");
  CHECK(p.source == "US2701982, https://patentimages.storage.googleapis.com/2f/75/dd/b76ccb73bc0f44/US2701982.pdf");
  CHECK_THAT(p.notes, Contains("swirly bokeh"));
}

TEST_CASE("lentil: a named glass is the catalogue glass when its nd is within 0.002 of the entry's ior",
          "[prescription][lentil]") {
  REQUIRE(GlassCatalog::builtin().find("SF15") != nullptr);
  const LensReadResult r = read_entry("0001");
  // Element 9 is SF15 with ior 1.6992; Schott's SF15 has nd 1.69895.
  CHECK(r.prescription.surfaces[8].material == MaterialSpec::catalog("SF15", "SCHOTT"));
}

TEST_CASE("lentil: a named glass whose catalogue nd differs by more than 0.002 becomes a model glass with a note",
          "[prescription][lentil]") {
  const LensReadResult r = read_entry("0001");
  // Element 1 is SF5 with ior 1.6751 and abbe 32.3; Schott's SF5 has nd 1.6727 (0.0024 away).
  CHECK(r.prescription.surfaces[0].material == MaterialSpec::model(1.6751, 32.3));
  bool noted = false;
  for (const Diagnostic& d : r.diagnostics) {
    if (d.severity == Diagnostic::Severity::Note && d.message.find("SF5") != std::string::npos &&
        d.message.find("optical-elements-patent[0]") != std::string::npos) {
      noted = d.where.line > 0;
    }
  }
  CHECK(noted);
}

TEST_CASE("lentil: material \"abbe\" is a model glass from ior and abbe", "[prescription][lentil]") {
  const Prescription p = read_entry("0014").prescription;
  CHECK(p.surfaces[0].material == MaterialSpec::model(1.883, 40.81));
}

TEST_CASE("lentil: the aspherical terms are the r^4, r^6, r^8, r^10 coefficients", "[prescription][lentil]") {
  const Prescription p = read_entry("0014").prescription;
  const Surface& s = p.surfaces[6];
  CHECK(s.conic == 0.0);
  CHECK(s.even_asphere[0] == 0.0);
  CHECK(s.even_asphere[1] == -1.5313e-05);
  CHECK(s.even_asphere[2] == 9.4893e-08);
  CHECK(s.even_asphere[3] == -1.8128e-09);
  CHECK(s.even_asphere[4] == 8.7528e-12);
  CHECK_FALSE(p.surfaces[5].has_asphere());
}

TEST_CASE("lentil: a radius of 99999 or more is a plane", "[prescription][lentil]") {
  const Prescription p = read_entry("0014").prescription;
  CHECK(p.surfaces[19].is_plane());  // radius 100000, a cover plate
  CHECK(p.surfaces[20].is_plane());
}

TEST_CASE("lentil: cylindrical elements read as biconics, cyl-y curved in x and cyl-x curved in y", "[prescription][lentil]") {
  // lentil's tracer (Hanika's polynomial optics) gives a "cyl-y" surface its axis along y: its normal has an x
  // component, so it bends rays in x, the horizontal squeeze of a cinema anamorphic.
  const Prescription p = read_entry("2001").prescription;
  const Surface& first = p.surfaces[0];
  CHECK(first.kind == SurfaceKind::Biconic);
  CHECK(first.curvature_per_mm == 0.0);
  CHECK(first.curvature_x_per_mm == 1.0 / 4.4467);  // the patent's radius, as every entry's, in its own units
  CHECK_FALSE(first.is_rotationally_symmetric());
  CHECK_FALSE(p.is_rotationally_symmetric());
  const Prescription rear = read_entry("2004").prescription;  // cyl-y and spherical elements
  CHECK(rear.surfaces[0].kind == SurfaceKind::Biconic);
  CHECK(rear.surfaces[3].kind == SurfaceKind::Standard);
}

TEST_CASE("lentil: an unknown id is an error listing the available ids", "[prescription][lentil]") {
  try {
    read_entry("0042");
    FAIL("expected a FileError");
  } catch (const FileError& e) {
    CHECK_THAT(e.what(), Contains("0042") && Contains("0001, 0002") && Contains("9994"));
  }
}

TEST_CASE("lentil: every supported entry reads and validates", "[prescription][lentil]") {
  const auto entries = list_lentil_entries(database(), database_path());
  int supported = 0;
  for (const LentilEntrySummary& e : entries) {
    INFO("entry " << e.id);
    if (e.supported) {
      ++supported;
      CHECK_NOTHROW(read_entry(e.id));
    } else {
      CHECK_THROWS_AS(read_entry(e.id), FileError);  // "supported" means exactly "readable"
    }
  }
  CHECK(supported == 21);  // all but the three without an iris (2002, 9991, 9994)
}

TEST_CASE("lentil: the entry list gives ids, makers and what lensmith can read", "[prescription][lentil]") {
  const auto entries = list_lentil_entries(database(), database_path());
  REQUIRE(entries.size() == 24);
  const LentilEntrySummary& first = entries.front();
  CHECK(first.id == "0001");
  CHECK(first.company == "angenieux");
  CHECK(first.product_name == "double-gauss");
  CHECK(first.year == 1953);
  CHECK(first.patent_focal_length_mm == 100.0);
  CHECK(first.production_ready);
  CHECK(first.supported);
  for (const LentilEntrySummary& e : entries) {
    INFO("entry " << e.id);
    // 2002 (a rear anamorphic attachment), 9991 (an anamorphic test) and 9994 (a test lens) have no iris.
    const bool without_iris = e.id == "2002" || e.id == "9991" || e.id == "9994";
    CHECK(e.supported == !without_iris);
  }
}

TEST_CASE("lentil: a zoom thickness list is an error naming the element", "[prescription][lentil]") {
  std::string element = glass_element("abbe", "1.6", "40");
  element.replace(element.find("\"thickness\": 4"), 14, "\"thickness\": [4, 5, 6]");
  const FileError e = lentil_error(tiny_database(element), "0100");
  CHECK_THAT(e.what(), Contains("optical-elements-patent[0].thickness") && Contains("zoom"));
  CHECK(e.where().line == 6);
}

TEST_CASE("lentil: a glass in no catalogue without an ior is an error listing close names", "[prescription][lentil]") {
  const FileError e = lentil_error(tiny_database(glass_element("NBK8", "null", "null")), "0100");
  CHECK_THAT(e.what(), Contains("NBK8") && Contains("closest catalogue names") && Contains("N-BK7"));
  CHECK(e.where().line == 6);
}

TEST_CASE("lentil: a catalogue glass with a null ior is used as is", "[prescription][lentil]") {
  const Prescription p =
      read_lentil(tiny_database(glass_element("N-BK7", "null", "null")), "t.json", "0100").prescription;
  CHECK(p.surfaces[0].material == MaterialSpec::catalog("N-BK7", "SCHOTT"));
}

TEST_CASE("lentil: OHARA names written without their dash (SLAH64) find the catalogue glass, with a note",
          "[prescription][lentil]") {
  REQUIRE(GlassCatalog::builtin().find("S-LAH64") != nullptr);
  const LensReadResult r = read_lentil(tiny_database(glass_element("SLAH64", "1.788", "47.37")), "t.json", "0100");
  CHECK(r.prescription.surfaces[0].material == MaterialSpec::catalog("S-LAH64", "OHARA"));
  REQUIRE(r.diagnostics.size() == 1);
  CHECK(r.diagnostics[0].severity == Diagnostic::Severity::Note);
}

TEST_CASE("lentil: an element key lensmith does not know is an error", "[prescription][lentil]") {
  const FileError e =
      lentil_error(tiny_database(glass_element("abbe", "1.6", "40", ", \"housing_radius\": 9")), "0100");
  CHECK_THAT(e.what(), Contains("housing_radius") && Contains("unknown key"));
}

TEST_CASE("lentil: a second iris is an error", "[prescription][lentil]") {
  std::string element = glass_element("iris", "null", "null");
  const FileError e = lentil_error(tiny_database(element), "0100");
  CHECK_THAT(e.what(), Contains("second iris"));
}

TEST_CASE("lentil: aspherical terms on a spherical element, or a wrong count, are errors", "[prescription][lentil]") {
  std::string spherical = glass_element("abbe", "1.6", "40");
  spherical.replace(spherical.find("\"aspherical-equation\": null"), 27, "\"aspherical-equation\": [1e-5, 0, 0, 0]");
  CHECK_THAT(lentil_error(tiny_database(spherical), "0100").what(), Contains("aspherical-equation"));
  std::string three = glass_element("abbe", "1.6", "40");
  three.replace(three.find("\"spherical\""), 11, "\"aspherical\"");
  three.replace(three.find("\"aspherical-equation\": null"), 27, "\"aspherical-equation\": [1e-5, 0, 0]");
  CHECK_THAT(lentil_error(tiny_database(three), "0100").what(), Contains("four"));
}

TEST_CASE("lentil: malformed JSON and a non-object root are errors with positions", "[prescription][lentil]") {
  CHECK(lentil_error("{\"0001\": [}", "0001").where().line == 1);
  CHECK_THROWS_AS(read_lentil("[1, 2]", "t.json", "0001"), FileError);
  CHECK_THROWS_AS(list_lentil_entries("\"text\"", "t.json"), FileError);
  CHECK_THROWS_AS(read_lentil(std::string(100000, '['), "deep.json", "0001"), FileError);
  CHECK_THROWS_AS(read_lentil(tiny_database(glass_element("abbe", "1e999", "40")), "t.json", "0100"), FileError);
}

TEST_CASE("lentil: a housing radius wider than the sphere is limited to |radius|, with a warning",
          "[prescription][lentil]") {
  const LensReadResult r = read_entry("0015");
  // Element 2 of 0015: radius 0.8146, housing-radius 0.82.
  CHECK_THAT(*r.prescription.surfaces[1].semi_diameter_mm, WithinRel(0.8146, 1e-15));
  REQUIRE(r.diagnostics.size() == 1);
  CHECK(r.diagnostics[0].severity == Diagnostic::Severity::Warning);
  CHECK_THAT(r.diagnostics[0].message, Contains("optical-elements-patent[1]") && Contains("housing-radius"));
}
