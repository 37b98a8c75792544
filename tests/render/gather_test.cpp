// Jimenez's scatter-as-you-gather at half resolution (render_gather) and Tan et al.'s traced holes,
// against the thin lens's exact blur and the scatter method:
// - in focus nothing is gathered: the picture comes back as it went in;
// - a black-and-white step on a defocused plane takes the profile of the uniform disc of its circle
//   of confusion (the share of the disc on the white side), within the rings' undersampling;
// - a flat wall stays flat to the frame's edges through a real lens, and darkens towards them as
//   the scatter method integrates the same model's vignetting;
// - a blurred foreground spreads over a sharp background beyond its silhouette, the background
//   stays sharp beyond the foreground's reach (the composite);
// - the hybrid asks for rays along the blurred foreground's edge and not in the open, and what the
//   rays bring is what the picture shows there.
#include <catch2/catch.hpp>

#include <cmath>

#include "lensmith/core/errors.h"
#include "lensmith/core/units.h"
#include "lensmith/prescription/lens_library.h"
#include "lensmith/render/bokeh_renderer.h"
#include "lensmith/render/gather_renderer.h"
#include "thin_lens_geometry.h"

using namespace lensmith;

using test::thin_camera;

TEST_CASE("Gather: a textured plane in focus comes back as it went in", "[render][gather]") {
  // No tile is gathered: the composite takes the sharp picture, values up to 4.0 in float.
  constexpr double kSharpComposite = 1e-5;
  const int w = 48, h = 32;
  const Camera camera = thin_camera(w, h, 2.0);
  const auto model = make_ray_model(RayModelKind::Thin, camera);
  const Image image = test::textured_image(w, h);
  GatherOptions o;
  o.threads = 2;
  GatherStatistics stats;
  const Image out = render_gather(image, DepthMap(w, h, 2.0f), *model, Aperture::circular(), o, &stats);
  // No blur: no tile is gathered, and the composite takes the sharp picture (float rounding).
  CHECK(stats.gathered_pixels == 0);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      for (int c = 0; c < 3; ++c) REQUIRE(out.at(x, y, c) == Approx(image.at(x, y, c)).margin(kSharpComposite));
    }
  }
}

TEST_CASE("Gather: a step on a defocused plane takes the profile of the uniform disc of its circle of confusion",
          "[render][gather]") {
  // The gathered mean moves no light across the step; not derived: the bound this test was written with.
  constexpr double kStepLight = 0.01;
  const int w = 160, h = 48, edge = 80;
  const Camera camera = thin_camera(w, h, 3.0);
  const auto model = make_ray_model(RayModelKind::Thin, camera);
  for (const double blur_px : {12.0, 32.0}) {
    const double z_m = test::near_depth_for_blur(camera, 3.0, blur_px);
    const double radius = 0.5 * std::abs(camera.signed_coc_px(inverse_depth_per_mm(z_m)));
    Image image(w, h, 3, 0.0f);
    for (int y = 0; y < h; ++y) {
      for (int x = edge; x < w; ++x) {
        for (int c = 0; c < 3; ++c) image.at(x, y, c) = 1.0f;
      }
    }
    for (const int rings : {3, 4}) {
      GatherOptions o;
      o.threads = 2;
      o.rings = rings;
      const Image out = render_gather(image, DepthMap(w, h, static_cast<float>(z_m)), *model, Aperture::circular(), o);
      // The exact profile: the share of the disc centred on the pixel that lies on the white side.
      double worst = 0.0, total = 0.0, expected_total = 0.0;
      for (int x = 0; x < w; ++x) {
        const double expected = 1.0 - test::disc_share_left_of((edge - (x + 0.5)) / radius);
        const double got = out.at(x, h / 2, 1);
        worst = std::max(worst, std::abs(got - expected));
        total += got;
        expected_total += expected;
      }
      INFO(blur_px << " px, " << rings << " rings: largest difference from the disc's profile " << worst << ", light "
                   << total << " against " << expected_total);
      // The rings sample the disc at 49 (81) taps over a prefilter of R / 6 (R / 8), at half
      // resolution, with the median after: observed 0.017-0.060.
      CHECK(worst < 0.09);
      // A step keeps its light (the gathered mean moves none across it): within 1 % of the row.
      CHECK(total == Approx(expected_total).epsilon(kStepLight));
    }
  }
}

