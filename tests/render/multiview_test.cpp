// Lee, Eisemann & Seidel's multiview synthesis (render_multiview) against the geometry of a thin
// lens (pbrt-v3 sec. 6.2.3: a ray from lens point a towards the focus-plane point of its pixel), and
// against the scatter path through a real lens:
// - in focus, every lens ray of a pixel meets the same cell: the picture comes back as it went in;
// - behind the edge of a blurred foreground half-plane, the share of a pixel's lens disc whose rays
//   the foreground blocks is the circle segment beyond a line, so a layered scene (background
//   behind the foreground) gives mixtures that a single picture cannot;
// - through a real lens (exact rays) a lit wall falls off towards the corners as the scatter path
//   says, which issue 12 checked against the path-traced ground truth.
#include <catch2/catch.hpp>
#include <cmath>

#include "lensmith/core/units.h"
#include "thin_lens_geometry.h"
#include "lensmith/prescription/lens_library.h"
#include "lensmith/render/bokeh_renderer.h"
#include "lensmith/render/multiview_renderer.h"

using namespace lensmith;

using test::disc_share_left_of;
using test::thin_camera;
constexpr double kFocalLengthMm = test::kThinFocalLengthMm;
constexpr double kFNumber = test::kThinFNumber;

TEST_CASE("Multiview: a textured plane in focus comes back as it went in, colours and all", "[render][multiview]") {
  // Every ray hits its pixel's own cell and the spectral round trip over evenly visited nodes is the identity: float rounding.
  constexpr double kInFocus = 1e-4;
  const int w = 48, h = 32;
  const Camera camera = thin_camera(w, h, 2.0);
  const auto model = make_ray_model(RayModelKind::Thin, camera);
  const Image image = test::textured_image(w, h);
  const DeepImage scene = deep_image_from_flat(image, DepthMap(w, h, 2.0f));
  MultiviewOptions o;
  o.threads = 2;
  const Image out = render_multiview(scene, *model, Aperture::circular(), o);
  // The thin lens has no colour and every ray hits the pixel's own cell; the spectral round trip over
  // nodes visited evenly is the identity (SpectralQuadrature): float rounding only.
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      for (int c = 0; c < 3; ++c) REQUIRE(out.at(x, y, c) == Approx(image.at(x, y, c)).margin(kInFocus).epsilon(kInFocus));
      REQUIRE(out.at(x, y, 3) == Approx(1.0f));
    }
  }
}

TEST_CASE("Multiview: beside a blurred foreground edge, a layered scene shows the circle segment a thin lens's rays see",
          "[render][multiview]") {
  // A red half-plane at 0.6 m covers the pinhole image left of the edge; behind it and everywhere
  // else a blue wall at 3 m, in focus. The rays of a pixel at tangent t_p meet the wall at t_p z_2;
  // the ray from lens point a crosses the foreground's plane at tangent t_p + a_x (1/z_1 - 1/z_2)
  // and is blocked where that is left of the edge's tangent t_e: a_x < (t_e - t_p) / (1/z_1 - 1/z_2).
  const int w = 120, h = 40, edge = 60;
  const double z1_m = 0.6, z2_m = 3.0;
  const Camera camera = thin_camera(w, h, z2_m);
  const auto model = make_ray_model(RayModelKind::Thin, camera);
  const std::array<float, 3> red{1.0f, 0.1f, 0.05f}, blue{0.05f, 0.2f, 1.0f};
  DeepImage layered(w, h), flat(w, h);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const DeepSample wall{blue, 1.0f, static_cast<float>(z2_m), static_cast<float>(z2_m)};
      const DeepSample front{red, 1.0f, static_cast<float>(z1_m), static_cast<float>(z1_m)};
      if (x < edge) {
        layered.push_pixel({front, wall});
        flat.push_pixel({front});
      } else {
        layered.push_pixel({wall});
        flat.push_pixel({wall});
      }
    }
  }
  MultiviewOptions o;
  o.threads = 2;
  o.samples = 64;
  o.vignetting = false;
  o.spectral = false;  // geometry here; one wavelength per ray would add colour noise
  const Image a = render_multiview(layered, *model, Aperture::circular(), o);
  const Image b = render_multiview(flat, *model, Aperture::circular(), o);
  const PinholeFrame& frame = camera.frame();
  const double pupil_radius_mm = kFocalLengthMm / (2.0 * kFNumber);
  const double t_e = frame.tangents_at({static_cast<double>(edge), 0.0}).x;
  const double parallax_per_mm = 1.0 / mm_from_m(z1_m) - 1.0 / mm_from_m(z2_m);
  double worst_layered = 0.0, worst_flat = 0.0;
  for (int x = 0; x < w; ++x) {
    const double t_p = frame.tangents_at({x + 0.5, 0.0}).x;
    const double blocked = disc_share_left_of((t_e - t_p) / parallax_per_mm / pupil_radius_mm);
    // The red channel over the middle rows (each pixel's lens samples differ; the mean over rows
    // leaves the geometry): expected blocked red + unblocked blue.
    double mean_a = 0.0, mean_b = 0.0;
    for (int y = 5; y < h - 5; ++y) {
      mean_a += a.at(x, y, 0);
      mean_b += b.at(x, y, 0);
    }
    mean_a /= h - 10;
    mean_b /= h - 10;
    const double expected = blocked * red[0] + (1.0 - blocked) * blue[0];
    INFO("x " << x << ": blocked share " << blocked << ", expected red " << expected << ", layered " << mean_a << ", flat " << mean_b);
    // 64 samples a pixel over 30 rows (the pixels' windows into the 128-point set), cone tracing on:
  // observed at most 0.025 (0.022 without it).
    CHECK(std::abs(mean_a - expected) < 0.03);
    worst_layered = std::max(worst_layered, std::abs(mean_a - expected));
    worst_flat = std::max(worst_flat, std::abs(mean_b - expected));
  }
  // The single picture has no wall behind the foreground: its unblocked rays there are lost and the
  // foreground's red fills in for them.
  INFO("worst column error: layered " << worst_layered << ", flat " << worst_flat);
  CHECK(worst_flat > 0.2);
}

