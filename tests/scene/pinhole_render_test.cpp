// The pinhole renderer against closed forms: planar depth of planes and spheres from ray-plane and
// ray-sphere intersection solved by hand, the colour of the self-lit shading model, anti-aliased
// coverage of a straight edge against its exact area, and the camera-pose convention of
// camera_pose.h (x right, y up, depth along the look direction).
#include "lensmith/scene/pinhole_render.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <limits>

#include "lensmith/core/errors.h"
#include "lensmith/scene/scene_intersection.h"

#include "brightest_pixel.h"

using Catch::Matchers::Contains;
using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;
using namespace lensmith;
using lensmith::testing::brightest;

namespace {

// The depth map stores float: rounding a double to float moves it by at most 2^-24 relative; one
// float ulp (2^-23) leaves room for the double arithmetic before it.
constexpr double kFloatDepth = 1.2e-7;
// A float colour channel after double accumulation: one float ulp of values near 1.
constexpr double kFloatColour = 1.2e-7;

Rgb grey(double v) { return {v, v, v}; }

SceneObject object(SceneShape shape, Rgb albedo, Rgb emission = {}) {
  SceneObject o;
  o.shape = std::move(shape);
  o.material.albedo = ConstantTexture{albedo};
  o.material.emission = emission;
  return o;
}

// A fronto-parallel rectangle at depth z_m facing the default camera, covering the camera-space
// box [x0, x1] x [y0, y1] (metres at that depth).
Rectangle box_at(double z_m, double x0, double x1, double y0, double y1) {
  Rectangle r;
  r.centre_m = {0.5 * (x0 + x1), 0.5 * (y0 + y1), z_m};
  r.half_u_m = {0.5 * (x1 - x0), 0.0, 0.0};
  r.half_v_m = {0.0, 0.5 * (y1 - y0), 0.0};
  return r;
}

}  // namespace

TEST_CASE("a fronto-parallel plane at 3 m has depth exactly 3 m at every pixel", "[scene][pinhole]") {
  Scene scene;
  scene.objects.push_back(object(Plane{{0.0, 0.0, 3.0}, {0.0, 0.0, -1.0}, std::nullopt}, grey(0.5)));
  const PinholeFrame frame(40, 24, 30.0);  // a wide field (hfov 67 deg) so corner rays are far off axis
  const PinholeRender out = render_pinhole(scene, frame, {2, 0});
  for (int y = 0; y < frame.height_px(); ++y) {
    for (int x = 0; x < frame.width_px(); ++x) {
      INFO("pixel (" << x << ", " << y << ")");
      REQUIRE(out.depth.at(x, y) == 3.0f);
    }
  }
}

TEST_CASE("a tilted plane's depth equals the ray-plane intersection in camera coordinates at every pixel centre", "[scene][pinhole]") {
  // A camera away from the origin, turned and rolled, so that every part of the pose matters.
  Scene scene;
  scene.camera = CameraPose::looking_at({1.0, 0.5, -2.0}, {0.2, 0.1, 3.0}, {0.1, 1.0, 0.0});
  const Eigen::Vector3d p0{0.3, -0.2, 4.0};
  const Eigen::Vector3d n = Eigen::Vector3d(0.2, 0.9, -0.4).normalized();  // about 66 deg from the axis
  scene.objects.push_back(object(Plane{p0, n, std::nullopt}, grey(0.5)));
  const PinholeFrame frame(48, 32, 50.0);
  const PinholeRender out = render_pinhole(scene, frame, {1, 0});

  // The plane in camera coordinates: n_c . (p - p0_c) = 0; the pixel ray is z (tx, ty, 1).
  const CameraBasis b = scene.camera.basis();
  const Eigen::Vector3d n_c{n.dot(b.right), n.dot(b.up), n.dot(b.forward)};
  const Eigen::Vector3d p0_c = scene.camera.to_camera(p0);
  int on_plane = 0;
  for (int y = 0; y < frame.height_px(); ++y) {
    for (int x = 0; x < frame.width_px(); ++x) {
      const Tangents t = frame.tangents_at({x + 0.5, y + 0.5});
      const double z = n_c.dot(p0_c) / n_c.dot(Eigen::Vector3d(t.x, t.y, 1.0));
      INFO("pixel (" << x << ", " << y << "), closed-form depth " << z << " m");
      if (z > 0.0) {
        REQUIRE_THAT(out.depth.at(x, y), WithinRel(z, kFloatDepth));
        ++on_plane;
      } else {
        REQUIRE(std::isinf(out.depth.at(x, y)));  // the ray runs above the horizon
      }
    }
  }
  CHECK(on_plane > frame.width_px() * frame.height_px() / 2);
}

