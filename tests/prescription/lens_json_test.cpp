// The native lens format (docs/lens-format.md): one test per rule, and read -> write -> read.
#include <catch2/catch.hpp>

#include <cmath>
#include <string>

#include "lensmith/core/errors.h"
#include "lensmith/prescription/lens_json.h"
#include "lensmith/prescription/lens_library.h"

using namespace lensmith;
using Catch::Contains;

namespace {

// A minimal valid lens file with one surface's JSON and extra top-level keys spliced in.
std::string lens_with(const std::string& surface2, const std::string& extra_top = "") {
  return "{\n"
         "  \"format\": \"lensmith-lens\",\n"
         "  \"version\": 1,\n"
         "  \"name\": \"test singlet\",\n" +
         extra_top +
         "  \"aperture\": {\"entrance_pupil_diameter_mm\": 10},\n"
         "  \"surfaces\": [\n"
         "    {\"radius_mm\": 50, \"thickness_mm\": 5, \"material\": {\"nd\": 1.5, \"vd\": 60}, \"semi_diameter_mm\": 12},\n"
         "    " + surface2 + "\n"
         "  ]\n"
         "}\n";
}

FileError read_error(const std::string& text) {
  try {
    read_lens_json(text, "t.json");
  } catch (const FileError& e) {
    return e;
  }
  FAIL("expected a FileError");
  throw;  // unreachable
}

}  // namespace

TEST_CASE("lens JSON: a minimal singlet reads with the documented defaults", "[prescription][json]") {
  const auto r = read_lens_json(lens_with("{\"radius_mm\": \"flat\", \"thickness_mm\": 95}"), "t.json");
  const Prescription& p = r.prescription;
  CHECK(p.name == "test singlet");
  REQUIRE(p.surfaces.size() == 2);
  CHECK(p.surfaces[0].curvature_per_mm == 1.0 / 50.0);
  CHECK(p.surfaces[1].curvature_per_mm == 0.0);
  CHECK(p.surfaces[1].material.kind == MaterialSpec::Kind::Air);  // default material
  CHECK(std::isinf(p.object_distance_mm));                         // default: infinity
  CHECK(p.wavelengths_nm == std::vector<double>{486.1327, 587.5618, 656.2725});
  CHECK(p.primary_wavelength_nm() == 587.5618);
  CHECK_FALSE(p.image_at_paraxial_focus);
  CHECK_FALSE(p.field.has_value());
  // The model glass is resolved and reproduces its nd.
  CHECK_THAT(p.surfaces[0].medium.index(587.5618), Catch::Matchers::WithinAbs(1.5, 1e-12));
}

TEST_CASE("lens JSON: a last surface without thickness puts the image at the paraxial focus", "[prescription][json]") {
  const auto r = read_lens_json(lens_with("{\"radius_mm\": \"flat\"}"), "t.json");
  CHECK(r.prescription.image_at_paraxial_focus);
}

TEST_CASE("lens JSON: a surface other than the last needs a thickness", "[prescription][json]") {
  const std::string text = "{\"format\": \"lensmith-lens\", \"version\": 1, \"name\": \"x\", \"surfaces\": [\n"
                           "  {\"radius_mm\": 10},\n  {\"radius_mm\": -10}]}";
  auto e = read_error(text);
  CHECK(e.where().line == 2);
  CHECK_THAT(e.what(), Contains("surface 1") && Contains("missing thickness_mm"));
}

TEST_CASE("lens JSON: an unknown key is an error with its line, column and the allowed keys", "[prescription][json]") {
  auto e = read_error(lens_with("{\"radius_mm\": \"flat\", \"thicknes_mm\": 95}"));
  CHECK(e.where().line == 8);
  CHECK_THAT(e.what(), Contains("thicknes_mm: unknown key") && Contains("thickness_mm"));
}

