// Křivánek et al.'s EWA splatting (render_ewa) against the paper's own kernel and a thin lens:
// - in focus, each surfel's kernel is a Gaussian of 0.3 px: the picture comes back nearly as it went in;
// - one bright pixel on a defocused plane keeps its light and spreads as the L2-best Gaussian of its
//   circle of confusion, variance R^2 / (2 ln 4) (derived in ewa_renderer.h), whether that comes from
//   the formula (the paper) or from the moments of the ray model's rays (lensmith's table);
// - the level of detail leaves the picture as it was and keeps the work per pixel nearly flat from
//   8 to 64 px of blur, where drawing every pixel grows with the blur's area (the paper's table 1);
// - a sharp foreground keeps its colour up to its edge over a blurred background (no intensity
//   leakage, the paper's sec. 5), and a flat wall stays flat to the frame's edges through a real lens.
#include <catch2/catch.hpp>

#include <cmath>

#include "lensmith/core/units.h"
#include "lensmith/prescription/lens_library.h"
#include "lensmith/render/bokeh_renderer.h"
#include "lensmith/render/ewa_renderer.h"
#include "thin_lens_geometry.h"

using namespace lensmith;

using test::thin_camera;

TEST_CASE("EWA: a textured plane in focus comes back nearly as it went in", "[render][ewa]") {
  // Each neighbour gets 0.39 % of a pixel's weight from its sharp kernel: a 4.0 dot moves a 0.2 pixel by 4 x 0.4 % x 4 = 0.064.
  constexpr double kOwnKernelSpread = 0.07;
  const int w = 48, h = 32;
  const Camera camera = thin_camera(w, h, 2.0);
  const auto model = make_ray_model(RayModelKind::Thin, camera);
  const Image image = test::textured_image(w, h);
  EwaOptions o;
  o.threads = 2;
  EwaStatistics stats;
  const Image out = render_ewa(image, DepthMap(w, h, 2.0f), *model, Aperture::circular(), o, &stats);
  // A surfel's own Gaussian (sigma 0.3 px) gives each neighbour exp(-1 / 0.18) = 0.39 % of its
  // pixel's weight before normalisation: a 4.0 dot beside 0.2 pixels moves them by at most 4 x 0.4 %
  // of the dot, 0.016 x 4.
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      for (int c = 0; c < 3; ++c) REQUIRE(out.at(x, y, c) == Approx(image.at(x, y, c)).margin(kOwnKernelSpread));
    }
  }
  CHECK(stats.splats_per_level[0] == stats.splats);  // nothing blurred: every pixel its own splat
  CHECK(stats.unfilled_pixels == 0);
}

TEST_CASE("EWA: one bright pixel on a defocused plane keeps its light and spreads as the L2-best Gaussian of its circle of confusion",
          "[render][ewa]") {
  // The plane's fragments share weights that sum to 1: the bright pixel's light, but for float sums (about 1e-4).
  constexpr double kBrightPixelLight = 1e-3;
  const int w = 101, h = 101, cx = 50, cy = 50;
  const Camera camera = thin_camera(w, h, 3.0);
  const double z_m = test::near_depth_for_blur(camera, 3.0, 16.0);
  const double radius = 0.5 * std::abs(camera.signed_coc_px(inverse_depth_per_mm(z_m)));
  const auto model = make_ray_model(RayModelKind::Thin, camera);
  Image image(w, h, 3, 0.0f);
  for (int c = 0; c < 3; ++c) image.at(cx, cy, c) = 1.0f;
  // The paper's variance for a uniform disc of radius R, plus the surfel's own 0.3 px.
  const double expected = radius * radius / (2.0 * std::log(4.0)) + 0.09;
  for (const bool lens_psf : {false, true}) {
    for (const bool lod : {false, true}) {
      EwaOptions o;
      o.threads = 2;
      o.lens_psf = lens_psf;
      o.level_of_detail = lod;
      const Image out = render_ewa(image, DepthMap(w, h, static_cast<float>(z_m)), *model, Aperture::circular(), o);
      double total = 0.0, sxx = 0.0, syy = 0.0, sxy = 0.0;
      for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
          const double v = out.at(x, y, 1);
          total += v;
          sxx += v * (x - cx) * (x - cx);
          syy += v * (y - cy) * (y - cy);
          sxy += v * (x - cx) * (y - cy);
        }
      }
      INFO((lens_psf ? "the lens's moments" : "the paper's formula") << (lod ? ", level of detail" : "") << ": light " << total
                                                                      << ", variances " << sxx / total << " / " << syy / total
                                                                      << " px^2, expected " << expected);
      // Light: the plane is one surface, so its black pixels and the bright one share fragments
      // whose weights sum to 1: the bright pixel's light, all of it (float sums: 1e-4).
      CHECK(total == Approx(1.0).epsilon(kBrightPixelLight));
      // Spread: the moments of 128 pupil points (8 equal-area rings: a disc's second moment is
      // exact) and of the cut-off, renormalised Gaussian (3 sigma holds 98.9 % of its mass, and
      // the cut-off's tail is narrower: -4.4 % of the variance) against the formula: 6 %. With the
      // level of detail the bright pixel is averaged into a block whose blur stands in for it: the
      // variance then grows by the block's width (sigma^2 of the level), at most 25 % here.
      const double tolerance = lod ? 0.25 : 0.06;
      CHECK(sxx / total == Approx(expected).epsilon(tolerance));
      CHECK(syy / total == Approx(expected).epsilon(tolerance));
      CHECK(std::abs(sxy / total) < 0.02 * expected);
    }
  }
}

