// The scenes shipped in examples/scenes/ load, render at 64 x 36 through the framing they are
// designed for (36 mm sensor, 50 mm pinhole: hfov 39.6 deg), and show the depths they promise.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <string>

#include "lensmith/core/units.h"
#include "lensmith/scene/pinhole_render.h"
#include "lensmith/scene/scene_json.h"

using Catch::Matchers::WithinRel;
using namespace lensmith;

namespace {

const std::string kScenes = std::string(LENSMITH_SOURCE_DIR) + "/examples/scenes/";

// The framing the scenes are designed for: 36 mm sensor behind a 50 mm pinhole.
PinholeFrame example_frame(int width, int height) {
  PinholeFrameOptions framing;
  framing.sensor_width_mm = 36.0;
  framing.focal_length_mm = 50.0;
  return PinholeFrame::from_options(width, height, framing, 50.0);
}

PinholeRender render_example(const std::string& file) { return render_pinhole(load_scene(kScenes + file), example_frame(64, 36)); }

// Every colour finite and >= 0, every depth > 0 (inf allowed, NaN not).
void check_valid(const PinholeRender& out) {
  for (float v : out.rgb.data) REQUIRE((std::isfinite(v) && v >= 0.0f));
  for (float z : out.depth.z_m) REQUIRE(z > 0.0f);
}

// The depths (rounded to 1 mm) that cover at least `min_pixels` pixels.
std::set<double> main_depths(const DepthMap& depth, int min_pixels) {
  std::map<double, int> count;
  for (float z : depth.z_m) ++count[std::isinf(z) ? static_cast<double>(z) : m_from_mm(std::round(mm_from_m(z)))];
  std::set<double> out;
  for (const auto& [z, n] : count) {
    if (n >= min_pixels) out.insert(z);
  }
  return out;
}

}  // namespace

TEST_CASE("the highlight field renders with its far wall at 30 m behind every highlight", "[scene][examples]") {
  const PinholeRender out = render_example("highlight-field.json");
  check_valid(out);
  CHECK(main_depths(out.depth, 100) == std::set<double>{30.0});
  CHECK(*std::min_element(out.depth.z_m.begin(), out.depth.z_m.end()) >= 1.0f - 0.002f);
}

TEST_CASE("the occluder scene shows a disc at 1 m and a bar at 1.2 m over the wall at 3 m", "[scene][examples]") {
  const PinholeRender out = render_example("occluder.json");
  check_valid(out);
  const std::set<double> depths = main_depths(out.depth, 10);
  CHECK(depths.count(1.0) == 1);
  CHECK(depths.count(1.2) == 1);
  CHECK(depths.count(3.0) == 1);
  CHECK(std::none_of(out.depth.z_m.begin(), out.depth.z_m.end(), [](float z) { return std::isinf(z); }));
}

TEST_CASE("the tilted plane fills the frame with depth varying continuously from about 1.8 to 9 m", "[scene][examples]") {
  const PinholeRender out = render_example("tilted-plane.json");
  check_valid(out);
  const auto [lo, hi] = std::minmax_element(out.depth.z_m.begin(), out.depth.z_m.end());
  CHECK(*lo > 1.7f);
  CHECK(*lo < 2.0f);
  CHECK(*hi > 8.0f);
  CHECK(std::isfinite(*hi));
  // Continuous: neighbouring pixels of the floor differ by a few per cent at most (the top rows,
  // near 9 m, change fastest: about 5 % per row).
  for (int y = 0; y + 1 < out.depth.height; ++y) {
    for (int x = 0; x + 1 < out.depth.width; ++x) {
      const double z = out.depth.at(x, y);
      INFO("pixel (" << x << ", " << y << ")");
      // Lamps on the floor are nearer than the floor around them; skip their pixels.
      if (out.rgb.at(x, y, 1) > 1.0f || out.rgb.at(x + 1, y, 1) > 1.0f || out.rgb.at(x, y + 1, 1) > 1.0f) continue;
      REQUIRE_THAT(out.depth.at(x + 1, y), WithinRel(z, 0.1));
      REQUIRE_THAT(out.depth.at(x, y + 1), WithinRel(z, 0.1));
    }
  }
}

TEST_CASE("the depth staircase shows its five steps side by side from left to right", "[scene][examples]") {
  const PinholeRender out = render_example("depth-staircase.json");
  check_valid(out);
  const double steps[] = {1.0, 1.5, 2.2, 3.3, 5.0};
  // Strip k of the 64 columns spans x in [12.8 k, 12.8 (k + 1)); sample the middle row's strip centres.
  for (int k = 0; k < 5; ++k) {
    const int x = static_cast<int>(12.8 * k + 6.4);
    INFO("step " << k + 1 << ", column " << x);
    CHECK(out.depth.at(x, 25) == static_cast<float>(steps[k]));
  }
  CHECK(main_depths(out.depth, 50) == std::set<double>{1.0, 1.5, 2.2, 3.3, 5.0});
}