TEST_CASE("the pixel on a sphere's centre line shows depth centre z minus radius", "[scene][pinhole]") {
  Scene scene;
  scene.objects.push_back(object(Sphere{{0.0, 0.0, 5.0}, 0.5}, grey(0.5)));
  const PinholeFrame frame(33, 21, 40.0);  // odd sizes: pixel (16, 10) is centred on the axis
  const PinholeRender out = render_pinhole(scene, frame, {1, 0});
  CHECK(out.depth.at(16, 10) == 4.5f);
}

TEST_CASE("a sphere centred on an off-axis pixel's ray shows depth (distance - radius) times that ray's cosine", "[scene][pinhole]") {
  const PinholeFrame frame(40, 30, 35.0);
  const int px = 31;
  const int py = 6;
  const Tangents t = frame.tangents_at({px + 0.5, py + 0.5});
  const Eigen::Vector3d d = Eigen::Vector3d(t.x, t.y, 1.0).normalized();
  const double distance_m = 7.0;
  const double radius_m = 0.8;
  Scene scene;
  scene.objects.push_back(object(Sphere{distance_m * d, radius_m}, grey(0.5)));
  const PinholeRender out = render_pinhole(scene, frame, {1, 0});
  CHECK_THAT(out.depth.at(px, py), WithinRel((distance_m - radius_m) * d.z(), kFloatDepth));
}

TEST_CASE("a constant-albedo rectangle renders as albedo times ambient exactly inside it", "[scene][pinhole]") {
  Scene scene;
  scene.ambient = {0.9, 0.8, 0.5};
  scene.background = {0.05, 0.1, 0.2};
  const Rgb albedo{0.3, 0.5, 0.7};
  // Covers pixels 10..29 x 6..17 of a 40 x 24 frame with f = 40 px at z = 2 m: x = (px - 20) / 20 m.
  scene.objects.push_back(object(box_at(2.0, -0.5, 0.5, -0.3, 0.3), albedo));
  const PinholeFrame frame(40, 24, 40.0);
  const PinholeRender out = render_pinhole(scene, frame);
  for (int y = 7; y < 17; ++y) {
    for (int x = 11; x < 29; ++x) {
      INFO("pixel (" << x << ", " << y << ")");
      for (int c = 0; c < 3; ++c) REQUIRE(out.rgb.at(x, y, c) == static_cast<float>(albedo[c] * scene.ambient[c]));
      REQUIRE(out.depth.at(x, y) == 2.0f);
    }
  }
  // Outside: the background, at infinite depth.
  for (int c = 0; c < 3; ++c) CHECK(out.rgb.at(2, 2, c) == static_cast<float>(scene.background[c]));
  CHECK(std::isinf(out.depth.at(2, 2)));
}