TEST_CASE("EWA: the level of detail keeps the work per pixel nearly flat as the blur grows, and the picture as it was",
          "[render][ewa]") {
  const int w = 160, h = 120;
  const Camera camera = thin_camera(w, h, 3.0);
  const auto model = make_ray_model(RayModelKind::Thin, camera);
  const Image image = test::textured_image(w, h);
  auto writes = [&](double blur_px, bool lod, Image* picture) {
    EwaOptions o;
    o.threads = 2;
    o.level_of_detail = lod;
    EwaStatistics stats;
    const DepthMap depth(w, h, static_cast<float>(test::near_depth_for_blur(camera, 3.0, blur_px)));
    const Image out = render_ewa(image, depth, *model, Aperture::circular(), o, &stats);
    if (picture) *picture = out;
    return static_cast<double>(stats.pixel_writes) / (w * h);
  };
  const double lod8 = writes(8.0, true, nullptr), lod64 = writes(64.0, true, nullptr);
  const double all8 = writes(8.0, false, nullptr), all64 = writes(64.0, false, nullptr);
  INFO("pixel writes per pixel: level of detail " << lod8 << " -> " << lod64 << ", every pixel " << all8 << " -> " << all64);
  // The blur's area grows 64 times; every pixel's splat grows with it (the frame's margin grows too).
  CHECK(all64 > 30.0 * all8);
  // With the level of detail a coarser level takes over every doubling of the blur (observed
  // within a factor of 2 across 8-64 px).
  CHECK(lod64 < 3.0 * lod8);
  CHECK(lod8 < 3.0 * lod64);
  // And the picture barely changes: a textured plane blurred by 24 px with and without it.
  Image with, without;
  writes(24.0, true, &with);
  writes(24.0, false, &without);
  double worst = 0.0, worst_edge = 0.0;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const bool edge = x < 3 || y < 3 || x >= w - 3 || y >= h - 3;
      for (int c = 0; c < 3; ++c) (edge ? worst_edge : worst) = std::max(edge ? worst_edge : worst, static_cast<double>(std::abs(with.at(x, y, c) - without.at(x, y, c))));
    }
  }
  // Red is a sawtooth of period 11 px (0.1 to 0.4), blue one of period 7, green 0.2 with 4.0 dots:
  // coarse levels sample them every 8 px, and what their binomial filter lets through aliases into
  // a slow beat. Observed 0.0076 inside the frame and 0.0093 at its edges (a box filter instead of
  // the binomial: 0.034 and 0.053).
  INFO("largest difference " << worst << ", within 3 px of the frame's edges " << worst_edge);
  CHECK(worst < 0.012);
  CHECK(worst_edge < 0.015);
}

