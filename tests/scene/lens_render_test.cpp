// The ground truth through the lens against outside truth: a near-perfect lens (the Sasian triplet
// of ray-optics' documentation, at f/8 over a 6 degree field) makes the pinhole picture of its focus
// plane; Monte-Carlo noise falls as 1 / sqrt(samples); the normalisation gives a uniform wall its
// radiance; the thin lens blurs a point into the circle of confusion A f |z - s| / (z s) of
// docs/bokeh.md; the result does not depend on the thread count.
#include "lensmith/scene/lens_render.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

#include "lensmith/core/errors.h"
#include "lensmith/core/units.h"
#include "lensmith/prescription/lens_library.h"
#include "lensmith/render/image_metrics.h"
#include "lensmith/scene/pinhole_render.h"

#include "brightest_pixel.h"

using Catch::Matchers::Contains;
using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;
using namespace lensmith;
using lensmith::testing::brightest;

namespace {

constexpr int kWidth = 96;
constexpr int kHeight = 64;
constexpr double kFocusM = 3.0;
// 200 mm pinhole framing on a 36 mm sensor: the Sasian triplet (EFL 50 mm) uses a 9 x 6 mm patch
// of its sensor, about 6 degrees of field, where it is near-perfect at f/8.
constexpr double kPinholeFocalMm = 200.0;

SceneObject textured_wall(double z_m) {
  SceneObject o;
  Rectangle r;
  r.centre_m = {0.0, 0.0, z_m};
  r.half_u_m = {2.0, 0.0, 0.0};
  r.half_v_m = {0.0, 2.0, 0.0};
  o.shape = r;
  // Squares of 25 mm: about 4.4 px at 3 m in this framing.
  o.material.albedo = CheckerTexture{0.025, {Rgb{0.8, 0.75, 0.7}, Rgb{0.05, 0.08, 0.1}}};
  return o;
}

SceneObject highlight(const Eigen::Vector3d& centre_m, double radius_m, double radiance) {
  SceneObject o;
  o.shape = Sphere{centre_m, radius_m};
  o.material.emission = {radiance, radiance, radiance};
  return o;
}

Camera triplet_camera(double focus_m, double f_number = 8.0, int width = kWidth, int height = kHeight) {
  CameraOptions options;
  options.focus_distance_m = focus_m;
  options.f_number = f_number;
  options.framing.focal_length_mm = kPinholeFocalMm;
  return Camera::from_lens(LensLibrary::load("sasian-triplet").prescription, options, width, height);
}

// The central w x h pixels of an image, moved right by shift_px.
Image centre(const Image& image, int w, int h, int shift_px = 0) {
  Image out(w, h, image.channels);
  const int x0 = (image.width - w) / 2 + shift_px, y0 = (image.height - h) / 2;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      for (int c = 0; c < image.channels; ++c) out.at(x, y, c) = image.at(x0 + x, y0 + y, c);
    }
  }
  return out;
}

double rms_difference(const Image& a, const Image& b) {
  double sum = 0.0;
  for (std::size_t i = 0; i < a.data.size(); ++i) sum += (a.data[i] - b.data[i]) * (a.data[i] - b.data[i]);
  return std::sqrt(sum / static_cast<double>(a.data.size()));
}

// Energy-weighted second moment <(x - cx)^2 + (y - cy)^2> of channel 1 about its centroid, px^2.
double second_moment(const Image& image) {
  double w = 0.0, sx = 0.0, sy = 0.0;
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      const double v = image.at(x, y, 1);
      w += v;
      sx += v * (x + 0.5);
      sy += v * (y + 0.5);
    }
  }
  const double cx = sx / w, cy = sy / w;
  double m = 0.0;
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      m += image.at(x, y, 1) * ((x + 0.5 - cx) * (x + 0.5 - cx) + (y + 0.5 - cy) * (y + 0.5 - cy));
    }
  }
  return m / w;
}

}  // namespace

