// The unvignetted entrance pupil: the full disc on axis, shrinking into a "cat's eye" off axis for the
// f/1.1 Angenieux double Gauss (US 2,701,982), whose optical vignetting gives its swirly bokeh.
#include "lensmith/analysis/pupil_shape.h"

#include <catch2/catch.hpp>
#include <cmath>

#include "reference_lenses.h"

using Catch::Matchers::WithinAbs;
using namespace lensmith;

namespace {

double polygon_area(const std::vector<PupilCoordinate>& p) {
  double twice = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const PupilCoordinate& a = p[i];
    const PupilCoordinate& b = p[(i + 1) % p.size()];
    twice += a.px * b.py - b.px * a.py;
  }
  return 0.5 * twice;
}

double polygon_perimeter(const std::vector<PupilCoordinate>& p) {
  double length = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) length += std::hypot(p[(i + 1) % p.size()].px - p[i].px, p[(i + 1) % p.size()].py - p[i].py);
  return length;
}

}  // namespace

TEST_CASE("the f/1.1 double Gauss: the whole pupil passes on axis and less and less of it off axis", "[analysis][pupil]") {
  AnalysisOptions options;
  options.relative_fields = {0.0, 0.5, 1.0};  // 0, 6 and 12 degrees
  PupilShapeOptions o;
  o.grid = 48;
  o.outline_points = 48;
  const PupilShape shape = compute_pupil_shape(AnalysisContext(lensmith::testing::angenieux_double_gauss(), options), o);
  INFO(shape);
  REQUIRE(shape.fields.size() == 3);
  CHECK(shape.fields[0].area_fraction == 1.0);
  CHECK(shape.fields[0].losses.empty());
  CHECK(shape.fields[1].area_fraction < shape.fields[0].area_fraction);
  CHECK(shape.fields[2].area_fraction < shape.fields[1].area_fraction);
  CHECK(!shape.fields[2].losses.empty());
  std::size_t lost = 0;
  for (const SurfaceLoss& l : shape.fields[2].losses) lost += l.rays;
  CHECK(lost + shape.fields[2].rays_passed == shape.fields[2].rays_in_pupil);
}

TEST_CASE("the pupil outline encloses the passing area the grid counts, within half a cell along its length", "[analysis][pupil]") {
  AnalysisOptions options;
  options.relative_fields = {0.0, 1.0};
  PupilShapeOptions o;
  o.grid = 64;
  o.outline_points = 180;
  const PupilShape shape = compute_pupil_shape(AnalysisContext(lensmith::testing::angenieux_double_gauss(), options), o);
  for (const FieldPupilShape& f : shape.fields) {
    INFO("field " << f.field_label << ": area fraction " << f.area_fraction);
    REQUIRE(f.outline.size() == 180);
    for (const PupilCoordinate& p : f.outline) CHECK(p.px * p.px + p.py * p.py <= 1.0);
    const double cell = 2.0 / o.grid;
    const double grid_area = static_cast<double>(f.rays_passed) * cell * cell;
    // Each boundary cell is counted whole or not at all: the grid area can miss the true one by
    // about half a cell along the outline; the 180-gon's chords lose a little less than that.
    const double tolerance = polygon_perimeter(f.outline) * cell / 2.0;
    CHECK_THAT(polygon_area(f.outline), WithinAbs(grid_area, tolerance));
  }
  // On axis the outline is the unit circle.
  CHECK_THAT(polygon_area(shape.fields[0].outline), WithinAbs(kPi, 1e-3));
}