TEST_CASE("lens JSON: radius zero is refused, flat must be said", "[prescription][json]") {
  auto e = read_error(lens_with("{\"radius_mm\": 0, \"thickness_mm\": 95}"));
  CHECK_THAT(e.what(), Contains("radius_mm: must be finite and non-zero; write \"flat\""));
}

TEST_CASE("lens JSON: radius and curvature together are refused", "[prescription][json]") {
  auto e = read_error(lens_with("{\"radius_mm\": 10, \"curvature_per_mm\": 0.1, \"thickness_mm\": 95}"));
  CHECK_THAT(e.what(), Contains("radius_mm or curvature_per_mm, not both"));
}

TEST_CASE("lens JSON: a wrong type names the key and what was expected", "[prescription][json]") {
  auto e = read_error(lens_with("{\"radius_mm\": \"flat\", \"thickness_mm\": \"95\"}"));
  CHECK(e.where().line == 8);
  CHECK_THAT(e.what(), Contains("thickness_mm: expected a number, got a string"));
}

TEST_CASE("lens JSON: an unknown glass is an error naming the surface and the closest names, never a default index",
          "[prescription][json]") {
  auto e = read_error(lens_with("{\"radius_mm\": \"flat\", \"thickness_mm\": 95, \"material\": \"NBK7\"}"));
  CHECK_THAT(e.what(), Contains("surface 2") && Contains("NBK7") && Contains("N-BK7"));
  CHECK(e.where().line == 8);
}

TEST_CASE("lens JSON: catalogue glass by name or with vendor, and model glasses", "[prescription][json]") {
  auto r = read_lens_json(lens_with("{\"radius_mm\": -50, \"thickness_mm\": 2, \"material\": {\"glass\": \"N-BK7\", \"vendor\": \"SCHOTT\"}},\n"
                                    "    {\"radius_mm\": -80, \"thickness_mm\": 2, \"material\": {\"nd\": 1.7}},\n"
                                    "    {\"radius_mm\": \"flat\", \"thickness_mm\": 90, \"material\": \"n-sf5\"},\n"
                                    "    {\"radius_mm\": \"flat\", \"thickness_mm\": 1}"),
                          "t.json");
  const auto& s = r.prescription.surfaces;
  CHECK(s[1].medium.name() == "N-BK7");
  CHECK(s[1].medium.vendor() == "SCHOTT");
  CHECK(s[2].material.kind == MaterialSpec::Kind::Model);
  CHECK(s[2].medium.index(400.0) == 1.7);  // no Vd: dispersion-free
  CHECK(s[3].medium.name() == "N-SF5");    // names are case-insensitive
}

TEST_CASE("lens JSON: a model glass outside [1, 5] is refused", "[prescription][json]") {
  auto e = read_error(lens_with("{\"radius_mm\": \"flat\", \"thickness_mm\": 95, \"material\": {\"nd\": 0.5}}"));
  CHECK_THAT(e.what(), Contains("nd: must lie in [1, 5]"));
}

TEST_CASE("lens JSON: two stops are refused, naming the count", "[prescription][json]") {
  auto e = read_error(lens_with("{\"radius_mm\": \"flat\", \"thickness_mm\": 1, \"stop\": true, \"semi_diameter_mm\": 3},\n"
                                "    {\"radius_mm\": \"flat\", \"thickness_mm\": 95, \"stop\": true, \"semi_diameter_mm\": 3}"));
  CHECK_THAT(e.what(), Contains("2 surfaces are flagged as the stop"));
}

TEST_CASE("lens JSON: a semi-diameter beyond a sphere's radius is refused, naming the surface", "[prescription][json]") {
  auto e = read_error(lens_with("{\"radius_mm\": -8, \"thickness_mm\": 95, \"semi_diameter_mm\": 9}"));
  CHECK_THAT(e.what(), Contains("surface 2: semi_diameter_mm = 9: larger than the surface allows"));
  CHECK(e.where().line == 8);
}