TEST_CASE("an edge between sample columns gives its pixel exactly the covered fraction of the colour", "[scene][pinhole]") {
  const int n = GENERATE(2, 4, 5);
  const int k = GENERATE_COPY(range(1, n));  // the edge at x = 20 + k / n
  Scene scene;
  scene.background = {0.1, 0.2, 0.05};
  const Rgb albedo{0.9, 0.4, 0.6};
  // f = 40 px at z = 2 m: image x = 20 + 20 X, so X = (x - 20) / 20.
  const double edge_x = 20.0 + static_cast<double>(k) / n;
  scene.objects.push_back(object(box_at(2.0, -5.0, (edge_x - 20.0) / 20.0, -5.0, 5.0), albedo));
  const PinholeFrame frame(40, 24, 40.0);
  const PinholeRender out = render_pinhole(scene, frame, {n, 0});
  const double exact_area = static_cast<double>(k) / n;
  // The stratified grid counts whole sample columns; an edge between two columns covers k of n of
  // them exactly, so the fraction must agree with the area to far better than one sample (1/n^2).
  const double one_sample = 1.0 / (n * n);
  for (int y = 0; y < frame.height_px(); ++y) {
    for (int c = 0; c < 3; ++c) {
      const double fraction = (out.rgb.at(20, y, c) - scene.background[c]) / (albedo[c] - scene.background[c]);
      INFO("n " << n << ", edge at x = " << edge_x << ", row " << y << ", channel " << c);
      REQUIRE_THAT(fraction, WithinAbs(exact_area, one_sample));
      REQUIRE_THAT(fraction, WithinAbs(exact_area, 1e-6));
      REQUIRE(out.rgb.at(19, y, c) == static_cast<float>(albedo[c]));
      REQUIRE(out.rgb.at(21, y, c) == static_cast<float>(scene.background[c]));
    }
    // Depth follows the centre ray only: covered when the edge lies right of the pixel centre.
    if (exact_area > 0.5) REQUIRE(out.depth.at(20, y) == 2.0f);
    if (exact_area < 0.5) REQUIRE(std::isinf(out.depth.at(20, y)));
  }
}

TEST_CASE("a horizontal edge at any sub-pixel position is within half a sample row of its covered area", "[scene][pinhole]") {
  const int n = 4;
  const double offset = GENERATE(0.07, 0.3, 0.5, 0.61, 0.93);
  Scene scene;
  const Rgb albedo{1.0, 1.0, 1.0};
  // A white rectangle above the image line y = 12 - offset (rows run down): it covers rows 0..10
  // and the fraction 1 - offset of row 11.
  const double edge_y = 12.0 - offset;
  // f = 40 px at z = 2 m: image y = 12 - 20 Y, so the edge is at Y = (12 - edge_y) / 20.
  scene.objects.push_back(object(box_at(2.0, -5.0, 5.0, (12.0 - edge_y) / 20.0, 5.0), albedo));
  const PinholeFrame frame(40, 24, 40.0);
  const PinholeRender out = render_pinhole(scene, frame, {n, 0});
  // Sample rows sit at cell centres; a straight axis-parallel edge anywhere is counted to the
  // nearest row of n samples, at most half a row (1 / (2n)) from the true area.
  const double half_row = 1.0 / (2.0 * n);
  for (int x = 0; x < frame.width_px(); ++x) {
    INFO("column " << x << ", edge at y = " << edge_y);
    REQUIRE_THAT(out.rgb.at(x, 11, 0), WithinAbs(1.0 - offset, half_row));
    REQUIRE(out.rgb.at(x, 10, 0) == 1.0f);
    REQUIRE(out.rgb.at(x, 12, 0) == 0.0f);
  }
}

TEST_CASE("an object at camera-space +x appears right of centre and one at +y above it", "[scene][pinhole]") {
  // Poses: the default one, and a camera at x = 5 m looking back at the origin with a rolled up vector.
  const CameraPose pose = GENERATE(CameraPose{}, CameraPose::looking_at({5.0, 0.0, 0.0}, {0.0, 0.0, 0.0}, {0.0, 1.0, 0.3}));
  const PinholeFrame frame(64, 48, 60.0);
  for (const Eigen::Vector3d& camera_point : {Eigen::Vector3d(0.8, 0.0, 5.0), Eigen::Vector3d(0.0, 0.8, 5.0)}) {
    Scene scene;
    scene.camera = pose;
    scene.objects.push_back(object(Sphere{pose.to_world(camera_point), 0.1}, grey(0.0), grey(100.0)));
    const PinholeRender out = render_pinhole(scene, frame, {2, 0});
    const PixelPoint p = brightest(out.rgb);
    INFO(pose << ", object at camera " << format_vector(camera_point) << ", brightest pixel (" << p.x << ", " << p.y << ")");
    // The centre of the image is (32, 24); the point projects to 32 + 60 * 0.8 / 5 = 41.6 (or 24 - 9.6 = 14.4).
    if (camera_point.x() > 0.0) {
      CHECK_THAT(p.x, WithinAbs(41.6, 1.0));
      CHECK_THAT(p.y, WithinAbs(24.0, 1.0));
    } else {
      CHECK_THAT(p.x, WithinAbs(32.0, 1.0));
      CHECK_THAT(p.y, WithinAbs(14.4, 1.0));
    }
    // The visible cap of the sphere lies between its front point (depth 4.9) and its centre plane.
    const float depth = out.depth.at(static_cast<int>(p.x), static_cast<int>(p.y));
    CHECK(depth >= 4.9f);
    CHECK(depth < 5.0f);
  }
}

