// The shape of a defocused highlight whose beam the lens's clear apertures clip, against the ground
// truth through the lens (lib/scene/lens_render.h: real rays traced from the sensor through every
// surface into the scene). Where a clear aperture stops some of a footprint's rays, the exact and
// poly models cut its mesh's triangles where their corners' clearances cross 0
// (lib/render/src/footprint.cpp, record_mesh): the cat's eye's size, its width across the field and
// its place must be the ground truth's.
#include <catch2/catch.hpp>

#include <array>
#include <cmath>
#include <string>

#include "lensmith/prescription/lens_library.h"
#include "lensmith/render/bokeh_renderer.h"
#include "lensmith/scene/lens_render.h"
#include "lensmith/scene/pinhole_render.h"

#include "spot_moments.h"

using namespace lensmith;

TEST_CASE("A defocused highlight through a lens whose clear apertures clip its beam has the ground truth's cat's eye, through the exact model",
          "[scene][bokeh]") {
  // pbrt's 50 mm double Gauss at f/2 focused at 2 m: its clear apertures clip every beam (the axial
  // one by 2 % of its radius, the corners' to cat's eyes). Three glowing discs at 0.5 m, about 8 px of
  // blur: on the axis, at half the field and at 0.8 of the half-diagonal.
  // Tolerances: the ground truth's noise (256 rays a pixel, of which about a sixth reach a disc)
  // moves its moments by about 1 %; the model's rays are interpolated over field and depth
  // (mapped_pupil_table.h, within 0.02 px) and its triangles cut to first order. The spot's extent
  // along its long and short axes within 6 % (measured: within 1.1 % on the axis, 1.9 % at half the
  // field, 2.2 % at 0.8), its centroid within 0.3 px (0.13 px). Its light is the radiometry tests'
  // (bokeh_radiometry_test.cpp). With every stopped ray drawn as passing, the cat's eye at 0.8 of
  // the field came out 4.07 x 3.53 px where the truth's is 2.40 x 1.67.
  constexpr double kExtent = 0.06;
  constexpr double kCentroidPx = 0.3;
  const int w = 192, h = 128;
  CameraOptions co;
  co.focus_distance_m = 2.0;
  co.f_number = 2.0;
  const Camera camera = Camera::from_lens(LensLibrary::load("pbrt-dgauss-50mm").prescription, co, w, h);
  constexpr double kDepthM = 0.5;
  Scene scene;
  scene.name = "three glowing discs";
  const std::array<PixelPoint, 3> places{{{0.5 * w, 0.5 * h}, {0.75 * w, 0.5 * h}, {0.5 * w + 0.4 * w, 0.5 * h + 0.4 * h}}};
  for (const PixelPoint& p : places) {
    const Tangents t = camera.frame().tangents_at(p);
    SceneObject disc;
    disc.name = "disc";
    disc.shape = Disc{Eigen::Vector3d(t.x * kDepthM, t.y * kDepthM, kDepthM), Eigen::Vector3d(0.0, 0.0, -1.0), 0.004, std::nullopt};
    disc.material.emission = Rgb{10.0, 10.0, 10.0};
    scene.objects.push_back(disc);
  }
  LensRenderOptions ro;
  ro.spp = 256;
  ro.spectral = false;
  const LensRender truth = render_through_lens(scene, camera, ro);
  const PinholeRender input = render_pinhole(scene, camera.frame());
  RayModelOptions mo;
  mo.nearest_depth_m = 0.3;
  const auto exact = make_ray_model(RayModelKind::Exact, camera, mo);
  BokehOptions bo;
  bo.spectral = false;
  const Image out = render_bokeh(input.rgb, input.depth, *exact, Aperture::circular(), bo);
  constexpr int kWindow = 24;
  for (const PixelPoint& p : places) {
    // The window around the truth's spot (the lens's distortion moves it from the pinhole's place).
    const testing::SpotMoments around =
        testing::spot_moments(truth.rgb, 1, static_cast<int>(p.x) - kWindow / 2, static_cast<int>(p.y) - kWindow / 2, kWindow, kWindow);
    const int x0 = static_cast<int>(std::lround(around.x)) - kWindow / 2, y0 = static_cast<int>(std::lround(around.y)) - kWindow / 2;
    REQUIRE((x0 >= 0 && y0 >= 0 && x0 + kWindow <= w && y0 + kWindow <= h));
    const testing::SpotMoments t = testing::spot_moments(truth.rgb, 1, x0, y0, kWindow, kWindow);
    const testing::SpotMoments m = testing::spot_moments(out, 1, x0, y0, kWindow, kWindow);
    INFO("at (" << p.x << ", " << p.y << "): light " << m.light << " against the truth's " << t.light << ", centroid (" << m.x << ", "
                << m.y << ") against (" << t.x << ", " << t.y << "), extent " << m.major() << " x " << m.minor() << " px against "
                << t.major() << " x " << t.minor());
    CHECK(std::abs(m.x - t.x) < kCentroidPx);
    CHECK(std::abs(m.y - t.y) < kCentroidPx);
    CHECK(m.major() == Approx(t.major()).epsilon(kExtent));
    CHECK(m.minor() == Approx(t.minor()).epsilon(kExtent));
  }
}
