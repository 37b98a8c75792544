// pbrt .dat reader: the lens files of pbrt-v4-scenes (prescriptions from W. J. Smith, Modern Lens
// Design; tests/data/pbrt/README.md). Each unscaled file, read with the Auto rule, must be the same
// lens as its scaled counterpart: the two column conventions meet only if both are read right.
#include "lensmith/prescription/pbrt_reader.h"

#include <catch2/catch.hpp>
#include <cmath>
#include <stdexcept>
#include <string>

#include "lensmith/core/errors.h"
#include "lensmith/core/text_file.h"

using Catch::Matchers::Contains;
using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;
using namespace lensmith;

namespace {

// The scaled files print exactly the decimal digits of unscaled value x factor; only the binary
// rounding of that product separates them.
constexpr double kScaledFileRounding = 1e-12;

LensReadResult read_data(const std::string& name, PbrtConvention convention = PbrtConvention::Auto) {
  const std::string path = std::string(LENSMITH_TEST_DATA_DIR) + "/pbrt/" + name;
  return read_pbrt(read_file_bytes(path), path, convention);
}

FileError pbrt_error(const std::string& text, PbrtConvention convention = PbrtConvention::Auto) {
  try {
    read_pbrt(text, "t.dat", convention);
  } catch (const FileError& e) {
    return e;
  }
  FAIL("expected a FileError");
  throw std::logic_error("unreachable");
}

// A three-row lens in the scaled (thickness-to-next) convention.
const std::string kSmallLens =
    "# TEST LENS\n"
    "50.0\t5.0\t1.6\t20\n"
    "0\t3.0\t0\t16\n"
    "-80.0\t0\t1\t20\n";

}  // namespace

TEST_CASE("pbrt: every unscaled file read with the Auto rule is its scaled counterpart", "[prescription][pbrt]") {
  struct Pair {
    const char* unscaled;
    double factor;
    const char* scaled;
  };
  for (const Pair& pair :
       {Pair{"dgauss.dat", 0.5, "dgauss.50mm.dat"}, Pair{"telephoto.dat", 2.5, "telephoto.250mm.dat"},
        Pair{"fisheye.dat", 0.1, "fisheye.10mm.dat"}, Pair{"wide.dat", 0.22, "wide.22mm.dat"}}) {
    INFO(pair.unscaled << " x " << pair.factor << " vs " << pair.scaled);
    const Prescription a = read_data(pair.unscaled).prescription.scaled(pair.factor);
    const Prescription b = read_data(pair.scaled).prescription;
    REQUIRE(a.surfaces.size() == b.surfaces.size());
    for (std::size_t i = 0; i < a.surfaces.size(); ++i) {
      INFO("surface " << i + 1);
      const Surface& x = a.surfaces[i];
      const Surface& y = b.surfaces[i];
      CHECK_THAT(x.curvature_per_mm, WithinRel(y.curvature_per_mm, kScaledFileRounding));
      CHECK_THAT(x.thickness_mm, WithinRel(y.thickness_mm, kScaledFileRounding));
      CHECK_THAT(*x.semi_diameter_mm, WithinRel(*y.semi_diameter_mm, kScaledFileRounding));
      CHECK(x.material == y.material);
      CHECK(x.is_stop == y.is_stop);
    }
    CHECK(a.name == b.name);
    CHECK(a.field == b.field);
  }
}

TEST_CASE("pbrt: the double Gauss reads row by row: radius, thickness to next, index after, diameter",
          "[prescription][pbrt]") {
  const Prescription p = read_data("dgauss.50mm.dat").prescription;
  REQUIRE(p.surfaces.size() == 11);
  const Surface& first = p.surfaces[0];
  CHECK_THAT(first.radius_mm(), WithinRel(29.475, 1e-15));
  CHECK(first.thickness_mm == 3.76);
  CHECK(first.material == MaterialSpec::model(1.67, std::nullopt));
  CHECK(*first.semi_diameter_mm == 12.6);  // aperture column is a diameter
  CHECK(p.surfaces[1].material.kind == MaterialSpec::Kind::Air);
  const Surface& stop = p.surfaces[5];
  CHECK(stop.is_stop);
  CHECK(stop.is_plane());
  CHECK(stop.material.kind == MaterialSpec::Kind::Air);  // n = 0 on the stop row means air
  CHECK(*stop.semi_diameter_mm == 8.55);
}