TEST_CASE("Gather: a flat wall through a real lens stays flat to the frame's edges", "[render][gather]") {
  // Weighted means of one colour, and the sharp picture read inside the frame: float rounding.
  constexpr double kOneColour = 1e-4;
  // The PSF table's 512 pupil points and smoothed clipping edge against the scatter's pupil mesh: 2.2 % measured at the centre.
  constexpr double kVignettingCentre = 0.03;
  // The same towards the corners, where the clear apertures clip the beams, and where both now take
  // the lens's distortion (the scatter a pixel's image area as its coverage, the gather's throughput
  // divided by it): the gather's corner pixel is 5.0 % brighter than the scatter's, which is within
  // 0.5 % of the ground truth there (tests/scene bokeh_radiometry_test.cpp; docs/bokeh.md).
  constexpr double kVignettingEdges = 0.06;
  const int w = 96, h = 64;
  CameraOptions co;
  co.focus_distance_m = 3.0;
  co.f_number = 2.0;
  const Camera camera = Camera::from_lens(LensLibrary::load("pbrt-dgauss-50mm").prescription, co, w, h);
  RayModelOptions mo;
  mo.nearest_depth_m = 0.5;
  const auto model = make_ray_model(RayModelKind::Seidel, camera, mo);
  const Image image(w, h, 3, 0.5f);
  for (const double z_m : {3.0, 1.0}) {
    GatherOptions o;
    o.threads = 2;
    o.vignetting = false;
    const Image out = render_gather(image, DepthMap(w, h, static_cast<float>(z_m)), *model, Aperture::circular(), o);
    double lo = 1.0, hi = 0.0;
    for (float v : out.data) {
      lo = std::min(lo, static_cast<double>(v));
      hi = std::max(hi, static_cast<double>(v));
    }
    INFO("wall at " << z_m << " m: " << lo << " .. " << hi);
    // Weighted means of one colour, and a sharp picture read inside the frame (the lens's shift
    // clamps at the edge): the colour itself (float rounding).
    CHECK(lo == Approx(0.5).epsilon(kOneColour));
    CHECK(hi == Approx(0.5).epsilon(kOneColour));
    // With vignetting, the frame darkens as the scatter method integrates the same model's
    // weights: 3 % at the centre, 5 % towards the corners (the PSF table's 512 pupil points and
    // its smoothed clipping edge; measured 2.2 % low at the centre of the wall at 1 m).
    o.vignetting = true;
    const Image lit = render_gather(image, DepthMap(w, h, static_cast<float>(z_m)), *model, Aperture::circular(), o);
    BokehOptions bo;
    bo.spectral = false;
    bo.threads = 2;
    const Image scatter = render_bokeh(image, DepthMap(w, h, static_cast<float>(z_m)), *model, Aperture::circular(), bo);
    CHECK(lit.at(w / 2, h / 2, 1) == Approx(scatter.at(w / 2, h / 2, 1)).epsilon(kVignettingCentre));
    for (int x = 2; x < w / 2; x += 6) {
      const int y = x * h / w;
      INFO("(" << x << ", " << y << "): gather " << lit.at(x, y, 1) << ", scatter " << scatter.at(x, y, 1));
      CHECK(lit.at(x, y, 1) == Approx(scatter.at(x, y, 1)).epsilon(kVignettingEdges));
    }
  }
}

namespace {

// A white foreground strip at `near_m` (blurred) over a black background in focus at 3 m, the
// strip's right edge at column `edge`.
struct Strip {
  static constexpr int w = 200, h = 40, edge = 100;
  Image image{w, h, 3, 0.0f};
  DepthMap depth{w, h, 3.0f};
  explicit Strip(double near_m) {
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < edge; ++x) {
        for (int c = 0; c < 3; ++c) image.at(x, y, c) = 1.0f;
        depth.at(x, y) = static_cast<float>(near_m);
      }
    }
  }
};

// Beyond the blurred foreground's reach the black background is the sharp picture: 0 (Approx(0) needs a margin).
constexpr double kBeyondReach = 1e-6;
// Well inside the white foreground the taps gather white only; not derived: the bound these tests were written with.
constexpr double kInsideForeground = 0.02;

}  // namespace

