// Ray-shape intersection against hand-solved cases (a ray through a sphere from outside, from
// inside, tangent; rays at a rectangle's and disc's rims), the nearest-hit rule of intersect(), and
// the surface coordinates (s, t) textures are laid on.
#include "lensmith/scene/shape.h"

#include <catch2/catch.hpp>

#include <cmath>

#include "lensmith/core/units.h"
#include "lensmith/scene/scene_intersection.h"

using Catch::Matchers::Contains;
using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;
using namespace lensmith;

namespace {

// Distances and coordinates computed in double from exact inputs: a few ulps of 1.
constexpr double kDoubleRounding = 1e-14;

SceneRay ray(Eigen::Vector3d origin, Eigen::Vector3d direction) { return {origin, direction.normalized()}; }

}  // namespace

TEST_CASE("a ray meets a sphere ahead of it at centre distance minus radius", "[scene][shape]") {
  const Sphere s{{0.0, 0.0, 5.0}, 2.0};
  CHECK_THAT(hit_distance_m(s, ray({0, 0, 0}, {0, 0, 1})), WithinRel(3.0, kDoubleRounding));
  // Behind the ray: no hit.
  CHECK(std::isinf(hit_distance_m(s, ray({0, 0, 10}, {0, 0, 1}))));
}

TEST_CASE("a ray from inside a sphere meets its far side", "[scene][shape]") {
  const Sphere s{{0.0, 0.0, 5.0}, 2.0};
  CHECK_THAT(hit_distance_m(s, ray({0, 0, 5}, {0, 1, 0})), WithinRel(2.0, kDoubleRounding));
  CHECK_THAT(hit_distance_m(s, ray({0, 0, 4}, {0, 0, 1})), WithinRel(3.0, kDoubleRounding));
}

TEST_CASE("a ray passing a sphere by more than its radius misses it", "[scene][shape]") {
  const Sphere s{{0.0, 0.0, 5.0}, 2.0};
  CHECK(std::isinf(hit_distance_m(s, ray({2.0001, 0, 0}, {0, 0, 1}))));
  // Just inside the rim: a chord of half-length sqrt(r^2 - h^2).
  const double h = 1.999;
  CHECK_THAT(hit_distance_m(s, ray({h, 0, 0}, {0, 0, 1})), WithinRel(5.0 - std::sqrt(4.0 - h * h), 1e-12));
}

TEST_CASE("a tiny sphere far away is hit at the right distance without cancellation", "[scene][shape]") {
  // r / d = 1e-7: the textbook discriminant b^2 - c loses all digits here, r^2 - |oc - b d|^2 does not.
  const Sphere s{{0.0, 0.0, 1.0e4}, 1.0e-3};
  CHECK_THAT(hit_distance_m(s, ray({0, 0, 0}, {0, 0, 1})), WithinRel(1.0e4 - 1.0e-3, kDoubleRounding));
  CHECK_THAT(hit_distance_m(s, ray({0.5e-3, 0, 0}, {0, 0, 1})),
             WithinRel(1.0e4 - std::sqrt(1.0e-6 - 0.25e-6), kDoubleRounding));
}

TEST_CASE("a rectangle is hit inside its half-edges and missed outside from either side", "[scene][shape]") {
  const Rectangle r{{0.0, 0.0, 4.0}, {1.0, 0.0, 0.0}, {0.0, 0.5, 0.0}};
  CHECK_THAT(hit_distance_m(r, ray({0.99, 0.49, 0}, {0, 0, 1})), WithinRel(4.0, kDoubleRounding));
  CHECK(std::isinf(hit_distance_m(r, ray({1.01, 0, 0}, {0, 0, 1}))));
  CHECK(std::isinf(hit_distance_m(r, ray({0, 0.51, 0}, {0, 0, 1}))));
  CHECK_THAT(hit_distance_m(r, ray({0.2, 0.1, 9}, {0, 0, -1})), WithinRel(5.0, kDoubleRounding));  // the back side
  CHECK(std::isinf(hit_distance_m(r, ray({0, 0, 0}, {1, 0, 0}))));                               // parallel
}

