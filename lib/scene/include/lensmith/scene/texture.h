// Albedo textures of analytic scenes, evaluated at a surface's (s, t) coordinates in metres
// (shape.h): a constant colour, a checkerboard, fractal value noise (Perlin, "An image
// synthesizer", SIGGRAPH 1985, with value rather than gradient lattice noise, as in Ebert et al.,
// "Texturing and Modeling", 3rd ed., section 2.4) and a picture file. Every texture is a pure
// function of (s, t): deterministic, thread-safe, and allocation-free to evaluate.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <ostream>
#include <string>
#include <variant>

#include "lensmith/color/rgb.h"
#include "lensmith/render/image.h"
#include "lensmith/scene/shape.h"

namespace lensmith {

struct ConstantTexture {
  Rgb colour{0.0, 0.0, 0.0};  // linear RGB, each >= 0
};

// Squares of side size_m in (s, t): colours[0] where floor(s / size) + floor(t / size) is even
// (so the square [0, size) x [0, size) at the surface's origin), colours[1] where it is odd.
struct CheckerTexture {
  double size_m = 0.1;  // > 0
  std::array<Rgb, 2> colours{Rgb{0.8, 0.8, 0.8}, Rgb{0.1, 0.1, 0.1}};
};

// Fractal value noise n in [0, 1]: the sum over octaves k = 0 .. octaves-1 of 2^-k times lattice
// value noise at frequency 2^k / scale_m (random values in [0, 1) at the integer lattice points,
// hashed from (lattice point, seed, octave), blended with the quintic fade 6u^5 - 15u^4 + 10u^3),
// divided by the sum of the weights. Colour = (1 - n) colours[0] + n colours[1].
struct NoiseTexture {
  double scale_m = 0.1;  // lattice spacing of the first octave, > 0: the size of the largest blotches
  int octaves = 4;       // 1 .. 16
  std::uint32_t seed = 0;
  std::array<Rgb, 2> colours{Rgb{0.1, 0.1, 0.1}, Rgb{0.9, 0.9, 0.9}};
};

// A picture (linear RGB, as read_radiance_image gives it) spread over width_m x height_m of (s, t),
// centred on the surface's origin (s = t = 0 at the picture's centre; its top row at
// t = +height_m / 2, its left column at s = -width_m / 2) and repeated beyond. Bilinear between
// texel centres, wrapping around the edges.
struct ImageTexture {
  std::filesystem::path file;         // for messages and to_string
  std::shared_ptr<const Image> image;  // 3 channels, not null
  double width_m = 1.0;                // > 0
  double height_m = 1.0;               // > 0
};

using Texture = std::variant<ConstantTexture, CheckerTexture, NoiseTexture, ImageTexture>;

// "constant", "checker", "noise", "image" (the scene file's spelling).
std::string_view texture_type_name(const Texture& texture);

// Throws SceneError naming the field and the rule (colours finite and >= 0, sizes finite and > 0,
// octaves in 1..16, an image present with 3 channels).
void validate(const Texture& texture);

// The texture's colour at (s, t). Assumes validate() passed.
Rgb evaluate(const Texture& texture, const SurfaceCoordinates& at);

// Fractal value noise of NoiseTexture at (s, t), in [0, 1].
double fractal_value_noise(const NoiseTexture& noise, const SurfaceCoordinates& at);

std::string to_string(const Texture& texture);  // "checker(size 0.1 m, RGB(...) / RGB(...))"

}  // namespace lensmith