TEST_CASE("lens JSON: aperture takes exactly one of its forms", "[prescription][json]") {
  const std::string two = "{\"format\": \"lensmith-lens\", \"version\": 1, \"name\": \"x\",\n"
                          " \"aperture\": {\"f_number\": 2, \"entrance_pupil_diameter_mm\": 10},\n"
                          " \"surfaces\": [{\"radius_mm\": 50, \"thickness_mm\": 95, \"material\": {\"nd\": 1.5}}]}";
  CHECK_THAT(read_error(two).what(), Contains("exactly one of entrance_pupil_diameter_mm, f_number, float_by_stop"));
  const std::string negative = "{\"format\": \"lensmith-lens\", \"version\": 1, \"name\": \"x\",\n"
                               " \"aperture\": {\"f_number\": -2},\n"
                               " \"surfaces\": [{\"radius_mm\": 50, \"thickness_mm\": 95, \"material\": {\"nd\": 1.5}}]}";
  CHECK_THAT(read_error(negative).what(), Contains("f_number: must be finite and > 0"));
}

TEST_CASE("lens JSON: floating by stop size needs a stop semi-diameter", "[prescription][json]") {
  const std::string text = "{\"format\": \"lensmith-lens\", \"version\": 1, \"name\": \"x\",\n"
                           " \"surfaces\": [{\"radius_mm\": 50, \"thickness_mm\": 95, \"material\": {\"nd\": 1.5}}]}";
  CHECK_THAT(read_error(text).what(), Contains("floats by stop size"));
}

TEST_CASE("lens JSON: the field takes one kind, an object-height field needs a finite object", "[prescription][json]") {
  auto e = read_error(lens_with("{\"radius_mm\": \"flat\", \"thickness_mm\": 95}", "  \"field\": {\"object_height_mm\": 10},\n"));
  CHECK_THAT(e.what(), Contains("object-height field needs a finite object distance"));
  auto r = read_lens_json(lens_with("{\"radius_mm\": \"flat\", \"thickness_mm\": 95}",
                                    "  \"object_distance_mm\": 1000,\n  \"field\": {\"object_height_mm\": [0, 50, 100]},\n"),
                          "t.json");
  REQUIRE(r.prescription.field);
  CHECK(r.prescription.field->max_value() == 100.0);
  auto angle = read_error(lens_with("{\"radius_mm\": \"flat\", \"thickness_mm\": 95}", "  \"field\": {\"angle_deg\": 95},\n"));
  CHECK_THAT(angle.what(), Contains("must lie in (-90, 90) degrees"));
}

TEST_CASE("lens JSON: several wavelengths need a primary one among them", "[prescription][json]") {
  auto e = read_error(lens_with("{\"radius_mm\": \"flat\", \"thickness_mm\": 95}", "  \"wavelengths_nm\": [450, 550],\n"));
  CHECK_THAT(e.what(), Contains("primary_wavelength_nm is missing"));
  auto f = read_error(lens_with("{\"radius_mm\": \"flat\", \"thickness_mm\": 95}",
                                "  \"wavelengths_nm\": [450, 550],\n  \"primary_wavelength_nm\": 500,\n"));
  CHECK_THAT(f.what(), Contains("must be one of wavelengths_nm"));
  auto g = read_error(lens_with("{\"radius_mm\": \"flat\", \"thickness_mm\": 95}",
                                "  \"wavelengths_nm\": [50],\n"));
  CHECK_THAT(g.what(), Contains("must lie in (100, 20000) nm"));
}

TEST_CASE("lens JSON: the format name and version are checked", "[prescription][json]") {
  CHECK_THAT(read_error("{\"format\": \"zemax\", \"version\": 1, \"name\": \"x\", \"surfaces\": []}").what(),
             Contains("expected \"lensmith-lens\""));
  CHECK_THAT(read_error("{\"format\": \"lensmith-lens\", \"version\": 7, \"name\": \"x\", \"surfaces\": []}").what(),
             Contains("this build reads versions 1 to 1"));
}

