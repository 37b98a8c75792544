#include "lensmith/scene/pinhole_render.h"

#include <limits>

#include <omp.h>

#include "lensmith/core/errors.h"
#include "lensmith/scene/camera_pose.h"
#include "lensmith/scene/scene_intersection.h"

namespace lensmith {

namespace {

constexpr int kMaxSamplesPerAxis = 64;

// The ray from the pinhole through continuous pixel position p.
SceneRay ray_through(const PinholeFrame& frame, const CameraPose& pose, const CameraBasis& basis, const PixelPoint& p) {
  const Tangents t = frame.tangents_at(p);
  return SceneRay{pose.position_m, (t.x * basis.right + t.y * basis.up + basis.forward).normalized()};
}

}  // namespace

void PinholeRenderOptions::validate() const {
  if (samples_per_axis < 1 || samples_per_axis > kMaxSamplesPerAxis) {
    throw OptionsError("PinholeRenderOptions::samples_per_axis = " + std::to_string(samples_per_axis) + ": must be in 1..64");
  }
  if (threads < 0) {
    throw OptionsError("PinholeRenderOptions::threads = " + std::to_string(threads) + ": must be >= 0 (0 = all hardware threads)");
  }
}

std::string PinholeRenderOptions::to_string() const {
  return "PinholeRenderOptions(samples_per_axis " + std::to_string(samples_per_axis) + ", threads " + std::to_string(threads) + ")";
}

std::string PinholeRender::to_string() const { return "PinholeRender(" + rgb.to_string() + ", " + depth.to_string() + ")"; }

PinholeRender render_pinhole(const Scene& scene, const PinholeFrame& frame, const PinholeRenderOptions& options) {
  options.validate();
  scene.validate();
  const int width = frame.width_px();
  const int height = frame.height_px();
  PinholeRender out{Image(width, height, 3, 0.0f), DepthMap(width, height, std::numeric_limits<float>::infinity())};
  const CameraBasis basis = scene.camera.basis();
  const int n = options.samples_per_axis;
  const double cell = 1.0 / n;
  const double sample_weight = 1.0 / (static_cast<double>(n) * n);
  const int threads = options.threads > 0 ? options.threads : omp_get_max_threads();

#pragma omp parallel for num_threads(threads) schedule(dynamic, 1)
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      // Colour: the centres of an n x n grid of sub-pixel cells.
      Rgb sum{0.0, 0.0, 0.0};
      for (int b = 0; b < n; ++b) {
        for (int a = 0; a < n; ++a) {
          const PixelPoint p{x + (a + 0.5) * cell, y + (b + 0.5) * cell};
          const std::optional<SceneHit> hit = intersect(scene, ray_through(frame, scene.camera, basis, p));
          sum += hit ? hit->radiance : scene.background;
        }
      }
      for (int c = 0; c < 3; ++c) out.rgb.at(x, y, c) = static_cast<float>(sum[c] * sample_weight);

      // Depth: the pixel-centre ray alone, as a renderer's depth pass.
      const SceneRay centre = ray_through(frame, scene.camera, basis, PixelPoint{x + 0.5, y + 0.5});
      if (const std::optional<SceneHit> hit = intersect(scene, centre)) {
        out.depth.at(x, y) = static_cast<float>(hit->distance_m * centre.direction.dot(basis.forward));
      }
    }
  }
  return out;
}

}  // namespace lensmith