TEST_CASE("the default camera sees world +x on the right and a pose looking along -x sees world +z on the right", "[scene][pinhole]") {
  const PinholeFrame frame(64, 48, 60.0);
  Scene scene;
  scene.objects.push_back(object(Sphere{{1.0, 0.0, 5.0}, 0.1}, grey(0.0), grey(100.0)));
  CHECK(brightest(render_pinhole(scene, frame, {2, 0}).rgb).x > 32.0);
  // Standing at x = 5 looking at the origin, with +y up: right = up x forward = (0, 1, 0) x (-1, 0, 0) = +z.
  scene.camera = CameraPose::looking_at({5.0, 0.0, 0.0}, {0.0, 0.0, 0.0});
  scene.objects[0].shape = Sphere{{0.0, 0.0, 1.0}, 0.1};
  CHECK(brightest(render_pinhole(scene, frame, {2, 0}).rgb).x > 32.0);
  scene.objects[0].shape = Sphere{{0.0, 1.0, 0.0}, 0.1};
  CHECK(brightest(render_pinhole(scene, frame, {2, 0}).rgb).y < 24.0);
}

TEST_CASE("a pinhole render does not depend on the number of threads", "[scene][pinhole]") {
  Scene scene;
  scene.objects.push_back(object(Sphere{{0.2, 0.1, 3.0}, 0.5}, {0.2, 0.4, 0.6}, {1.0, 0.0, 0.0}));
  SceneObject wall;
  wall.shape = Plane{{0.0, 0.0, 6.0}, {0.1, 0.0, -1.0}, std::nullopt};
  wall.material.albedo = NoiseTexture{};
  scene.objects.push_back(wall);
  const PinholeFrame frame(37, 23, 30.0);
  const PinholeRender one = render_pinhole(scene, frame, {3, 1});
  const PinholeRender two = render_pinhole(scene, frame, {3, 2});
  CHECK(one.rgb.data == two.rgb.data);
  CHECK(one.depth.z_m == two.depth.z_m);
}

TEST_CASE("pinhole render options name the field they violate", "[scene][pinhole]") {
  Scene scene;
  const PinholeFrame frame(4, 4, 4.0);
  CHECK_THROWS_WITH(render_pinhole(scene, frame, {0, 0}), Contains("samples_per_axis = 0"));
  CHECK_THROWS_WITH(render_pinhole(scene, frame, {65, 0}), Contains("samples_per_axis = 65"));
  CHECK_THROWS_WITH(render_pinhole(scene, frame, {4, -1}), Contains("threads = -1"));
  CHECK_THROWS_AS(render_pinhole(scene, frame, {0, 0}), OptionsError);
}

TEST_CASE("an invalid scene built in code is refused with the object and field named", "[scene][pinhole]") {
  Scene scene;
  scene.objects.push_back(object(Sphere{{0.0, 0.0, 3.0}, 1.0}, grey(0.5)));
  scene.objects.push_back(object(Sphere{{0.0, 0.0, 3.0}, -1.0}, grey(0.5)));
  scene.objects.back().name = "lamp";
  CHECK_THROWS_AS(render_pinhole(scene, PinholeFrame(4, 4, 4.0)), SceneError);
  CHECK_THROWS_WITH(render_pinhole(scene, PinholeFrame(4, 4, 4.0)), Contains("objects[1] (sphere \"lamp\"): radius_m = -1"));
}