TEST_CASE("lens JSON: malformed JSON gives the line of the syntax error", "[prescription][json]") {
  auto e = read_error("{\n \"format\": \"lensmith-lens\",\n \"version\": 1,,\n}");
  CHECK(e.where().line == 3);
}

TEST_CASE("lens JSON: read -> write -> read gives an identical prescription for every shipped lens", "[prescription][json]") {
  for (const auto& shipped : LensLibrary::list()) {
    INFO("lens " << shipped.id);
    const Prescription first = LensLibrary::load(shipped.id).prescription;
    const std::string written = write_lens_json(first);
    const Prescription second = read_lens_json(written, "written.json").prescription;
    CHECK(second == first);
    CHECK(write_lens_json(second) == written);  // and the text is stable
  }
}

TEST_CASE("lens JSON: apertures, non-clipping semi-diameters, ray aiming and the new aperture and field kinds round-trip",
          "[prescription][json]") {
  Prescription p = LensLibrary::load("sasian-triplet").prescription;
  p.surfaces[0].clips_rays = false;
  p.surfaces[1].aperture = SurfaceAperture{SurfaceAperture::Shape::Rectangular, false, 0.0, 3.0, 2.0, 0.5, -0.25};
  p.surfaces[2].aperture = SurfaceAperture{SurfaceAperture::Shape::Circular, false, 1.0, 4.0, 4.0, 0.0, 0.0};
  p.surfaces[3].aperture = SurfaceAperture{SurfaceAperture::Shape::Elliptical, true, 0.0, 1.0, 0.5, 0.0, 0.0};
  p.ray_aiming = RayAiming::RealStop;
  p.object_distance_mm = 800.0;
  p.field = FieldSpec{FieldSpec::Kind::RealImageHeightMm, {0, 10, 21}};
  p.field->vignetting = {VignettingFactors{}, VignettingFactors{0.0, 0.05, 0.0, 0.1, 0.0}, VignettingFactors{0.01, 0.1, 0.02, 0.3, 4.0}};
  for (const ApertureSpec& a : {ApertureSpec{ApertureSpec::Kind::ParaxialWorkingFNumber, 5.6}, ApertureSpec{ApertureSpec::Kind::ObjectSpaceNA, 0.02},
                                ApertureSpec{ApertureSpec::Kind::ObjectConeAngleDeg, 1.5}}) {
    p.aperture = a;
    const Prescription again = read_lens_json(write_lens_json(p), "w.json").prescription;
    CHECK(again == p);
  }
}

TEST_CASE("lens JSON: a surface aperture's shape and sizes are checked with their key", "[prescription][json]") {
  CHECK_THAT(read_error(lens_with(R"({"radius_mm": -50, "aperture": {"shape": "hexagonal", "radius_mm": 3}})")).what(), Contains("shape"));
  CHECK_THAT(read_error(lens_with(R"({"radius_mm": -50, "aperture": {"shape": "rectangular", "half_x_mm": 3}})")).what(), Contains("half_y_mm"));
  CHECK_THAT(read_error(lens_with(R"({"radius_mm": -50, "aperture": {"radius_mm": 3, "min_radius_mm": 4}})")).what(), Contains("min_radius_mm"));
  CHECK_THAT(read_error(lens_with(R"({"radius_mm": -50, "clips_rays": false})")).what(), Contains("clips_rays"));
  CHECK_THAT(read_error(lens_with(R"({"radius_mm": -50})", "  \"ray_aiming\": \"sideways\",\n")).what(), Contains("ray_aiming"));
}