TEST_CASE("the fence shows slats at 1 m over the wall at 6 m, with lights at 3 m between and behind them", "[scene][examples]") {
  const PinholeRender out = render_example("fence.json");
  check_valid(out);
  const std::set<double> depths = main_depths(out.depth, 20);
  CHECK(depths.count(1.0) == 1);
  CHECK(depths.count(6.0) == 1);
  // Behind a slat the layered render keeps what the picture hides: somewhere a light at 3 m.
  const DeepImage layers = render_pinhole_layers(load_scene(kScenes + "fence.json"), example_frame(640, 360), 3);
  int visible_lights = 0, hidden_lights = 0;
  for (int y = 0; y < 360; ++y) {
    for (int x = 0; x < 640; ++x) {
      const auto p = layers.pixel(x, y);
      if (p.empty()) continue;
      // A light's samples lie within its 6 mm radius before 3 m (a pixel is 3.4 mm wide there).
      if (p.front().z_m > 2.99f && p.front().z_m <= 3.0f) ++visible_lights;
      if (p.size() >= 2 && p.front().z_m == 1.0f && p[1].z_m > 2.99f && p[1].z_m <= 3.0f) ++hidden_lights;
    }
  }
  CHECK(visible_lights > 50);
  CHECK(hidden_lights > 0);  // 8 pixels at 640 x 360: lights partly behind slats
}

TEST_CASE("the branches cross at 0.8, 0.95 and 1.1 m in front of lights at 4 m and the wall at 8 m", "[scene][examples]") {
  // At 640 x 360 the branches are 1.5 to 2 px wide: thin features that a method must not lose.
  const PinholeRender out = render_pinhole(load_scene(kScenes + "branches.json"), example_frame(640, 360));
  check_valid(out);
  const std::set<double> depths = main_depths(out.depth, 50);
  CHECK(depths.count(0.8) == 1);
  CHECK(depths.count(0.95) == 1);
  CHECK(depths.count(1.1) == 1);
  CHECK(depths.count(8.0) == 1);
  // The lights at 4 m: the far wall's depth everywhere else (a light's samples lie within 8 mm of 4 m).
  const auto lights = std::count_if(out.depth.z_m.begin(), out.depth.z_m.end(), [](float z) { return z > 3.99f && z <= 4.0f; });
  CHECK(lights > 10);
}

TEST_CASE("the frame-edge scene cuts a disc at 0.8 m by the right edge and a bar at 1.2 m by the top", "[scene][examples]") {
  const PinholeRender out = render_example("frame-edge.json");
  check_valid(out);
  const std::set<double> depths = main_depths(out.depth, 10);
  CHECK(depths.count(0.8) == 1);
  CHECK(depths.count(1.2) == 1);
  CHECK(depths.count(2.5) == 1);
  const int w = out.depth.width, h = out.depth.height;
  CHECK(out.depth.at(w - 1, h / 2) == Approx(0.8f));  // the disc reaches beyond the right edge
  CHECK(out.depth.at(w / 4, 0) == Approx(1.2f));      // the bar beyond the top
}

TEST_CASE("the crossing planes meet at 2.1 m in the middle of the frame, each nearer on its own side", "[scene][examples]") {
  // The middle pixel's centre lies half a pixel (tangent 0.0056) from the crossing: the 45-degree planes are 0.56 % nearer.
  constexpr double kMiddleDepth = 0.02;
  const PinholeRender out = render_example("crossing-planes.json");
  check_valid(out);
  const int w = out.depth.width, h = out.depth.height;
  // Along the middle row the nearer plane's depth falls towards the middle from both sides: 2.1 m
  // at the crossing (tangent 0), and less than that on either side.
  const float middle = out.depth.at(w / 2, h / 2);
  CHECK(middle == Approx(2.1f).epsilon(kMiddleDepth));
  CHECK(out.depth.at(w / 8, h / 2) < middle);
  CHECK(out.depth.at(7 * w / 8, h / 2) < middle);
  // Left of the crossing the checker plane is in front, right of it the noise plane (blue).
  CHECK(out.rgb.at(7 * w / 8, h / 2, 2) > out.rgb.at(7 * w / 8, h / 2, 0));
}
