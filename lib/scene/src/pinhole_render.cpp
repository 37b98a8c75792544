#include "lensmith/scene/pinhole_render.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

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

DeepImage render_pinhole_layers(const Scene& scene, const PinholeFrame& frame, int layers, const PinholeRenderOptions& options) {
  options.validate();
  scene.validate();
  if (layers < 1 || layers > kMaxPeeledLayers) {
    throw OptionsError("layers = " + std::to_string(layers) + ": must be in 1.." + std::to_string(kMaxPeeledLayers));
  }
  const int width = frame.width_px();
  const int height = frame.height_px();
  const CameraBasis basis = scene.camera.basis();
  const int n = options.samples_per_axis;
  const double cell = 1.0 / n;
  const int threads = options.threads > 0 ? options.threads : omp_get_max_threads();
  // What the rays of one pixel met, per object (and the background, object kBackground).
  constexpr std::size_t kBackground = std::numeric_limits<std::size_t>::max();
  struct Met {
    std::size_t object = 0;
    int rays = 0;
    Rgb radiance{0.0, 0.0, 0.0};
    double depth_sum_m = 0.0;
  };
  // Per row (rows go to threads) its pixels' samples, and per pixel how many: a vector per pixel
  // cost an allocation each.
  std::vector<std::vector<DeepSample>> rows(static_cast<std::size_t>(height));
  std::vector<std::uint32_t> counts(static_cast<std::size_t>(width) * height, 0);

#pragma omp parallel num_threads(threads)
  {
    std::vector<Met> met;
    std::vector<std::size_t> peeled;
    // Per ray of the pixel: the objects it met (indices into `met`), whether it was cut off after
    // `layers` objects, and the depth of its last recorded object.
    struct RayRecord {
      std::vector<std::size_t> met;
      bool truncated = false;
      double last_depth_m = 0.0;
    };
    std::vector<RayRecord> rays(static_cast<std::size_t>(n) * n);
#pragma omp for schedule(dynamic, 1)
    for (int y = 0; y < height; ++y) {
      for (int x = 0; x < width; ++x) {
        met.clear();
        auto record = [&met](std::size_t object, const Rgb& radiance, double depth_m) {
          auto it = std::find_if(met.begin(), met.end(), [object](const Met& m) { return m.object == object; });
          if (it == met.end()) it = met.insert(met.end(), Met{object, 0, Rgb{0.0, 0.0, 0.0}, 0.0});
          ++it->rays;
          it->radiance += radiance;
          it->depth_sum_m += depth_m;
          return static_cast<std::size_t>(it - met.begin());
        };
        for (int b = 0; b < n; ++b) {
          for (int a = 0; a < n; ++a) {
            RayRecord& r = rays[static_cast<std::size_t>(b * n + a)];
            r.met.clear();
            r.truncated = false;
            const SceneRay ray = ray_through(frame, scene.camera, basis, PixelPoint{x + (a + 0.5) * cell, y + (b + 0.5) * cell});
            const double planar = ray.direction.dot(basis.forward);
            peeled.clear();
            for (int k = 0; k < layers; ++k) {
              const std::optional<SceneHit> hit = intersect(scene, ray, peeled);
              if (!hit) {
                // The background is a surface only where it is seen: behind an (opaque) object
                // nothing is hidden but sky.
                if (k == 0) r.met.push_back(record(kBackground, scene.background, std::numeric_limits<double>::infinity()));
                break;
              }
              r.last_depth_m = hit->distance_m * planar;
              r.met.push_back(record(hit->object_index, hit->radiance, r.last_depth_m));
              peeled.push_back(hit->object_index);
              r.truncated = k + 1 == layers;
            }
          }
        }
        std::vector<DeepSample>& samples = rows[static_cast<std::size_t>(y)];
        counts[static_cast<std::size_t>(y) * width + x] = static_cast<std::uint32_t>(met.size());
        for (std::size_t i = 0; i < met.size(); ++i) {
          const Met& m = met[i];
          DeepSample s;
          s.z_m = m.object == kBackground ? std::numeric_limits<float>::infinity() : static_cast<float>(m.depth_sum_m / m.rays);
          s.z_back_m = s.z_m;
          // Alpha: the share of the rays known to meet or to miss the object that meet it (a ray cut
          // off in front of it may have met it): the object's own coverage, which "over" composites
          // back to the picture. The background lies behind everything: it covers all.
          int misses = 0;
          for (const RayRecord& r : rays) {
            if (std::find(r.met.begin(), r.met.end(), i) != r.met.end()) continue;
            if (!r.truncated || r.last_depth_m >= s.z_m) ++misses;
          }
          const double alpha = m.object == kBackground ? 1.0 : static_cast<double>(m.rays) / (m.rays + misses);
          for (int c = 0; c < 3; ++c) s.rgb[static_cast<std::size_t>(c)] = static_cast<float>(alpha * m.radiance[c] / m.rays);
          s.alpha = static_cast<float>(alpha);
          samples.push_back(s);
        }
      }
    }
  }
  DeepImage out(width, height);
  std::size_t total = 0;
  for (const std::vector<DeepSample>& row : rows) total += row.size();
  out.samples.reserve(total);
  for (int y = 0; y < height; ++y) {
    const DeepSample* next = rows[static_cast<std::size_t>(y)].data();
    for (int x = 0; x < width; ++x) {
      const std::uint32_t count = counts[static_cast<std::size_t>(y) * width + x];
      out.push_pixel(std::span<const DeepSample>(next, count));
      next += count;
    }
  }
  return out;
}

}  // namespace lensmith