TEST_CASE("a plane at the focus distance through the Sasian triplet at f/8 matches its pinhole picture", "[scene][lens]") {
  Scene scene;
  scene.objects.push_back(textured_wall(kFocusM));
  const Camera focused = triplet_camera(kFocusM);
  const PinholeRender pinhole = render_pinhole(scene, focused.frame());
  LensRenderOptions options;
  options.spp = 256;
  const LensRender sharp = render_through_lens(scene, focused, options);
  // Focused at 0.5 m the wall's blur disc is 5.6 px across (Camera::signed_coc_px), wider than a square.
  const Camera defocused = triplet_camera(0.5);
  REQUIRE_THAT(std::abs(defocused.signed_coc_px(1.0 / mm_from_m(kFocusM))), WithinAbs(5.6, 0.2));
  const LensRender blurred = render_through_lens(scene, defocused, options);
  INFO(sharp << "\n" << blurred);
  REQUIRE(sharp.spp_used == 256);
  CHECK(sharp.rays.vignetted > 0);  // the 15 % margin around the pupil is clipped by the stop
  // The central half of the frame in each direction (the triplet's own vignetting stays outside).
  const double psnr_sharp = psnr(centre(sharp.rgb, 48, 32), centre(pinhole.rgb, 48, 32));
  // What the threshold rejects: the pinhole picture against itself shifted by one pixel (17.3 dB).
  const double psnr_shifted = psnr(centre(pinhole.rgb, 48, 32, 1), centre(pinhole.rgb, 48, 32));
  const double psnr_blurred = psnr(centre(blurred.rgb, 48, 32), centre(pinhole.rgb, 48, 32));
  INFO("PSNR focused " << psnr_sharp << " dB, focused at 0.5 m " << psnr_blurred << " dB, pinhole shifted by 1 px "
                         << psnr_shifted << " dB");
  // Measured 30.2 dB, limited by sampling noise (about +3 dB per doubling of spp; 34.6 dB at 1024
  // spp): mostly the pass-or-vignetted lottery of the 15 % pupil margin.
  constexpr double kSharpPsnrDb = 27.0;
  // Measured 17.4 dB: the 4.4 px checker blurred over 5.6 px.
  constexpr double kBlurredPsnrDb = 21.0;
  CHECK(psnr_sharp > kSharpPsnrDb);
  CHECK(psnr_blurred < kBlurredPsnrDb);
  CHECK(psnr_shifted < kSharpPsnrDb);
}

TEST_CASE("a small highlight on the focus plane lands on its pinhole pixel through the lens", "[scene][lens]") {
  // Up and to the right of the axis, so a mirrored or flipped frame would put it elsewhere.
  Scene scene;
  scene.ambient = {0.0, 0.0, 0.0};
  const Camera camera = triplet_camera(kFocusM);
  const PixelPoint target{70.5, 20.5};
  const Tangents t = camera.frame().tangents_at(target);
  scene.objects.push_back(highlight({t.x * kFocusM, t.y * kFocusM, kFocusM}, 0.004, 100.0));
  LensRenderOptions options;
  options.spp = 16;
  const LensRender out = render_through_lens(scene, camera, options);
  const PixelPoint pinhole_peak = brightest(render_pinhole(scene, camera.frame()).rgb);
  const PixelPoint lens_peak = brightest(out.rgb);
  CHECK(pinhole_peak.x == target.x);
  CHECK(pinhole_peak.y == target.y);
  CHECK(lens_peak.x == pinhole_peak.x);
  CHECK(lens_peak.y == pinhole_peak.y);
}

TEST_CASE("the noise of the lens render falls as one over the square root of the samples", "[scene][lens]") {
  // The wall at 3 m with the lens focused at 1 m: a 2.2 px blur of the checker.
  Scene scene;
  scene.objects.push_back(textured_wall(kFocusM));
  const Camera camera = triplet_camera(1.0, 8.0, 48, 32);
  auto noise = [&](int spp) {
    LensRenderOptions a;
    a.spp = spp;
    a.seed = 11;
    LensRenderOptions b = a;
    b.seed = 12;
    return rms_difference(render_through_lens(scene, camera, a).rgb, render_through_lens(scene, camera, b).rgb);
  };
  const double at_16 = noise(16);
  const double at_64 = noise(64);
  INFO("RMS difference of two seeds: " << at_16 << " at 16 spp, " << at_64 << " at 64 spp, ratio " << at_16 / at_64);
  // sqrt(64 / 16) = 2; the RMS over 1536 pixels x 3 channels is itself uncertain by a few percent,
  // and 16 spp with 16 wavelength strata is stratified as finely as 64, so the ratio is 2 +- 20 %.
  CHECK(at_16 / at_64 > 1.6);
  CHECK(at_16 / at_64 < 2.5);
}

TEST_CASE("a uniform wall at the focus distance renders to its radiance on the axis", "[scene][lens]") {
  Scene scene;
  scene.ambient = {0.0, 0.0, 0.0};
  SceneObject wall;
  wall.shape = Plane{{0.0, 0.0, kFocusM}, {0.0, 0.0, -1.0}, std::nullopt};
  wall.material.emission = {0.5, 0.5, 0.5};
  scene.objects.push_back(wall);
  LensRenderOptions options;
  options.spp = 256;
  const LensRender out = render_through_lens(scene, triplet_camera(kFocusM), options);
  // The central 8 x 8 pixels: 16384 samples, each passing the stop with probability 1 / 1.15^2, so
  // the mean has a relative standard error of 0.57 / sqrt(16384) = 0.45 %.
  const Image middle = centre(out.rgb, 8, 8);
  INFO(out);
  // 2 %: four standard errors of the sampling plus the real pupil's departure from the paraxial one.
  constexpr double kNormalisation = 0.02;
  for (int c = 0; c < 3; ++c) {
    INFO("channel " << c);
    CHECK_THAT(middle.mean(c), WithinRel(0.5, kNormalisation));
  }
}