TEST_CASE("Gather: a blurred foreground spreads over a sharp background, which stays sharp beyond its reach", "[render][gather]") {
  // Half resolution, the prefilter and the upsampling widen the edge; this still catches the foreground's alpha applied
  // twice (a blurred edge read 0.34 where the disc's share is 0.5, docs/methods.md).
  constexpr double kSilhouette = 0.12;
  const Camera camera = thin_camera(Strip::w, Strip::h, 3.0);
  const auto model = make_ray_model(RayModelKind::Thin, camera);
  const double z_m = test::near_depth_for_blur(camera, 3.0, 24.0);
  const double radius = 0.5 * std::abs(camera.signed_coc_px(inverse_depth_per_mm(z_m)));
  const Strip strip(z_m);
  GatherOptions o;
  o.threads = 2;
  const Image out = render_gather(strip.image, strip.depth, *model, Aperture::circular(), o);
  const int y = Strip::h / 2;
  INFO("radius " << radius << " px; at the edge " << out.at(Strip::edge, y, 1) << ", half a radius out "
                 << out.at(Strip::edge + static_cast<int>(radius / 2), y, 1));
  // At its silhouette the foreground covers half of a pixel's view of the lens, and its light
  // fades to nothing one radius beyond (the scatter method's exact answer: the disc's share).
  CHECK(out.at(Strip::edge, y, 1) == Approx(0.5).margin(kSilhouette));
  CHECK(out.at(Strip::edge + static_cast<int>(radius / 2), y, 1) == Approx(1.0 - test::disc_share_left_of(0.5)).margin(kSilhouette));
  CHECK(out.at(Strip::edge + static_cast<int>(radius) + 4, y, 1) < 0.02);
  CHECK(out.at(Strip::w - 5, y, 1) == Approx(0.0).margin(kBeyondReach));
  // Inside the foreground, white.
  CHECK(out.at(Strip::edge - static_cast<int>(radius) - 4, y, 1) == Approx(1.0).margin(kInsideForeground));
}

TEST_CASE("Gather: the hybrid traces rays along a blurred foreground's edge, not in the open, and composites what they bring",
          "[render][gather]") {
  const Camera camera = thin_camera(Strip::w, Strip::h, 3.0);
  const auto model = make_ray_model(RayModelKind::Thin, camera);
  const double z_m = test::near_depth_for_blur(camera, 3.0, 24.0);
  const Strip strip(z_m);
  // A tracer that sees a red world: where its colour shows, the composite took the rays.
  std::size_t requests = 0;
  int most_rays = 0;
  bool squares_ok = true;
  GatherOptions o;
  o.threads = 2;
  o.trace_rays = 16;
  o.trace = [&](std::vector<GatherTraceRequest>& all) {
    requests = all.size();
    for (GatherTraceRequest& r : all) {
      most_rays = std::max(most_rays, r.rays);
      squares_ok = squares_ok && r.size_px == 1.0f && r.x_px >= 0.0f && r.x_px + r.size_px <= Strip::w && r.y_px >= 0.0f &&
                   r.y_px + r.size_px <= Strip::h;
      r.rgb = {1.0f, 0.0f, 0.0f};
      r.reached = r.rays;
    }
  };
  GatherStatistics stats;
  const Image out = render_gather(strip.image, strip.depth, *model, Aperture::circular(), o, &stats);
  CHECK(squares_ok);
  CHECK(most_rays <= 4);  // a quarter of 16 through each output pixel
  CHECK(requests == stats.traced_pixels);
  const int y = Strip::h / 2;
  INFO(requests << " requests; at the edge R " << out.at(Strip::edge, y, 0) << " G " << out.at(Strip::edge, y, 1));
  // Along the edge the rays' colour takes over (the mask is ~1 where the foreground half covers).
  CHECK(out.at(Strip::edge, y, 0) > 0.8);
  CHECK(out.at(Strip::edge, y, 1) < 0.3);
  // In the open, far from any edge, nothing was traced: the picture's own colours.
  CHECK(out.at(10, y, 1) == Approx(1.0).margin(kInsideForeground));
  CHECK(out.at(Strip::w - 5, y, 0) == Approx(0.0).margin(kBeyondReach));
  // Fewer than a quarter of the pixels.
  CHECK(requests < static_cast<std::size_t>(Strip::w * Strip::h / 4));
}

TEST_CASE("Gather: options that cannot work are refused", "[render][gather]") {
  const Camera camera = thin_camera(16, 16, 3.0);
  const auto model = make_ray_model(RayModelKind::Thin, camera);
  const Image image(16, 16, 3, 0.5f);
  const DepthMap depth(16, 16, 3.0f);
  GatherOptions o;
  o.rings = 5;
  CHECK_THROWS_AS(render_gather(image, depth, *model, Aperture::circular(), o), OptionsError);
  o = GatherOptions{};
  o.trace_rays = 0;
  CHECK_THROWS_AS(render_gather(image, depth, *model, Aperture::circular(), o), OptionsError);
  CHECK_THROWS_AS(render_gather(image, DepthMap(8, 16, 3.0f), *model, Aperture::circular()), OptionsError);
  CHECK_THROWS_AS(render_gather(image, depth, *model, Aperture::mask(2, 2, {1.0f, 1.0f, 1.0f, 0.0f})), OptionsError);
}
