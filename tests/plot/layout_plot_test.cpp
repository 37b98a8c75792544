// The lens layout picture: every surface and the stop are drawn where the section puts them, and the
// section itself is the lens (vertices, stop, elements) traced by the real tracer.
#include "lensmith/plot/layout_plot.h"

#include <catch2/catch.hpp>

#include "reference_lenses.h"

using namespace lensmith;
using namespace lensmith::plot;

namespace {

// True when a pixel within `radius` px of `p` differs from the white background.
bool drawn_near(const Canvas& c, Point2 p, int radius) {
  for (int y = static_cast<int>(p.y) - radius; y <= static_cast<int>(p.y) + radius; ++y) {
    for (int x = static_cast<int>(p.x) - radius; x <= static_cast<int>(p.x) + radius; ++x) {
      if (x < 0 || y < 0 || x >= c.width() || y >= c.height()) continue;
      const Rgb q = c.pixel(x, y);
      if (q.r < 0.9f || q.g < 0.9f || q.b < 0.9f) return true;
    }
  }
  return false;
}

}  // namespace

TEST_CASE("lens layout of the Sasian triplet: three elements, the stop at surface 3, rays from three fields", "[plot][layout]") {
  const AnalysisContext context(lensmith::testing::sasian_triplet());
  const LensLayout layout = compute_lens_layout(context);
  REQUIRE(layout.surfaces.size() == 6);
  CHECK(layout.elements.size() == 3);
  REQUIRE(layout.stop_surface);
  CHECK(*layout.stop_surface == 3);
  CHECK(layout.rays.size() == 3 * 5);
  // The axial bundle passes: real aiming fills the stop without cutting its rim rays.
  for (const LayoutRay& r : layout.rays) {
    if (r.relative_field == 0.0) CHECK(r.status == RayStatus::Ok);
  }
  CHECK_THAT(layout.total_track_mm, Catch::Matchers::WithinAbs(layout.image_plane_z_mm, 1e-12));  // surface 1 at z = 0
}

TEST_CASE("lens layout picture: something is drawn at every surface vertex, at the stop's bars and on the image plane", "[plot][layout]") {
  const AnalysisContext context(lensmith::testing::angenieux_double_gauss(), [] {
    AnalysisOptions o;
    o.max_field_angle_deg = 15.0;
    return o;
  }());
  const LensLayout layout = compute_lens_layout(context);
  LayoutFrame frame;
  const Canvas picture = plot_lens_layout(layout, PlotOptions{}, &frame);
  for (const LayoutSurface& s : layout.surfaces) {
    INFO("surface " << s.surface << " at z = " << s.vertex_z_mm << " mm");
    // The profile's top end: the surface line (or the stop bar) is there, 2 px of anti-aliasing aside.
    CHECK(drawn_near(picture, frame.to_pixel(s.edge_z_mm(), s.semi_diameter_mm), 2));
  }
  REQUIRE(layout.stop_surface);
  const LayoutSurface& stop = layout.surfaces[static_cast<std::size_t>(*layout.stop_surface - 1)];
  // Just outside the stop's opening: the bar, not a ray.
  CHECK(drawn_near(picture, frame.to_pixel(stop.edge_z_mm(), -(stop.semi_diameter_mm * 1.05)), 1));
  CHECK(drawn_near(picture, frame.to_pixel(layout.image_plane_z_mm, 0.5 * layout.image_half_height_mm), 1));
  // Equal scales: a millimetre along z is as long as one along y.
  const Point2 o = frame.to_pixel(0.0, 0.0), z1 = frame.to_pixel(1.0, 0.0), y1 = frame.to_pixel(0.0, 1.0);
  CHECK_THAT(z1.x - o.x, Catch::Matchers::WithinRel(o.y - y1.y, 1e-12));
}

TEST_CASE("lens layout picture: no two labels overlap", "[plot][layout][labels]") {
  const AnalysisContext context(lensmith::testing::sasian_triplet());
  const Canvas picture = plot_lens_layout(compute_lens_layout(context));
  const auto& boxes = picture.text_boxes();
  REQUIRE(boxes.size() > 3);
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    for (std::size_t j = i + 1; j < boxes.size(); ++j) {
      INFO("\"" << boxes[i].text << "\" and \"" << boxes[j].text << "\"");
      CHECK_FALSE(boxes[i].box.intersects(boxes[j].box));
    }
  }
}