TEST_CASE("the thin-lens ground truth blurs a point into the disc A f |z - s| / (z s) over the pixel pitch", "[scene][lens]") {
  // f = 100 mm at f/1.4 focused at 5 m; a highlight on the axis at 1 m.
  constexpr double kFocalMm = 100.0, kFNumber = 1.4, kFocus = 5000.0, kDepth = 1000.0;
  Scene scene;
  scene.ambient = {0.0, 0.0, 0.0};
  // A 6 mm sphere (1.6 px across sharp): big enough that many samples of every disc pixel see it,
  // so the measured second moment is not shot noise.
  scene.objects.push_back(highlight({0.0, 0.0, m_from_mm(kDepth)}, 0.006, 100.0));
  CameraOptions options;
  options.focus_distance_m = m_from_mm(kFocus);
  options.f_number = kFNumber;
  const Camera camera = Camera::thin_lens(kFocalMm, options, kWidth, kHeight);
  LensRenderOptions render;
  render.spp = 256;
  const LensRender out = render_through_thin_lens(scene, camera, render);
  REQUIRE(out.rays.reached_scene == out.rays.traced);
  // The highlight's own size and the pixel footprint, measured on the pinhole picture, add their
  // second moments to the disc's (R^2 / 2 for a uniform disc of radius R), so subtract them.
  const double sharp = second_moment(render_pinhole(scene, camera.frame()).rgb);
  const double measured_px = 2.0 * std::sqrt(2.0 * (second_moment(out.rgb) - sharp));
  const double pitch_mm = 36.0 / kWidth;
  const double aperture_mm = kFocalMm / kFNumber;
  const double expected_px = aperture_mm * kFocalMm * std::abs(kDepth - kFocus) / (kDepth * kFocus) / pitch_mm;
  INFO("disc diameter " << measured_px << " px, expected " << expected_px << " px");
  REQUIRE_THAT(expected_px, WithinAbs(15.24, 0.01));  // 71.43 * 100 * 4000 / 5e6 / 0.375
  // Within a pixel, as the issue asks (measured 15.05 px): the moment of a few thousand sphere hits.
  constexpr double kDiscTolerancePx = 1.0;
  CHECK_THAT(measured_px, WithinAbs(expected_px, kDiscTolerancePx));
  // The same, from the camera's own paraxial blur (docs/bokeh.md convention).
  CHECK_THAT(std::abs(camera.signed_coc_px(1.0 / kDepth)), WithinAbs(expected_px, 1e-9 * expected_px));
}

TEST_CASE("the lens render is the same image whatever the thread count", "[scene][lens]") {
  Scene scene;
  scene.objects.push_back(textured_wall(kFocusM));
  scene.objects.push_back(highlight({0.1, 0.05, 2.0}, 0.01, 50.0));
  const Camera camera = triplet_camera(2.0, 4.0, 32, 24);
  LensRenderOptions one;
  one.spp = 8;
  one.threads = 1;
  one.seed = 7;
  LensRenderOptions two = one;
  two.threads = 2;
  const LensRender a = render_through_lens(scene, camera, one);
  const LensRender b = render_through_lens(scene, camera, two);
  CHECK(a.rgb.data == b.rgb.data);
  CHECK(a.rays.vignetted == b.rays.vignetted);
  two.seed = 8;
  CHECK(render_through_lens(scene, camera, two).rgb.data != a.rgb.data);  // the seed matters
}

TEST_CASE("a noise target doubles the samples until the estimated error is below it", "[scene][lens]") {
  Scene scene;
  scene.objects.push_back(textured_wall(kFocusM));
  const Camera camera = triplet_camera(1.0, 8.0, 24, 16);
  LensRenderOptions options;
  options.spp = 4;
  options.max_spp = 256;
  const LensRender first = render_through_lens(scene, camera, options);
  options.noise_target = 0.5 * first.estimated_relative_error;
  std::vector<double> progress;
  options.progress = [&progress](double f) { progress.push_back(f); };
  const LensRender out = render_through_lens(scene, camera, options);
  INFO(first << "\n" << out);
  // Halving the error takes four times the samples: 16, or 32 when the estimate is unlucky.
  CHECK(out.spp_used >= 16);
  CHECK(out.spp_used <= 32);
  CHECK(out.estimated_relative_error <= *options.noise_target);
  REQUIRE_FALSE(progress.empty());
  CHECK(progress.back() == 1.0);
}

TEST_CASE("lens render options name the field they break", "[scene][lens]") {
  LensRenderOptions o;
  o.spp = 0;
  CHECK_THROWS_WITH(o.validate(), Contains("LensRenderOptions::spp = 0"));
  o = {};
  o.max_spp = 8;
  CHECK_THROWS_WITH(o.validate(), Contains("LensRenderOptions::max_spp = 8"));
  o = {};
  o.noise_target = -1.0;
  CHECK_THROWS_WITH(o.validate(), Contains("noise_target"));
  CameraOptions thin;
  thin.focus_distance_m = 2.0;
  thin.f_number = 2.0;
  const Camera camera = Camera::thin_lens(50.0, thin, 16, 16);
  CHECK_THROWS_AS(render_through_lens(Scene{}, camera, {}), OptionsError);
  CHECK_THROWS_AS(render_through_thin_lens(Scene{}, triplet_camera(kFocusM, 8.0, 16, 16), {}), OptionsError);
}