TEST_CASE("Multiview through the exact tracer: a lit wall falls off towards the corners as the scatter path's exact model says",
          "[render][multiview][radiometry]") {
  // A uniform wall in focus through the double Gauss at f/2, framed to its 36 mm width: the corners
  // are darker by cos^4-type falloff and the cat's-eye vignetting of the rims. The scatter path's
  // exact model was checked against the path-traced ground truth (issue 12); multiview's rays are
  // LensCamera's, a different sampling of the same lens (pbrt's weight over the exit pupil's disc).
  // Two samplings of the same pupil at the centre, multiview's 256 rays a pixel against the scatter's mesh; not derived.
  constexpr double kCentreLight = 0.02;
  const Prescription lens = LensLibrary::load("pbrt-dgauss-50mm").prescription;
  CameraOptions o;
  o.focus_distance_m = 5.0;
  o.f_number = 2.0;
  const int w = 96, h = 64;
  const Camera camera = Camera::from_lens(lens, o, w, h);
  const auto model = make_ray_model(RayModelKind::Exact, camera);
  Image wall(w, h, 3, 1.0f);
  const DepthMap depth(w, h, 5.0f);
  MultiviewOptions mv;
  mv.samples = 256;
  mv.threads = 2;
  const Image a = render_multiview(deep_image_from_flat(wall, depth), *model, Aperture::circular(), mv);
  BokehOptions sc;
  sc.threads = 2;
  const Image b = render_bokeh(wall, depth, *model, Aperture::circular(), sc);
  // Means over 4 x 4 px patches (the multiview estimate's noise), green channel.
  auto patch = [](const Image& im, int x0, int y0) {
    double s = 0.0;
    for (int y = y0; y < y0 + 4; ++y) {
      for (int x = x0; x < x0 + 4; ++x) s += im.at(x, y, 1);
    }
    return s / 16.0;
  };
  const double centre_a = patch(a, w / 2 - 2, h / 2 - 2), centre_b = patch(b, w / 2 - 2, h / 2 - 2);
  INFO("centre: multiview " << centre_a << ", scatter " << centre_b);
  CHECK(centre_a == Approx(centre_b).epsilon(kCentreLight));
  for (const auto& [x, y] : std::vector<std::pair<int, int>>{{0, 0}, {w - 4, 0}, {0, h - 4}, {w - 4, h - 4}, {w / 2 - 2, 0}, {0, h / 2 - 2}}) {
    const double ra = patch(a, x, y) / centre_a, rb = patch(b, x, y) / centre_b;
    INFO("patch at " << x << ", " << y << ": multiview " << ra << " of the centre, scatter " << rb);
    // The corners come out at about 0.2 of the centre, the top edge's middle at 0.6; the two samplings of
    // the pupil agree within 0.03 (observed at most 0.023, 256 rays a pixel).
    CHECK(ra < 0.95);
    CHECK(std::abs(ra - rb) < 0.03);
  }
}

