#include "lensmith/core/number_parsing.h"
#include "lensmith/scene/texture.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "lensmith/scene/scene.h"
#include "lensmith/scene/scene_error.h"

namespace lensmith {

namespace {

// Lattice coordinates are clamped to +-2^50 before conversion to integers: far beyond any texture
// detail a double still resolves there, and safely inside int64.
constexpr double kMaxLatticeCoordinate = 1125899906842624.0;
constexpr int kMaxOctaves = 16;

template <class... Ts>
struct Overloaded : Ts... {
  using Ts::operator()...;
};
template <class... Ts>
Overloaded(Ts...) -> Overloaded<Ts...>;

// `shown` names the value in the message; the subject is its key (the part before any index), and
// `index` the entry of a list.
void require_size(double size_m, const char* shown, int index = -1) {
  if (!(std::isfinite(size_m) && size_m > 0.0)) {
    const std::string name(shown);
    throw SceneError(ErrorSubject{0, name.substr(0, name.find_first_of("[ ")), index}, name + " = " + format_rounded(size_m, 6) + ": must be finite and > 0");
  }
}

// SplitMix64's finaliser (Steele, Lea & Flood, "Fast splittable pseudorandom number generators",
// OOPSLA 2014): a bijective mix of 64 bits with full avalanche.
std::uint64_t mix64(std::uint64_t z) {
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

// The random value in [0, 1) at lattice point (ix, iy) of the noise keyed by `key`.
double lattice_value(std::int64_t ix, std::int64_t iy, std::uint64_t key) {
  const std::uint64_t h = mix64(mix64(mix64(key) ^ static_cast<std::uint64_t>(ix)) ^ static_cast<std::uint64_t>(iy));
  return static_cast<double>(h >> 11) * 0x1.0p-53;
}

double fade(double u) { return u * u * u * (u * (u * 6.0 - 15.0) + 10.0); }

double lerp(double a, double b, double w) { return a + (b - a) * w; }

// One octave of value noise at (x, y) in lattice units, in [0, 1).
double value_noise(double x, double y, std::uint64_t key) {
  x = std::clamp(x, -kMaxLatticeCoordinate, kMaxLatticeCoordinate);
  y = std::clamp(y, -kMaxLatticeCoordinate, kMaxLatticeCoordinate);
  const double fx = std::floor(x);
  const double fy = std::floor(y);
  const auto ix = static_cast<std::int64_t>(fx);
  const auto iy = static_cast<std::int64_t>(fy);
  const double wx = fade(x - fx);
  const double wy = fade(y - fy);
  const double bottom = lerp(lattice_value(ix, iy, key), lattice_value(ix + 1, iy, key), wx);
  const double top = lerp(lattice_value(ix, iy + 1, key), lattice_value(ix + 1, iy + 1, key), wx);
  return lerp(bottom, top, wy);
}

Rgb mix_colours(const std::array<Rgb, 2>& colours, double w) {
  return {lerp(colours[0].r, colours[1].r, w), lerp(colours[0].g, colours[1].g, w), lerp(colours[0].b, colours[1].b, w)};
}

// A texel coordinate reduced into [0, size).
double wrap(double x, int size) {
  double r = std::fmod(x, static_cast<double>(size));
  if (r < 0.0) r += size;
  return r < size ? r : 0.0;  // fmod of a tiny negative can round up to size
}

Rgb image_lookup(const ImageTexture& texture, const SurfaceCoordinates& at) {
  const Image& image = *texture.image;
  // Continuous texel position with texel centres at integers: (s / width + 1/2) W - 1/2.
  const double px = wrap((at.s_m / texture.width_m + 0.5) * image.width - 0.5, image.width);
  const double py = wrap((0.5 - at.t_m / texture.height_m) * image.height - 0.5, image.height);
  const int x0 = static_cast<int>(px);
  const int y0 = static_cast<int>(py);
  const double wx = px - x0;
  const double wy = py - y0;
  const int x1 = x0 + 1 == image.width ? 0 : x0 + 1;
  const int y1 = y0 + 1 == image.height ? 0 : y0 + 1;
  Rgb out;
  for (int c = 0; c < 3; ++c) {
    const double top = lerp(image.at(x0, y0, c), image.at(x1, y0, c), wx);
    const double bottom = lerp(image.at(x0, y1, c), image.at(x1, y1, c), wx);
    out[c] = lerp(top, bottom, wy);
  }
  return out;
}

}  // namespace

std::string_view texture_type_name(const Texture& texture) {
  return std::visit(Overloaded{[](const ConstantTexture&) { return std::string_view("constant"); },
                               [](const CheckerTexture&) { return std::string_view("checker"); },
                               [](const NoiseTexture&) { return std::string_view("noise"); },
                               [](const ImageTexture&) { return std::string_view("image"); }},
                    texture);
}

void validate(const Texture& texture) {
  std::visit(Overloaded{[](const ConstantTexture& t) { validate_colour(t.colour, "colour"); },
                        [](const CheckerTexture& t) {
                          require_size(t.size_m, "size_m");
                          validate_colour(t.colours[0], "colours[0]");
                          validate_colour(t.colours[1], "colours[1]");
                        },
                        [](const NoiseTexture& t) {
                          require_size(t.scale_m, "scale_m");
                          if (t.octaves < 1 || t.octaves > kMaxOctaves) {
                            throw SceneError(ErrorSubject{0, "octaves", -1}, "octaves = " + std::to_string(t.octaves) + ": must be in 1..16");
                          }
                          validate_colour(t.colours[0], "colours[0]");
                          validate_colour(t.colours[1], "colours[1]");
                        },
                        [](const ImageTexture& t) {
                          if (!t.image) throw SceneError(ErrorSubject{0, "file", -1}, "image texture " + t.file.string() + ": no picture loaded");
                          if (t.image->channels != 3 || t.image->width < 1 || t.image->height < 1) {
                            throw SceneError(ErrorSubject{0, "file", -1}, "image texture " + t.file.string() + ": needs a 3-channel picture, got " +
                                             t.image->to_string());
                          }
                          require_size(t.width_m, "size_m[0] (width)", 0);
                          require_size(t.height_m, "size_m[1] (height)", 1);
                        }},
             texture);
}

double fractal_value_noise(const NoiseTexture& noise, const SurfaceCoordinates& at) {
  double sum = 0.0;
  double weight_sum = 0.0;
  double frequency = 1.0 / noise.scale_m;
  double weight = 1.0;
  for (int k = 0; k < noise.octaves; ++k) {
    const std::uint64_t key = (static_cast<std::uint64_t>(noise.seed) << 8) | static_cast<std::uint64_t>(k);
    sum += weight * value_noise(at.s_m * frequency, at.t_m * frequency, key);
    weight_sum += weight;
    frequency *= 2.0;
    weight *= 0.5;
  }
  return sum / weight_sum;
}

Rgb evaluate(const Texture& texture, const SurfaceCoordinates& at) {
  return std::visit(Overloaded{[](const ConstantTexture& t) { return t.colour; },
                               [&](const CheckerTexture& t) {
                                 // fmod keeps the parity exact for any double, where an integer cast could overflow.
                                 const double cell = std::floor(at.s_m / t.size_m) + std::floor(at.t_m / t.size_m);
                                 return std::fmod(cell, 2.0) == 0.0 ? t.colours[0] : t.colours[1];
                               },
                               [&](const NoiseTexture& t) { return mix_colours(t.colours, fractal_value_noise(t, at)); },
                               [&](const ImageTexture& t) { return image_lookup(t, at); }},
                    texture);
}

std::string to_string(const Texture& texture) {
  return std::visit(Overloaded{[](const ConstantTexture& t) { return "constant(" + t.colour.to_string() + ")"; },
                               [](const CheckerTexture& t) {
                                 return "checker(size " + format_rounded(t.size_m, 6) + " m, " + t.colours[0].to_string() + " / " +
                                        t.colours[1].to_string() + ")";
                               },
                               [](const NoiseTexture& t) {
                                 return "noise(scale " + format_rounded(t.scale_m, 6) + " m, " + std::to_string(t.octaves) + " octaves, seed " +
                                        std::to_string(t.seed) + ", " + t.colours[0].to_string() + " / " + t.colours[1].to_string() +
                                        ")";
                               },
                               [](const ImageTexture& t) {
                                 return "image(" + t.file.string() + ", " + (t.image ? t.image->to_string() : std::string("not loaded")) +
                                        ", " + format_rounded(t.width_m, 6) + " x " + format_rounded(t.height_m, 6) + " m)";
                               }},
                    texture);
}

}  // namespace lensmith
