// The shared set-up of the analyses: field points from the prescription or an explicit angle, the
// reference wavelength, and one real ray made and traced (RayTraceListing).
#include "lensmith/analysis/analysis_context.h"

#include <catch2/catch.hpp>
#include <cmath>
#include <string>

#include "lensmith/analysis/ray_trace_listing.h"
#include "lensmith/core/errors.h"
#include "lensmith/prescription/lens_file.h"
#include "reference_lenses.h"

using Catch::Matchers::WithinAbs;
using namespace lensmith;

TEST_CASE("off-axis analyses of a lens without a field ask for a field angle, on axis needs none", "[analysis][context]") {
  Prescription lens = lensmith::testing::angenieux_double_gauss();
  lens.field.reset();
  CHECK_THROWS_WITH(AnalysisContext(lens), Catch::Contains("states no field") && Catch::Contains("--field-angle"));
  AnalysisOptions on_axis;
  on_axis.relative_fields = {0.0};
  const AnalysisContext context(lens, on_axis);
  CHECK(!context.has_field());
  CHECK(context.field_at(0.0).y == 0.0);
  AnalysisOptions given;
  given.max_field_angle_deg = 15.0;
  const AnalysisContext with_angle(lens, given);
  CHECK(with_angle.field_at(0.7).y == 0.7 * 15.0);
  CHECK(with_angle.field_label(1.0) == "15.00 deg");
}

TEST_CASE("the reference wavelength is the primary when analysed, else the first analysed", "[analysis][context]") {
  const Prescription lens = lensmith::testing::sasian_triplet();
  CHECK(AnalysisContext(lens).reference_wavelength_nm() == lens.primary_wavelength_nm());
  AnalysisOptions options;
  options.wavelengths_nm = {550.0, 650.0};
  CHECK(AnalysisContext(lens, options).reference_wavelength_nm() == 550.0);
}

TEST_CASE("analysis options name the field and the violated constraint", "[analysis][context]") {
  AnalysisOptions o;
  o.relative_fields = {0.0, 1.5};
  CHECK_THROWS_WITH(o.validate(), Catch::Contains("relative_fields[1] = 1.5") && Catch::Contains("[0, 1]"));
  o.relative_fields = {0.0};
  o.wavelengths_nm = {50.0};
  CHECK_THROWS_WITH(o.validate(), Catch::Contains("wavelengths_nm[0]"));
  o.wavelengths_nm.clear();
  o.max_field_angle_deg = 90.0;
  CHECK_THROWS_WITH(o.validate(), Catch::Contains("max_field_angle_deg"));
}

TEST_CASE("one real ray: the axial ray stays on the axis, surface by surface, to the image plane", "[analysis][listing]") {
  const Prescription lens = lensmith::testing::sasian_triplet();
  RayTraceOptions o;
  const RayTraceListing r = trace_ray_listing(lens, o);
  INFO(r);
  REQUIRE(r.status == RayStatus::Ok);
  REQUIRE(r.hits.size() == lens.surfaces.size());
  for (std::size_t i = 0; i < r.hits.size(); ++i) {
    CHECK(r.hits[i].surface == static_cast<int>(i + 1));
    CHECK(r.hits[i].point_mm.y() == 0.0);
    CHECK_THAT(r.hits[i].point_mm.z(), WithinAbs(lens.vertex_z_mm(i), 1e-12));
  }
  REQUIRE(r.image);
  CHECK_THAT(r.image->z_mm, WithinAbs(r.image_plane_z_mm, 1e-12));
}

TEST_CASE("one real ray that is vignetted reports the surface, and no image point", "[analysis][listing]") {
  RayTraceOptions o;
  o.field = FieldPoint::angle_deg(12.0);
  o.pupil = {0.0, 0.999};
  const RayTraceListing r = trace_ray_listing(lensmith::testing::angenieux_double_gauss(), o);
  INFO(r);
  CHECK(r.status == RayStatus::Vignetted);
  CHECK(r.surface > 0);
  CHECK(!r.image.has_value());
  o.pupil = {2.0, 0.0};
  CHECK_THROWS_WITH(o.validate(), Catch::Contains("unit disc"));
}

TEST_CASE("A traced ray through a folded system is also listed in each surface's own frame, as OpticStudio lists it",
          "[analysis][coordinate-break]") {
  // Edmund's 90-degree off-axis paraboloid (tests/data/zemax/real): a decentring break, the mirror, the image
  // plane turned 90 degrees. In the mirror's frame the ray meets the paraboloid 190.6 mm + 12.7 mm off its
  // axis (the beam's offset plus the pupil point) at its sag; at the turned image plane, in its own frame, it
  // is at the focus, the origin.
  const std::string path = std::string(LENSMITH_TEST_DATA_DIR) + "/zemax/real/zmax_37992.zmx";
  const Prescription lens = read_lens_file(path).prescription;
  RayTraceOptions o;
  o.pupil = {0.0, 0.5};
  const RayTraceListing r = trace_ray_listing(lens, o);
  REQUIRE(r.status == RayStatus::Ok);
  REQUIRE(r.folded);
  REQUIRE(r.local_hits.size() == 4);
  const Eigen::Vector3d& on_mirror = r.local_hits[2].point_mm;
  CHECK_THAT(on_mirror.y(), Catch::Matchers::WithinAbs(190.6 + 12.7, 1e-9));
  CHECK_THAT(on_mirror.z(), Catch::Matchers::WithinAbs(lens.surfaces[2].sag_mm(190.6 + 12.7), 1e-9));
  CHECK(r.local_hits[3].point_mm.norm() < 1e-9);
}
