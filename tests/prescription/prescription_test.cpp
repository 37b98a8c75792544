// Prescription::validate names the surface and field it rejects; scaled() scales every length.
#include <catch2/catch.hpp>

#include <cmath>

#include "lensmith/core/errors.h"
#include "lensmith/prescription/lens_library.h"
#include "reference_lenses.h"

using namespace lensmith;
using Catch::Contains;

namespace {
Prescription sasian() { return LensLibrary::load("sasian-triplet").prescription; }
}  // namespace

TEST_CASE("prescription: a negative semi-diameter is rejected naming the surface", "[prescription]") {
  Prescription p = sasian();
  p.surfaces[3].semi_diameter_mm = -2.0;
  CHECK_THROWS_WITH(p.validate(), Contains("surface 4: semi_diameter_mm = -2: must be finite and > 0"));
}

TEST_CASE("prescription: an error carries its subject (surface, field, list entry), so readers need not parse its text", "[prescription]") {
  auto subject_of = [](const Prescription& p) {
    try {
      p.validate();
    } catch (const PrescriptionError& e) {
      return e.subject();
    }
    FAIL("validate() accepted the lens");
    return ErrorSubject{};
  };
  Prescription p = sasian();
  p.surfaces[3].semi_diameter_mm = -2.0;
  const ErrorSubject rim = subject_of(p);
  CHECK(rim.surface == 4);
  CHECK(rim.field == "semi_diameter_mm");
  CHECK(rim.to_string() == "surface 4, semi_diameter_mm");

  Prescription q = sasian();
  q.wavelengths_nm[1] = q.wavelengths_nm[0];
  const ErrorSubject twice = subject_of(q);
  CHECK(twice.surface == 0);
  CHECK(twice.field == "wavelengths_nm");
  CHECK(twice.index == 1);

  Prescription r = sasian();
  r.surfaces[2].material = MaterialSpec::catalog("NO-SUCH-GLASS");
  try {
    r.resolve_materials(GlassCatalog::builtin());
    FAIL("an unknown glass was resolved");
  } catch (const GlassError& e) {
    CHECK(e.subject().surface == 3);
    CHECK(e.subject().field == "material");
  }
}

TEST_CASE("prescription: a non-finite thickness is rejected naming the surface", "[prescription]") {
  Prescription p = sasian();
  p.surfaces[1].thickness_mm = std::nan("");
  CHECK_THROWS_WITH(p.validate(), Contains("surface 2: thickness_mm = nan: must be finite"));
}

TEST_CASE("prescription: object distance must be positive", "[prescription]") {
  Prescription p = sasian();
  p.object_distance_mm = -100.0;
  CHECK_THROWS_WITH(p.validate(), Contains("object_distance_mm = -100: must be > 0"));
}

TEST_CASE("prescription: a primary wavelength index beyond the list is rejected", "[prescription]") {
  Prescription p = sasian();
  p.primary_wavelength_index = 3;
  CHECK_THROWS_WITH(p.validate(), Contains("primary wavelength index 4 is beyond the 3 wavelengths"));
}

TEST_CASE("prescription: scaling multiplies lengths and divides curvatures", "[prescription]") {
  Prescription p = sasian();
  p.surfaces[0].even_asphere[1] = 1e-5;  // r^4 term: scales as factor^-3
  const Prescription q = p.scaled(2.0);
  CHECK_THAT(q.surfaces[0].curvature_per_mm, Catch::Matchers::WithinRel(p.surfaces[0].curvature_per_mm / 2.0, 1e-15));
  CHECK(q.surfaces[0].thickness_mm == 2.0 * p.surfaces[0].thickness_mm);
  CHECK(*q.surfaces[0].semi_diameter_mm == 2.0 * *p.surfaces[0].semi_diameter_mm);
  CHECK_THAT(q.surfaces[0].even_asphere[1], Catch::Matchers::WithinRel(1e-5 / 8.0, 1e-15));
  CHECK(q.aperture.value == 25.0);
  CHECK_THROWS_AS(p.scaled(0.0), PrescriptionError);
}

TEST_CASE("prescription: the flagged stop and vertex positions", "[prescription]") {
  const Prescription p = sasian();
  REQUIRE(p.flagged_stop_index());
  CHECK(*p.flagged_stop_index() == 2);
  // Sum of the first five thicknesses of the Sasian triplet (REFERENCE-VALUES.md section 2).
  CHECK_THAT(p.last_vertex_z_mm(), Catch::Matchers::WithinAbs(4.831 + 5.86 + 0.975 + 4.822 + 3.127, 1e-12));
}

TEST_CASE("Geometry a glassmaker cannot build is warned about, naming the surfaces, and a real lens is not", "[prescription][geometry]") {
  // A biconvex N-BK7 singlet, R = +/-50 mm, 5 mm thick, 10 mm semi-diameter: the sags at the rim
  // are +/-1.0102 mm, so the edge is 5 - 2 x 1.0102 = 2.98 mm thick.
  auto singlet = [](double centre_mm) {
    Prescription p;
    p.surfaces = {testing::make_surface(50.0, centre_mm, MaterialSpec::model(1.5168, 64.17), 10.0),
                  testing::make_surface(-50.0, 40.0, MaterialSpec::air(), 10.0)};
    return p;
  };
  CHECK(singlet(5.0).geometry_warnings().empty());
  // 1.5 mm at the centre leaves -0.52 mm at the rim: the element's faces cross.
  const Diagnostics thin = singlet(1.5).geometry_warnings();
  REQUIRE(thin.size() == 1);
  CHECK(thin.front().message.find("surfaces 1 and 2 cross") != std::string::npos);
  CHECK(thin.front().message.find("edge thickness is -0.52") != std::string::npos);
  const Diagnostics negative = singlet(-2.0).geometry_warnings();
  REQUIRE(negative.size() == 1);
  CHECK(negative.front().message.find("surface 1: the glass after it") != std::string::npos);
  CHECK(negative.front().message.find("negative centre thickness") != std::string::npos);
  CHECK(sasian().geometry_warnings().empty());
}