TEST_CASE("a disc is hit within its radius and missed beyond it", "[scene][shape]") {
  const Disc d{{1.0, 0.0, 3.0}, {0.0, 0.0, -2.0}, 0.5, std::nullopt};
  CHECK_THAT(hit_distance_m(d, ray({1.3, 0.39, 0}, {0, 0, 1})), WithinRel(3.0, kDoubleRounding));  // 0.3^2 + 0.39^2 < 0.25
  CHECK(std::isinf(hit_distance_m(d, ray({1.3, 0.41, 0}, {0, 0, 1}))));                           // 0.09 + 0.168 > 0.25
}

TEST_CASE("an oblique ray meets a plane at the closed-form distance", "[scene][shape]") {
  const Plane p{{0.0, -1.0, 0.0}, {0.0, 1.0, 0.0}, std::nullopt};
  // From (0, 1, 0) down at 45 degrees: 2 m of drop, 2 sqrt(2) m of path.
  CHECK_THAT(hit_distance_m(p, ray({0, 1, 0}, {0, -1, 1})), WithinRel(2.0 * std::sqrt(2.0), kDoubleRounding));
  CHECK(std::isinf(hit_distance_m(p, ray({0, 1, 0}, {0, 1, 1}))));  // going away
}

TEST_CASE("intersect returns the nearest object with a normal facing the ray and its radiance", "[scene][shape]") {
  Scene scene;
  scene.ambient = {0.5, 0.5, 0.5};
  SceneObject far_wall;
  far_wall.shape = Plane{{0.0, 0.0, 10.0}, {0.0, 0.0, 1.0}, std::nullopt};  // normal pointing away from the camera
  far_wall.material.albedo = ConstantTexture{{0.2, 0.4, 0.6}};
  SceneObject ball;
  ball.shape = Sphere{{0.0, 0.0, 5.0}, 1.0};
  ball.material.emission = {10.0, 0.0, 0.0};
  scene.objects = {far_wall, ball};

  const auto on_ball = intersect(scene, ray({0, 0, 0}, {0, 0, 1}));
  REQUIRE(on_ball);
  CHECK(on_ball->object_index == 1);
  CHECK_THAT(on_ball->distance_m, WithinRel(4.0, kDoubleRounding));
  CHECK_THAT(on_ball->normal.z(), WithinAbs(-1.0, kDoubleRounding));
  CHECK(on_ball->radiance.r == 10.0);
  CHECK(on_ball->radiance.g == 0.0);

  const auto on_wall = intersect(scene, ray({3, 0, 0}, {0, 0, 1}));
  REQUIRE(on_wall);
  CHECK(on_wall->object_index == 0);
  CHECK(on_wall->normal.z() == -1.0);  // turned toward the ray's origin
  CHECK(on_wall->radiance.b == 0.6 * 0.5);
  CHECK_FALSE(intersect(scene, ray({0, 0, 0}, {0, 0, -1})));
}

TEST_CASE("of two objects at the same distance the one listed first is seen", "[scene][shape]") {
  Scene scene;
  SceneObject a;
  a.shape = Rectangle{{0.0, 0.0, 2.0}, {1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}};
  SceneObject b = a;
  b.material.emission = {1.0, 1.0, 1.0};
  scene.objects = {b, a};
  CHECK(intersect(scene, ray({0, 0, 0}, {0, 0, 1}))->object_index == 0);
  scene.objects = {a, b};
  CHECK(intersect(scene, ray({0, 0, 0}, {0, 0, 1}))->object_index == 0);
}

TEST_CASE("a rectangle's surface coordinates run along its half-edges from the centre", "[scene][shape]") {
  const Rectangle r{{1.0, 2.0, 3.0}, {0.0, 0.0, 2.0}, {0.0, 0.5, 0.0}};
  const SurfaceCoordinates c = surface_coordinates(r, {1.0, 2.25, 4.5});
  CHECK_THAT(c.s_m, WithinAbs(1.5, kDoubleRounding));
  CHECK_THAT(c.t_m, WithinAbs(0.25, kDoubleRounding));
  // Its normal is half_v x half_u: the side from which half_u points right and half_v up.
  CHECK(surface_normal(r, {1.0, 2.0, 3.0}) == Eigen::Vector3d(1.0, 0.0, 0.0));
}