TEST_CASE("pbrt: the unscaled file's second column is the separation from the previous vertex",
          "[prescription][pbrt]") {
  const Prescription p = read_data("dgauss.dat").prescription;
  REQUIRE(p.surfaces.size() == 11);
  CHECK(p.surfaces[0].thickness_mm == 7.52);  // row 2's column
  CHECK(p.surfaces[9].thickness_mm == 6.44);  // row 11's column
  CHECK(p.surfaces[10].thickness_mm == 0.0);  // unknown: the image goes to the paraxial focus
}

TEST_CASE("pbrt: the image is at the paraxial focus, the aperture floats by the stop, the object is at infinity",
          "[prescription][pbrt]") {
  const Prescription p = read_data("telephoto.250mm.dat").prescription;
  CHECK(p.image_at_paraxial_focus);
  CHECK(p.aperture.kind == ApertureSpec::Kind::FloatByStop);
  CHECK(std::isinf(p.object_distance_mm));
  CHECK(p.surfaces[0].medium.vd() == kInfinity);  // pbrt gives no dispersion
}

TEST_CASE("pbrt: header comments give the name, the source and the notes", "[prescription][pbrt]") {
  const Prescription p = read_data("dgauss.50mm.dat").prescription;
  CHECK(p.name == "D-GAUSS F/2 22deg HFOV");
  CHECK(p.source == "US patent 2,673,491 Tronnier; Moden Lens Design, p.312");
  CHECK(p.notes == "Scaled to 50 mm from 100 mm");
}

TEST_CASE("pbrt: a half field in the header (\"22deg HFOV\", \"155.9FOV\") becomes the field, with a note",
          "[prescription][pbrt]") {
  const LensReadResult dgauss = read_data("dgauss.dat");
  REQUIRE(dgauss.prescription.field);
  CHECK(dgauss.prescription.field->kind == FieldSpec::Kind::AngleDeg);
  CHECK(dgauss.prescription.field->max_value() == 22.0);
  REQUIRE(dgauss.diagnostics.size() == 1);
  CHECK(dgauss.diagnostics[0].severity == Diagnostic::Severity::Note);
  CHECK(dgauss.diagnostics[0].where.line == 1);
  CHECK_THAT(read_data("fisheye.dat").prescription.field->max_value(), WithinRel(77.95, 1e-15));
  CHECK_FALSE(read_data("telephoto.dat").prescription.field);  // its header states no field
}

TEST_CASE("pbrt: Auto reads separation-from-previous when the first row's thickness is 0 and the last's is not",
          "[prescription][pbrt]") {
  const std::string separation = "58.95 0 1.67 50\n169.66 7.52 1 50\n0 5 0 30\n-80 10 1 40\n";
  const Prescription p = read_pbrt(separation, "t.dat").prescription;
  CHECK(p.surfaces[0].thickness_mm == 7.52);
  CHECK(p.surfaces[2].thickness_mm == 10.0);
  // The same rows with a 0 last thickness are a scaled file.
  const Prescription q = read_pbrt(kSmallLens, "t.dat").prescription;
  CHECK(q.surfaces[0].thickness_mm == 5.0);
  CHECK(q.surfaces[1].thickness_mm == 3.0);
}

TEST_CASE("pbrt: an explicit convention overrides the Auto rule and reads a different lens", "[prescription][pbrt]") {
  const Prescription as_scaled = read_data("dgauss.dat", PbrtConvention::ThicknessToNext).prescription;
  const Prescription automatic = read_data("dgauss.dat").prescription;
  CHECK(as_scaled.surfaces[0].thickness_mm == 0.0);
  CHECK(as_scaled.surfaces[1].thickness_mm == 7.52);
  CHECK_FALSE(as_scaled == automatic);
}