TEST_CASE("lens JSON: conic, aspheric terms and curvatures that do not invert exactly round-trip", "[prescription][json]") {
  Prescription p = LensLibrary::load("sasian-triplet").prescription;
  p.surfaces[0].conic = -0.6;
  p.surfaces[0].even_asphere = {1e-4, 2.5e-6, -3e-9, 0, 0, 0, 0, 1e-20};
  p.surfaces[1].curvature_per_mm = 0.1 + 1e-17;  // 1/(1/c) != c for some c
  p.object_distance_mm = 1234.5;
  p.field = FieldSpec{FieldSpec::Kind::ObjectHeightMm, {0, 200}};
  const Prescription again = read_lens_json(write_lens_json(p), "w.json").prescription;
  CHECK(again == p);
}

TEST_CASE("lens JSON: mirrors, coordinate breaks, toroidal and biconic surfaces read and write back unchanged",
          "[prescription][json][mirror]") {
  const std::string text =
      "{\"format\": \"lensmith-lens\", \"version\": 1, \"name\": \"folded\",\n"
      " \"aperture\": {\"entrance_pupil_diameter_mm\": 10},\n"
      " \"surfaces\": [\n"
      "  {\"radius_mm\": \"flat\", \"thickness_mm\": 20, \"stop\": true, \"semi_diameter_mm\": 6},\n"
      "  {\"coordinate_break\": {\"tilt_x_deg\": 45}, \"thickness_mm\": 0},\n"
      "  {\"radius_mm\": \"flat\", \"thickness_mm\": 0, \"mirror\": true},\n"
      "  {\"coordinate_break\": {\"tilt_x_deg\": 45, \"decenter_y_mm\": 0.5, \"order\": \"tilt_first\"}, \"thickness_mm\": -30},\n"
      "  {\"radius_mm\": -50, \"thickness_mm\": -5, \"material\": {\"nd\": 1.5}, \"toroidal\": {\"radius_of_rotation_mm\": -80}},\n"
      "  {\"radius_mm\": 50, \"thickness_mm\": -40, \"biconic\": {\"radius_x_mm\": \"flat\", \"conic_x\": -0.5}, \"conic\": -1}\n"
      " ]}\n";
  const Prescription p = read_lens_json(text, "t.json").prescription;
  REQUIRE(p.surfaces.size() == 6);
  CHECK(p.surfaces[1].is_coordinate_break());
  CHECK(p.surfaces[1].coordinate_break.tilt_x_deg == 45.0);
  CHECK(p.surfaces[2].mirror);
  CHECK(p.surfaces[3].coordinate_break == CoordinateBreak{0.0, 0.5, 45.0, 0.0, 0.0, true});
  CHECK(p.surfaces[4].kind == SurfaceKind::Toroidal);
  CHECK(p.surfaces[4].curvature_x_per_mm == 1.0 / -80.0);
  CHECK(p.surfaces[5].kind == SurfaceKind::Biconic);
  CHECK(p.surfaces[5].conic_x == -0.5);
  CHECK(read_lens_json(write_lens_json(p), "again.json").prescription == p);
}

TEST_CASE("lens JSON: a mirror with a material, or a coordinate break with a shape, is refused", "[prescription][json][mirror]") {
  CHECK_THAT(read_error(lens_with("{\"radius_mm\": -100, \"thickness_mm\": -50, \"mirror\": true, \"material\": \"N-BK7\"}")).what(),
             Contains("a mirror has no material"));
  CHECK_THAT(read_error(lens_with("{\"coordinate_break\": {\"tilt_x_deg\": 5}, \"radius_mm\": 20, \"thickness_mm\": 50}")).what(),
             Contains("a coordinate break has no radius_mm"));
  CHECK_THAT(read_error(lens_with("{\"coordinate_break\": {\"order\": \"sideways\"}, \"thickness_mm\": 50}")).what(),
             Contains("tilt_first"));
  CHECK_THAT(read_error(lens_with("{\"radius_mm\": 20, \"thickness_mm\": 50, \"toroidal\": {}, \"biconic\": {\"radius_x_mm\": 9}}")).what(),
             Contains("not several"));
}
