// Textures: the checkerboard's parity rule on both sides of the origin, value noise's range,
// mean (uniform lattice values average 1/2), continuity and determinism, and the placement of an
// image texture's corners.
#include "lensmith/scene/texture.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <memory>

#include "lensmith/scene/scene_error.h"

using Catch::Matchers::Contains;
using Catch::Matchers::WithinAbs;
using namespace lensmith;

namespace {

const Rgb kBlack{0.0, 0.0, 0.0};
const Rgb kWhite{1.0, 1.0, 1.0};

}  // namespace

TEST_CASE("a checker's first colour fills the square at the origin and alternates on both sides", "[scene][texture]") {
  const Texture checker = CheckerTexture{0.5, {kWhite, kBlack}};
  CHECK(evaluate(checker, {0.1, 0.1}).r == 1.0);
  CHECK(evaluate(checker, {0.6, 0.1}).r == 0.0);
  CHECK(evaluate(checker, {0.6, 0.6}).r == 1.0);
  CHECK(evaluate(checker, {-0.1, 0.1}).r == 0.0);
  CHECK(evaluate(checker, {-0.1, -0.1}).r == 1.0);
  CHECK(evaluate(checker, {-0.6, 0.1}).r == 1.0);
  CHECK(evaluate(checker, {1.0e30, 0.1}).r >= 0.0);  // no overflow far out on an infinite plane
}

TEST_CASE("value noise stays in 0 to 1 and averages one half", "[scene][texture]") {
  const NoiseTexture noise{0.1, 4, 5, {kBlack, kWhite}};
  double sum = 0.0;
  double lo = 1.0;
  double hi = 0.0;
  const int n = 400;
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      // A 40 x 40 m patch sampled every 0.1013 m: 160000 samples over ~160000 lattice cells.
      const double v = fractal_value_noise(noise, {-20.0 + 0.1013 * i, -17.0 + 0.1013 * j});
      sum += v;
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
  }
  CHECK(lo >= 0.0);
  CHECK(hi < 1.0);
  // The lattice values are independent uniform [0, 1) numbers; interpolation keeps their mean 1/2.
  // Over ~1.6e5 cells of first-octave spread (sd ~0.15) the mean's standard error is ~5e-4.
  CHECK_THAT(sum / (n * n), WithinAbs(0.5, 0.005));
  CHECK(hi - lo > 0.6);  // it is not flat
}

TEST_CASE("value noise is continuous and deterministic, and the seed changes it", "[scene][texture]") {
  const NoiseTexture a{0.1, 4, 1, {kBlack, kWhite}};
  NoiseTexture b = a;
  b.seed = 2;
  const SurfaceCoordinates p{0.123, -0.456};
  // Deterministic: an equal texture made separately gives the same value after other evaluations in
  // between (no hidden state, no per-object random seeding).
  const double first = fractal_value_noise(a, p);
  (void)fractal_value_noise(b, {1.0, 2.0});
  const NoiseTexture a_again{0.1, 4, 1, {kBlack, kWhite}};
  CHECK(fractal_value_noise(a_again, p) == first);
  // The quintic fade has bounded slope (15/8 per lattice unit and octave, weights 2^-k): a step of
  // 1e-8 m, under 1e-6 lattice units of the finest octave, moves the value by far less than 1e-4.
  CHECK_THAT(fractal_value_noise(a, {p.s_m + 1e-8, p.t_m}), WithinAbs(fractal_value_noise(a, p), 1e-4));
  CHECK(fractal_value_noise(a, p) != fractal_value_noise(b, p));
  const Rgb colour = evaluate(Texture{a}, p);
  CHECK_THAT(colour.g, WithinAbs(fractal_value_noise(a, p), 1e-15));
}

TEST_CASE("an image texture puts the picture's top-left texel at minus s and plus t", "[scene][texture]") {
  auto picture = std::make_shared<Image>(2, 2, 3, 0.0f);
  picture->at(0, 0, 0) = 1.0f;  // top left: red
  picture->at(1, 1, 2) = 1.0f;  // bottom right: blue
  const Texture texture = ImageTexture{"test.exr", picture, 2.0, 1.0};
  // Texel centres: s = -0.5, 0.5 and t = 0.25, -0.25.
  CHECK(evaluate(texture, {-0.5, 0.25}).r == 1.0);
  CHECK(evaluate(texture, {0.5, -0.25}).b == 1.0);
  CHECK(evaluate(texture, {0.5, 0.25}).r == 0.0);
  // Halfway between the top texels, bilinear; and one width further, the same (it repeats).
  CHECK_THAT(evaluate(texture, {0.0, 0.25}).r, WithinAbs(0.5, 1e-15));
  CHECK_THAT(evaluate(texture, {2.0, 0.25}).r, WithinAbs(0.5, 1e-15));
  CHECK_THAT(evaluate(texture, {-0.5, -1e6 + 0.25}).r, WithinAbs(1.0, 1e-6));
}

TEST_CASE("textures refuse invalid fields by name", "[scene][texture]") {
  CHECK_THROWS_AS(validate(Texture{CheckerTexture{0.0, {kWhite, kBlack}}}), SceneError);
  CHECK_THROWS_WITH(validate(Texture{CheckerTexture{-1.0, {kWhite, kBlack}}}), Contains("size_m = -1"));
  CHECK_THROWS_WITH(validate(Texture{NoiseTexture{1.0, 0, 0, {kWhite, kBlack}}}), Contains("octaves = 0"));
  CHECK_THROWS_WITH(validate(Texture{ConstantTexture{{-1.0, 0.0, 0.0}}}), Contains("colour"));
  CHECK_THROWS_WITH(validate(Texture{ImageTexture{"x.exr", nullptr, 1.0, 1.0}}), Contains("x.exr"));
}
