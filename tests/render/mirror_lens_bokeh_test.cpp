// Bokeh through a mirror lens (issue 18): the shipped example Cassegrain (examples/lenses/cassegrain-500mm.json,
// the Handbook of Optics' classical Cassegrain scaled to 500 mm f/4, the secondary's shadow a central
// obscuration of 21 mm radius in a 62.6-mm beam) photographed by the exact model. Geometry says what comes
// out: the obscuration stops the pupil inside 21 / 62.6 = 0.336 of its radius, so a defocused point is a ring
// whose hole is that fraction of its outer radius; the other ray models, which assume a round refracting lens,
// refuse it; and the camera refuses what it cannot photograph yet (an odd number of mirrors, tilts).
#include <catch2/catch.hpp>
#include <cmath>
#include <string>
#include <vector>

#include "lensmith/camera/ray_model.h"
#include "lensmith/core/errors.h"
#include "lensmith/core/units.h"
#include "lensmith/glass/glass_catalog.h"
#include "lensmith/prescription/lens_file.h"
#include "lensmith/render/bokeh_renderer.h"

using namespace lensmith;

namespace {

Prescription example_cassegrain() {
  return read_lens_file(std::string(LENSMITH_SOURCE_DIR) + "/examples/lenses/cassegrain-500mm.json").prescription;
}

// The obscuration over the beam's radius at the entrance plane (the beam is parallel there for far points).
constexpr double kObscuredFraction = 21.0 / (0.5 * 500.5839 / 4.0);

Camera camera_at(const Prescription& lens, int width, int height) {
  CameraOptions o;
  o.focus_distance_m = 30.0;
  o.framing.sensor_width_mm = 36.0;
  return Camera::from_lens(lens, o, width, height);
}

}  // namespace

TEST_CASE("A mirror lens's exact model stops the pupil inside its central obscuration", "[render][mirror]") {
  const Camera camera = camera_at(example_cassegrain(), 160, 90);
  REQUIRE(camera.exact_model_only());
  const auto model = make_ray_model(RayModelKind::Exact, camera, {});
  // A point on the axis at 12 m (the focus is at 30 m): pupil points along x and y either side of the
  // obscuration's edge, 0.04 of the radius inside and outside it.
  const ScenePoint point{0.0, 0.0, 1.0 / 12000.0};
  std::vector<PupilPoint> pupil;
  for (double r : {kObscuredFraction - 0.04, kObscuredFraction + 0.04, 0.9}) {
    pupil.push_back({r, 0.0});
    pupil.push_back({0.0, -r});
  }
  std::vector<SensorHit> hits(pupil.size());
  model->map(point, kWavelengthD_nm, pupil, hits);
  for (std::size_t i = 0; i < pupil.size(); ++i) {
    INFO("pupil point " << pupil[i].x << ", " << pupil[i].y);
    CHECK(hits[i].unclipped);  // every ray lands, stopped or not (the beam's edges lie between rays)
    CHECK(hits[i].ok == (i >= 2));
  }
}

TEST_CASE("A defocused point through a mirror lens is a ring whose hole is the obscuration's share", "[render][mirror]") {
  constexpr int kWidth = 96, kHeight = 64;
  const Camera camera = camera_at(example_cassegrain(), kWidth, kHeight);
  const auto model = make_ray_model(RayModelKind::Exact, camera, {});
  // One bright pixel at 3 m over a black wall at 30 m (in focus): its bokeh is about 50 px across.
  Image image(kWidth, kHeight, 3, 0.0f);
  DepthMap depth(kWidth, kHeight, 30.0f);
  const int cx = kWidth / 2, cy = kHeight / 2;
  for (int c = 0; c < 3; ++c) image.at(cx, cy, c) = 1000.0f;
  depth.at(cx, cy) = 3.0f;
  BokehOptions options;
  options.spectral = false;
  const Image out = render_bokeh(image, depth, *model, Aperture::circular(), options);
  // The light along the row through the centre: the ring's inner and outer edges right of the centre, where
  // it crosses half its peak (interpolated between pixels: the 2-px reconstruction filter blurs a step
  // symmetrically about that crossing).
  std::vector<double> row(kWidth);
  double peak = 0.0;
  for (int x = 0; x < kWidth; ++x) {
    row[static_cast<std::size_t>(x)] = out.at(x, cy, 1);
    peak = std::max(peak, row[static_cast<std::size_t>(x)]);
  }
  REQUIRE(peak > 0.0);
  std::vector<double> crossings;  // px from the centre, where the row crosses half the peak
  for (int x = cx; x + 1 < kWidth; ++x) {
    const double a = row[static_cast<std::size_t>(x)] - 0.5 * peak, b = row[static_cast<std::size_t>(x) + 1] - 0.5 * peak;
    if ((a < 0.0) != (b < 0.0)) crossings.push_back(x - cx + a / (a - b));
  }
  INFO("centre " << row[static_cast<std::size_t>(cx)] << ", peak " << peak);
  REQUIRE(crossings.size() == 2);  // into the ring, out of it
  const double inner = crossings[0], outer = crossings[1];
  INFO("inner " << inner << " px, outer " << outer << " px");
  // The centre is dark (the obscuration's shadow), and the hole's radius is the obscured share of the ring's:
  // each edge to 0.3 px (the interpolation between pixels), 0.02 on the ratio of a ring 25 px in radius.
  CHECK(row[static_cast<std::size_t>(cx)] < 0.1 * peak);
  REQUIRE(outer > 20.0);
  // The beam from 3 m narrows by 100 / 3000 between the stop (the primary) and the entrance plane 100 mm in
  // front of it, so the obscuration takes that much more of it there.
  CHECK(std::abs(inner / outer - kObscuredFraction / (1.0 - 100.0 / 3000.0)) < 0.02);
}

TEST_CASE("The camera refuses what it cannot photograph through yet, and the other models refuse mirror lenses",
          "[render][mirror]") {
  const Camera camera = camera_at(example_cassegrain(), 32, 18);
  CHECK_THROWS_WITH(make_ray_model(RayModelKind::Seidel, camera, {}), Catch::Contains("--model exact") && Catch::Contains("2 mirrors"));
  // One mirror: the image faces the scene.
  Prescription single = example_cassegrain();
  single.surfaces.pop_back();
  single.surfaces.back().thickness_mm = -142.9;
  CHECK_THROWS_WITH(camera_at(single, 32, 18), Catch::Contains("odd number of mirrors"));
  // A tilt.
  Prescription tilted = example_cassegrain();
  Surface tilt;
  tilt.kind = SurfaceKind::CoordinateBreak;
  tilt.coordinate_break.tilt_x_deg = 1.0;
  tilted.surfaces.insert(tilted.surfaces.begin() + 1, tilt);
  tilted.resolve_materials(GlassCatalog::builtin());
  CHECK_THROWS_WITH(camera_at(tilted, 32, 18), Catch::Contains("tilted or decentred"));
}
