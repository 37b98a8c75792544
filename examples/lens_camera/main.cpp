// The smallest renderer that puts a real lens in front of its film: per pixel and sample, a pupil
// sample and a wavelength go to lensmith::LensCamera, which returns the ray leaving the lens and
// its radiometric weight; the renderer intersects its own scene (here a checkered wall and a row of
// small lights) and averages weight x radiance. Everything lensmith-specific is in the five lines
// marked "lensmith". Writes a binary PPM (sRGB, no other library needed).
//
//   lens_camera_example OUT.ppm [LENS (shipped name or file), default pbrt-dgauss-50mm]
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include "lensmith/camera/camera.h"
#include "lensmith/camera/lens_camera.h"
#include "lensmith/core/errors.h"
#include "lensmith/prescription/lens_library.h"

namespace {

constexpr int kWidth = 240, kHeight = 160, kSamples = 64;

// The renderer's own scene, in the camera frame (metres; z forward): a checkered wall at 4 m, and
// lights (emitting 40) on a row at 0.7 m, out of focus when the lens focuses at 4 m.
double radiance_along(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction) {
  for (int i = -3; i <= 3; ++i) {
    const Eigen::Vector3d light(0.05 * i, 0.02, 0.7);
    const Eigen::Vector3d to = light - origin;
    const double t = to.dot(direction);
    if (t > 0.0 && (to - t * direction).norm() < 0.002) return 40.0;
  }
  if (direction.z() <= 0.0) return 0.0;
  const double t = (4.0 - origin.z()) / direction.z();
  const Eigen::Vector3d p = origin + t * direction;
  const bool dark = (static_cast<int>(std::floor(p.x() / 0.1)) + static_cast<int>(std::floor(p.y() / 0.1))) % 2 != 0;
  return dark ? 0.05 : 0.6;
}

// A simple low-discrepancy pair (R2 sequence, Roberts 2018), offset per pixel.
double fract(double x) { return x - std::floor(x); }

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::cerr << "usage: lens_camera_example OUT.ppm [LENS]\n";
    return 2;
  }
  try {
    // lensmith: the lens, a camera focused at 4 m at f/2 whose film frames a 36 mm wide image of
    // kWidth x kHeight pixels, and the primary-ray generator (exact tracing).
    const lensmith::Prescription lens = lensmith::LensLibrary::load(argc > 2 ? argv[2] : "pbrt-dgauss-50mm").prescription;
    lensmith::CameraOptions options;
    options.focus_distance_m = 4.0;
    options.f_number = 2.0;
    const lensmith::Camera camera = lensmith::Camera::from_lens(lens, options, kWidth, kHeight);
    const lensmith::LensCamera lens_camera(camera, std::vector<double>{587.56});

    std::vector<double> image(static_cast<std::size_t>(kWidth) * kHeight, 0.0);
    for (int y = 0; y < kHeight; ++y) {
      for (int x = 0; x < kWidth; ++x) {
        double sum = 0.0;
        for (int s = 0; s < kSamples; ++s) {
          const double jitter_x = fract(0.5 + s * 0.7548776662), jitter_y = fract(0.5 + s * 0.5698402910);
          const double u = fract(0.31 * x + 0.17 * y + s * 0.7548776662), v = fract(0.23 * x + 0.41 * y + s * 0.5698402910);
          // lensmith: the film point of this sample, and the ray the lens sends into the scene.
          const auto film = lens_camera.film_point_mm(x + jitter_x, y + jitter_y);
          const std::optional<lensmith::CameraRay> ray = lens_camera.generate_ray(film[0], film[1], u, v, 587.56);
          if (ray) sum += ray->weight * radiance_along(ray->origin_m, ray->direction);
        }
        image[static_cast<std::size_t>(y) * kWidth + x] = sum / kSamples;
      }
    }
    std::ofstream out(argv[1], std::ios::binary);
    out << "P6\n" << kWidth << " " << kHeight << "\n255\n";
    for (double v : image) {
      const double c = std::clamp(v, 0.0, 1.0);
      const double encoded = c <= 0.0031308 ? 12.92 * c : 1.055 * std::pow(c, 1.0 / 2.4) - 0.055;
      const auto byte = static_cast<char>(static_cast<std::uint8_t>(std::lround(255.0 * encoded)));
      out << byte << byte << byte;
    }
    if (!out) throw lensmith::IoError(std::string(argv[1]) + ": cannot write");
    std::cout << "wrote " << argv[1] << " (" << kWidth << " x " << kHeight << ", " << kSamples << " samples per pixel) through "
              << lens.name << ": " << lens_camera.to_string() << "\n";
  } catch (const lensmith::Error& e) {
    std::cerr << "lens_camera_example: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