TEST_CASE("Multiview with cone tracing: few lens rays come closer to the converged picture of a blurred, spotted wall",
          "[render][multiview][cones]") {
  // Lee et al. sec. 4.4: with 8 rays a pixel, a wall of small bright spots far behind the focus plane
  // is a scatter of sparkles; each ray's cone averaging its window of the mipmapped layer spreads
  // them towards the discs that many rays converge to (here: 1024 rays without cones).
  // The light is kept but for the spots near the border, whose blur spreads beyond the frame.
  constexpr double kFrameMean = 0.02;
  const int w = 96, h = 64;
  const Camera camera = thin_camera(w, h, 0.6);
  const auto model = make_ray_model(RayModelKind::Thin, camera);
  Image image(w, h, 3, 0.05f);
  for (int y = 4; y < h; y += 9) {
    for (int x = 4; x < w; x += 11) {
      for (int c = 0; c < 3; ++c) image.at(x, y, c) = 20.0f;
    }
  }
  const DeepImage scene = deep_image_from_flat(image, DepthMap(w, h, 3.0f));
  MultiviewOptions o;
  o.threads = 2;
  o.spectral = false;
  o.samples = 1024;
  o.cone_tracing = false;
  const Image converged = render_multiview(scene, *model, Aperture::circular(), o);
  o.samples = 8;
  o.cone_tracing = false;
  const Image plain = render_multiview(scene, *model, Aperture::circular(), o);
  o.cone_tracing = true;
  const Image cones = render_multiview(scene, *model, Aperture::circular(), o);
  auto rms = [&](const Image& a) {
    double s = 0.0;
    for (std::size_t i = 0; i < a.data.size(); ++i) s += (a.data[i] - converged.data[i]) * (a.data[i] - converged.data[i]);
    return std::sqrt(s / static_cast<double>(a.data.size()));
  };
  const double e_plain = rms(plain), e_cones = rms(cones);
  INFO("blur " << camera.signed_coc_px(inverse_depth_per_mm(3.0)) << " px; RMS from converged: 8 rays " << e_plain << ", with cones "
               << e_cones << "; means " << plain.mean(1) << ", " << cones.mean(1) << ", " << converged.mean(1));
  CHECK(e_cones < 0.6 * e_plain);
  // The light is kept: the mean of the frame within 2 % (spots near the border spread beyond it).
  CHECK(cones.mean(1) == Approx(converged.mean(1)).epsilon(kFrameMean));
}

TEST_CASE("Multiview: no lens ray passes through an opaque floor that slopes across every depth layer", "[render][multiview]") {
  // A plane seen from above at a slant fills the frame: inverse depth linear in the row, from 1.5 m
  // at the bottom to 10 m at the top, focus at 1 m so every row is blurred. A continuous opaque
  // surface stops every ray, whichever layers its samples fall in and where a ray crosses it
  // between pixel centres or layer bounds (with and without cone tracing).
  const int w = 80, h = 60;
  const Camera camera = thin_camera(w, h, 1.0);
  const auto model = make_ray_model(RayModelKind::Thin, camera);
  DeepImage floor(w, h);
  for (int y = 0; y < h; ++y) {
    const double t = (y + 0.5) / h;  // 0 at the top
    const auto z = static_cast<float>(1.0 / ((1.0 - t) / 10.0 + t / 1.5));
    for (int x = 0; x < w; ++x) {
      const float v = ((x / 4 + y / 4) % 2) ? 0.8f : 0.2f;
      floor.push_pixel({DeepSample{{v, v, v}, 1.0f, z, z}});
    }
  }
  for (const bool cones : {true, false}) {
    for (const int layer_count : {1, 8, 16}) {
      MultiviewOptions o;
      o.threads = 2;
      o.layers = layer_count;
      o.cone_tracing = cones;
      MultiviewStatistics stats;
      render_multiview(floor, *model, Aperture::circular(), o, &stats);
      INFO((cones ? "cones, " : "no cones, ") << layer_count << " layers: " << stats.to_string());
      CHECK(stats.lost_rays == 0);
    }
  }
}
