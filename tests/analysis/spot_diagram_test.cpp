// Spot diagrams: a perfect lens makes a perfect point (the Cartesian ellipsoid k = -1/n^2 focuses a
// parallel beam exactly: Welford, Aberrations of Optical Systems, sec. 2.5; Born & Wolf sec. 4.2.3),
// the centroid is the point of least mean squared distance, and vignetted rays are counted.
#include "lensmith/analysis/spot_diagram.h"

#include <catch2/catch.hpp>
#include <cmath>

#include "lensmith/core/errors.h"
#include "reference_lenses.h"

using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;
using namespace lensmith;
using lensmith::testing::make_surface;

namespace {

// Exact geometry in doubles on a 10-mm surface: rounding leaves ~1e-13 mm; 1e-9 mm keeps a wide
// margin and is still 10^6 times below the sphere's aberration in the control below.
constexpr double kPerfectPointMm = 1e-9;

// One refracting surface, air to glass of index n (no dispersion), radius R, conic k, stop on it,
// image in the glass at the far focus n R / (n - 1).
Prescription single_surface(double conic, double n = 1.5, double radius_mm = 10.0, double epd_mm = 8.0) {
  Prescription p;
  p.name = "single surface";
  Surface s = make_surface(radius_mm, n * radius_mm / (n - 1.0), MaterialSpec::model(n, std::nullopt));
  s.conic = conic;
  s.is_stop = true;
  p.surfaces = {s};
  p.aperture = ApertureSpec{ApertureSpec::Kind::EntrancePupilDiameter, epd_mm};
  p.wavelengths_nm = {587.5618};
  p.primary_wavelength_index = 0;
  return p;
}

SpotDiagram on_axis_spot(const Prescription& lens) {
  AnalysisOptions options;
  options.relative_fields = {0.0};
  return compute_spot_diagram(AnalysisContext(lens, options));
}

}  // namespace

TEST_CASE("a perfect lens makes a perfect point: the ellipsoid k = -1/n^2 on axis has spot radii ~ 0", "[analysis][spot]") {
  const double n = 1.5;
  const SpotDiagram perfect = on_axis_spot(single_surface(-1.0 / (n * n), n));
  const SpotStatistics& s = perfect.fields.at(0).spots.at(0).stats;
  INFO(perfect);
  CHECK(s.passed == 127);
  CHECK(s.lost.total() == 0);
  CHECK_THAT(s.rms_radius_chief_mm, WithinAbs(0.0, kPerfectPointMm));
  CHECK_THAT(s.geo_radius_chief_mm, WithinAbs(0.0, kPerfectPointMm));
  // The control: the sphere through the same vertex has spherical aberration that the spot shows.
  const SpotDiagram sphere = on_axis_spot(single_surface(0.0, n));
  INFO(sphere);
  CHECK(sphere.fields.at(0).spots.at(0).stats.rms_radius_chief_mm > 1e3 * kPerfectPointMm);
}

TEST_CASE("spot statistics of two points: centroid halfway, radii about it and about the reference", "[analysis][spot]") {
  const SpotStatistics s = spot_statistics({{0.0, 0.0, 5.0}, {2.0, 0.0, 5.0}}, {0.0, 0.0, 5.0});
  constexpr double kArithmetic = 1e-15;
  CHECK_THAT(s.centroid_x_mm, WithinAbs(1.0, kArithmetic));
  CHECK_THAT(s.rms_radius_chief_mm, WithinAbs(std::sqrt(2.0), kArithmetic));
  CHECK_THAT(s.geo_radius_chief_mm, WithinAbs(2.0, kArithmetic));
  CHECK_THAT(s.rms_radius_centroid_mm, WithinAbs(1.0, kArithmetic));
  CHECK_THAT(s.geo_radius_centroid_mm, WithinAbs(1.0, kArithmetic));
  const SpotStatistics empty = spot_statistics({}, {});
  CHECK(std::isnan(empty.rms_radius_chief_mm));
}

TEST_CASE("RMS about the centroid never exceeds RMS about the chief ray (the centroid minimises the mean square)", "[analysis][spot]") {
  const SpotDiagram d = compute_spot_diagram(AnalysisContext(lensmith::testing::sasian_triplet()));
  REQUIRE(d.fields.size() == 3);
  for (const FieldSpot& f : d.fields) {
    for (const Spot& s : f.spots) {
      INFO("field " << f.field_label << ", " << s.wavelength_nm << " nm: " << s.stats.to_string());
      REQUIRE(s.stats.passed > 0);
      // RMS_chief^2 = RMS_centroid^2 + |centroid - chief|^2, exactly in real numbers.
      const double dx = s.stats.centroid_x_mm - f.chief.x_mm, dy = s.stats.centroid_y_mm - f.chief.y_mm;
      // On axis the two coincide and rounding decides the last bit: allow it.
      CHECK(s.stats.rms_radius_centroid_mm <= s.stats.rms_radius_chief_mm * (1.0 + 1e-12));
      CHECK_THAT(s.stats.rms_radius_chief_mm * s.stats.rms_radius_chief_mm,
                 WithinRel(s.stats.rms_radius_centroid_mm * s.stats.rms_radius_centroid_mm + dx * dx + dy * dy, 1e-9));
    }
  }
  // Off axis the centroid leaves the chief ray (coma, lateral colour): the two radii differ there.
  const Spot& blue_full_field = d.fields[2].spots[0];
  CHECK(blue_full_field.stats.rms_radius_centroid_mm < blue_full_field.stats.rms_radius_chief_mm);
}

TEST_CASE("vignetted rays are counted and left out of the spot, never counted as zeros", "[analysis][spot]") {
  AnalysisOptions options;
  options.relative_fields = {1.0};  // 12 degrees: the f/1.1 double Gauss cuts its beam hard
  const SpotDiagram d = compute_spot_diagram(AnalysisContext(lensmith::testing::angenieux_double_gauss(), options));
  for (const Spot& s : d.fields.at(0).spots) {
    INFO(s.wavelength_nm << " nm: " << s.stats.to_string());
    CHECK(s.stats.lost.vignetted > 0);
    CHECK(s.stats.passed + s.stats.lost.total() == s.stats.traced);
    CHECK(s.points.size() == s.stats.passed);
    CHECK(s.pupil.size() == s.stats.passed);
  }
  const SpotStatistics& poly = d.fields[0].polychromatic;
  CHECK(poly.traced == 3 * 127);
  CHECK(poly.passed + poly.lost.total() == poly.traced);
}

TEST_CASE("random pupil sampling is reproducible with its seed", "[analysis][spot]") {
  SpotOptions o;
  o.sampling.kind = PupilSampling::Kind::Random;
  o.sampling.random_rays = 300;
  o.sampling.seed = 42;
  const AnalysisContext context(lensmith::testing::sasian_triplet());
  const SpotDiagram a = compute_spot_diagram(context, o);
  const SpotDiagram b = compute_spot_diagram(context, o);
  CHECK(a.fields[2].spots[1].stats.rms_radius_chief_mm == b.fields[2].spots[1].stats.rms_radius_chief_mm);
  CHECK(a.fields[2].spots[1].stats.traced == 300);
  o.sampling.seed = 43;
  const SpotDiagram c = compute_spot_diagram(context, o);
  CHECK(a.fields[2].spots[1].stats.rms_radius_chief_mm != c.fields[2].spots[1].stats.rms_radius_chief_mm);
}