TEST_CASE("EWA: a sharp foreground keeps its colour up to its edge over a blurred background (no intensity leakage)",
          "[render][ewa]") {
  // The last column gets 0.4 % of the black wall from its own sharp kernel.
  constexpr double kSharpForeground = 0.01;
  const int w = 240, h = 40, edge = 120;
  const Camera camera = thin_camera(w, h, 0.6);
  const auto model = make_ray_model(RayModelKind::Thin, camera);
  // Left: a white foreground in focus at 0.6 m; right: a black wall at 10 m, blurred by 26 px.
  Image image(w, h, 3, 0.0f);
  DepthMap depth(w, h, 10.0f);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < edge; ++x) {
      for (int c = 0; c < 3; ++c) image.at(x, y, c) = 1.0f;
      depth.at(x, y) = 0.6f;
    }
  }
  REQUIRE(std::abs(camera.signed_coc_px(inverse_depth_per_mm(10.0))) > 20.0);
  EwaOptions o;
  o.threads = 2;
  const Image out = render_ewa(image, depth, *model, Aperture::circular(), o);
  // The wall's blur reaches 23 px (3 sigma of its Gaussian) into the foreground's pixels, behind
  // it: they stay white (the last column gets 0.4 % of the wall from its own sharp kernel).
  for (int x = edge - 23; x < edge; ++x) {
    INFO("column " << x);
    CHECK(out.at(x, h / 2, 1) == Approx(1.0).margin(kSharpForeground));
  }
  // And the foreground's edge stays sharp: the first wall pixel is dark.
  CHECK(out.at(edge, h / 2, 1) < 0.02);
}

TEST_CASE("EWA: a flat wall through a real lens stays flat to the frame's edges", "[render][ewa]") {
  // pbrt's double Gauss at f/2, focused at 3 m; the wall at 3 m (in focus) and at 1 m (blurred).
  // Its distortion moves centroids inwards at the edges: the picture continues beyond the frame, so
  // the last columns are reached as the others (without the margin they kept the input's colour).
  // One surface everywhere: each pixel's fragment is renormalised by its weight (float sums).
  constexpr double kOneSurface = 1e-4;
  // The table's 256 pupil points against the scatter's pupil mesh, at the centre ...
  constexpr double kVignettingCentre = 0.02;
  // ... and out to the corners, where the clear apertures clip the beams (6 % of even the axial beam here).
  constexpr double kVignettingEdges = 0.05;
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
    EwaOptions o;
    o.threads = 2;
    o.vignetting = false;
    EwaStatistics stats;
    const Image out = render_ewa(image, DepthMap(w, h, static_cast<float>(z_m)), *model, Aperture::circular(), o, &stats);
    double lo = 1.0, hi = 0.0;
    for (float v : out.data) {
      lo = std::min(lo, static_cast<double>(v));
      hi = std::max(hi, static_cast<double>(v));
    }
    INFO("wall at " << z_m << " m: " << lo << " .. " << hi);
    // One surface everywhere: each pixel's fragment is renormalised by its weight (float sums).
    CHECK(lo == Approx(0.5).epsilon(kOneSurface));
    CHECK(hi == Approx(0.5).epsilon(kOneSurface));
    CHECK(stats.unfilled_pixels == 0);
    // With vignetting the frame darkens towards its edges as the lens's relative illumination
    // does (the table's throughput), as the scatter method integrates the same ray model's weights
    // over its footprints: within 2 % at the centre and 5 % out to the corners (the table's 256
    // pupil points against the scatter's pupil mesh; this lens clips 6 % of even the axial beam).
    o.vignetting = true;
    const Image lit = render_ewa(image, DepthMap(w, h, static_cast<float>(z_m)), *model, Aperture::circular(), o);
    BokehOptions bo;
    bo.spectral = false;
    bo.threads = 2;
    const Image scatter = render_bokeh(image, DepthMap(w, h, static_cast<float>(z_m)), *model, Aperture::circular(), bo);
    CHECK(lit.at(w / 2, h / 2, 1) == Approx(scatter.at(w / 2, h / 2, 1)).epsilon(kVignettingCentre));
    for (int x = 2; x < w / 2; x += 6) {
      const int y = x * h / w;
      INFO("(" << x << ", " << y << "): ewa " << lit.at(x, y, 1) << ", scatter " << scatter.at(x, y, 1));
      CHECK(lit.at(x, y, 1) == Approx(scatter.at(x, y, 1)).epsilon(kVignettingEdges));
    }
    CHECK(lit.at(1, 1, 1) < 0.6 * lit.at(w / 2, h / 2, 1));
  }
}