TEST_CASE("a wall facing the default camera gets s to the right and t up", "[scene][shape]") {
  const Plane wall{{0.0, 0.0, 5.0}, {0.0, 0.0, -1.0}, std::nullopt};
  CHECK(default_u_axis(wall.normal) == Eigen::Vector3d(1.0, 0.0, 0.0));
  const SurfaceCoordinates c = surface_coordinates(wall, {0.3, 0.2, 5.0});
  CHECK_THAT(c.s_m, WithinAbs(0.3, kDoubleRounding));
  CHECK_THAT(c.t_m, WithinAbs(0.2, kDoubleRounding));
  // A floor: u = +x, v = u x n = +z (away from the default camera).
  const Plane floor{{0.0, -1.0, 0.0}, {0.0, 1.0, 0.0}, std::nullopt};
  const SurfaceCoordinates f = surface_coordinates(floor, {0.5, -1.0, 2.0});
  CHECK_THAT(f.s_m, WithinAbs(0.5, kDoubleRounding));
  CHECK_THAT(f.t_m, WithinAbs(2.0, kDoubleRounding));
}

TEST_CASE("a given u_axis is projected into the plane and sets the s direction", "[scene][shape]") {
  const Plane wall{{0.0, 0.0, 5.0}, {0.0, 0.0, -1.0}, Eigen::Vector3d(0.0, 1.0, 7.0)};
  const SurfaceCoordinates c = surface_coordinates(wall, {0.0, 0.4, 5.0});
  CHECK_THAT(c.s_m, WithinAbs(0.4, kDoubleRounding));
  CHECK_THAT(c.t_m, WithinAbs(0.0, kDoubleRounding));
}

TEST_CASE("sphere coordinates are arc lengths with the seam away from the default camera", "[scene][shape]") {
  const Sphere s{{0.0, 0.0, 5.0}, 2.0};
  const SurfaceCoordinates front = surface_coordinates(s, {0.0, 0.0, 3.0});
  CHECK(front.s_m == 0.0);
  CHECK(front.t_m == 0.0);
  const SurfaceCoordinates right = surface_coordinates(s, {2.0, 0.0, 5.0});
  CHECK_THAT(right.s_m, WithinRel(2.0 * kPi / 2.0, kDoubleRounding));
  const SurfaceCoordinates top = surface_coordinates(s, {0.0, 2.0, 5.0});
  CHECK_THAT(top.t_m, WithinRel(2.0 * kPi / 2.0, kDoubleRounding));
  const SurfaceCoordinates back = surface_coordinates(s, {0.0, 0.0, 7.0});
  CHECK_THAT(std::abs(back.s_m), WithinRel(2.0 * kPi, kDoubleRounding));
}

TEST_CASE("shapes refuse invalid fields by name", "[scene][shape]") {
  CHECK_THROWS_WITH(validate(Sphere{{0, 0, 1}, 0.0}), Contains("radius_m = 0: must be finite and > 0"));
  CHECK_THROWS_WITH(validate(Disc{{0, 0, 1}, {0, 0, 0}, 1.0, std::nullopt}), Contains("normal = [0, 0, 0]"));
  CHECK_THROWS_WITH(validate(Plane{{0, 0, std::nan("")}, {0, 0, 1}, std::nullopt}), Contains("point_m"));
  CHECK_THROWS_WITH(validate(Rectangle{{0, 0, 1}, {1, 0, 0}, {1, 1, 0}}), Contains("must be perpendicular"));
  CHECK_NOTHROW(validate(Rectangle{{0, 0, 1}, {1, 0, 0}, {1e-7, 1, 0}}));  // rounding of a hand-rotated rectangle
}