TEST_CASE("pbrt: separation-from-previous needs 0 in the first row", "[prescription][pbrt]") {
  const FileError e = pbrt_error(kSmallLens, PbrtConvention::SeparationFromPrevious);
  CHECK(e.where().line == 2);
  CHECK(e.where().column == 6);
}

TEST_CASE("pbrt: a row without exactly 4 columns is an error naming its line", "[prescription][pbrt]") {
  const FileError three = pbrt_error("# X\n50 5 1.6 20\n0 3 0\n-80 0 1 20\n");
  CHECK(three.where().line == 3);
  CHECK_THAT(three.what(), Contains("4 columns"));
  CHECK(pbrt_error("50 5 1.6 20 7\n0 3 0 16\n-80 0 1 20\n").where().line == 1);
}

TEST_CASE("pbrt: a value that is not a finite number is an error naming line and column", "[prescription][pbrt]") {
  for (const char* bad : {"abc", "nan", "inf", "1e999", "5,0", "0x1p3"}) {
    INFO(bad);
    const FileError e = pbrt_error(std::string("50 5 1.6 20\n0 ") + bad + " 0 16\n-80 0 1 20\n");
    CHECK(e.where().line == 2);
    CHECK(e.where().column == 3);
  }
  // '#' starts a comment anywhere in a pbrt file, so "1.#INF" leaves a row of two numbers.
  CHECK(pbrt_error("50 5 1.6 20\n0 1.#INF 0 16\n-80 0 1 20\n").where().line == 2);
}

TEST_CASE("pbrt: two stop rows are an error naming the second", "[prescription][pbrt]") {
  const FileError e = pbrt_error("0 2 0 16\n50 5 1.6 20\n0 3 0 16\n-80 0 1 20\n");
  CHECK(e.where().line == 3);
  CHECK_THAT(e.what(), Contains("line 1"));
}

TEST_CASE("pbrt: a file without a stop row is an error", "[prescription][pbrt]") {
  CHECK_THAT(pbrt_error("50 5 1.6 20\n-80 0 1 20\n").what(), Contains("no aperture stop"));
}

TEST_CASE("pbrt: index 0 is allowed only on the stop row, indices below 1 are errors", "[prescription][pbrt]") {
  CHECK(pbrt_error("50 5 0 20\n0 3 0 16\n-80 0 1 20\n").where().line == 1);
  CHECK(pbrt_error("50 5 0.8 20\n0 3 0 16\n-80 0 1 20\n").where().column == 6);
}

TEST_CASE("pbrt: a negative thickness or a non-positive diameter is an error", "[prescription][pbrt]") {
  CHECK(pbrt_error("50 -5 1.6 20\n0 3 0 16\n-80 0 1 20\n").where().line == 1);
  CHECK(pbrt_error("50 5 1.6 0\n0 3 0 16\n-80 0 1 20\n").where().column == 10);
}

TEST_CASE("pbrt: empty files, comment-only files and binary data are errors", "[prescription][pbrt]") {
  CHECK_THROWS_AS(read_pbrt("", "e.dat"), FileError);
  CHECK_THROWS_AS(read_pbrt("# only a comment\n\n", "c.dat"), FileError);
  CHECK_THROWS_AS(read_pbrt(std::string("\x7f"
                                        "ELF\0\0\0",
                                        7),
                            "b.dat"),
                  FileError);
}

TEST_CASE("pbrt: comments after the numbers and CRLF line ends are fine", "[prescription][pbrt]") {
  const Prescription p = read_pbrt("50 5 1.6 20 # front\r\n0 3 0 16\r\n-80 0 1 20\r\n", "t.dat").prescription;
  CHECK(p.surfaces.size() == 3);
}

TEST_CASE("pbrt: a file without header comments is named after the file", "[prescription][pbrt]") {
  CHECK(read_pbrt("50 5 1.6 20\n0 3 0 16\n-80 0 1 20\n", "lenses/tessar.dat").prescription.name == "tessar");
}

TEST_CASE("pbrt: a UTF-8 byte-order mark is skipped", "[prescription][pbrt]") {
  CHECK(read_pbrt("\xEF\xBB\xBF" + kSmallLens, "t.dat").prescription == read_pbrt(kSmallLens, "t.dat").prescription);
}