// ---- depth peeling (render_pinhole_layers) ---------------------------------------------------------

TEST_CASE("depth peeling keeps the wall behind a rectangle, at the wall's depth and in its colour", "[scene][pinhole][layers]") {
  Scene scene;
  const Rgb wall{0.2, 0.5, 0.3}, card{0.9, 0.1, 0.1};
  scene.objects.push_back(object(box_at(4.0, -9.0, 9.0, -9.0, 9.0), wall));
  scene.objects.push_back(object(box_at(1.0, -0.2, 0.2, -0.2, 0.2), card));  // f = 40 px at 1 m: pixels 12..28
  const PinholeFrame frame(40, 24, 40.0);
  const DeepImage one = render_pinhole_layers(scene, frame, 1, {4, 0});
  const DeepImage two = render_pinhole_layers(scene, frame, 2, {4, 0});
  // The card's middle: one layer sees the card only, two see the wall behind it, whole.
  REQUIRE(one.pixel(20, 12).size() == 1);
  REQUIRE(two.pixel(20, 12).size() == 2);
  const DeepSample& behind = two.pixel(20, 12)[1];
  CHECK_THAT(behind.z_m, WithinRel(4.0, kFloatDepth));
  CHECK(behind.alpha == 1.0f);
  for (int c = 0; c < 3; ++c) CHECK_THAT(behind.rgb[static_cast<std::size_t>(c)], WithinAbs(wall[c], kFloatColour));
  CHECK_THAT(two.pixel(20, 12)[0].z_m, WithinRel(1.0, kFloatDepth));
  // Beyond the card: the wall alone; no sky behind it (it covers the frame).
  CHECK(two.pixel(2, 2).size() == 1);
}

TEST_CASE("depth-peeled layers composite front to back into the pinhole picture where the surfaces are plain", "[scene][pinhole][layers]") {
  // A card whose edges cut pixels at sub-pixel positions over a plain wall, sky in a corner: every
  // pixel, edges included, must flatten to render_pinhole's colour, for any number of layers.
  Scene scene;
  scene.background = {0.05, 0.1, 0.4};
  scene.objects.push_back(object(box_at(4.0, -9.0, 0.8, -9.0, 0.5), Rgb{0.2, 0.5, 0.3}));
  scene.objects.push_back(object(box_at(1.0, -0.213, 0.187, -0.171, 0.229), Rgb{0.9, 0.1, 0.1}));
  const PinholeFrame frame(40, 24, 40.0);
  const PinholeRender flat = render_pinhole(scene, frame, {4, 0});
  for (int layers : {1, 2, 3}) {
    const Image composite = render_pinhole_layers(scene, frame, layers, {4, 0}).flatten();
    for (int y = 0; y < frame.height_px(); ++y) {
      for (int x = 0; x < frame.width_px(); ++x) {
        INFO(layers << " layers, pixel (" << x << ", " << y << ")");
        for (int c = 0; c < 3; ++c) REQUIRE_THAT(composite.at(x, y, c), WithinAbs(flat.rgb.at(x, y, c), 1e-6));
        REQUIRE_THAT(composite.at(x, y, 3), WithinAbs(1.0, 1e-6));
      }
    }
  }
}

TEST_CASE("depth peeling refuses a layer count outside 1..16", "[scene][pinhole][layers]") {
  Scene scene;
  scene.objects.push_back(object(box_at(4.0, -9.0, 9.0, -9.0, 9.0), grey(0.5)));
  CHECK_THROWS_WITH(render_pinhole_layers(scene, PinholeFrame(4, 4, 4.0), 0), Contains("layers = 0: must be in 1..16"));
  CHECK_THROWS_WITH(render_pinhole_layers(scene, PinholeFrame(4, 4, 4.0), 17), Contains("layers = 17"));
}
