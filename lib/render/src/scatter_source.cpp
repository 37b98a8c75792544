#include "scatter_source.h"

#include <algorithm>
#include <cmath>

#include "lensmith/core/units.h"

namespace lensmith::render_detail {

namespace {
// Nearest object the renderer places: this far in front of the lens's first surface (mm).
constexpr double kNearestObjectMm = 1.0;
// Bisection steps for the depth whose blur is the limit: 2^-60 of the inverse-depth interval.
constexpr int kClampBisections = 60;
}  // namespace

double clamp_inverse_depth(const Camera& camera, double w, double max_blur_px, std::size_t& clamped) {
  const double nearest_mm = std::max(camera.z_perspective_mm(), 0.0) + kNearestObjectMm;
  if (w > 1.0 / nearest_mm) {
    w = 1.0 / nearest_mm;
    ++clamped;
  }
  if (std::abs(camera.signed_coc_px(w)) <= max_blur_px) return w;
  // Bisect between the focus plane (no blur) and w for the depth whose blur is the limit.
  double in = inverse_per_mm(camera.focus_distance_mm()), out = w;
  for (int k = 0; k < kClampBisections; ++k) {
    const double mid = 0.5 * (in + out);
    (std::abs(camera.signed_coc_px(mid)) <= max_blur_px ? in : out) = mid;
  }
  ++clamped;
  return in;
}

ScatterSources make_scatter_sources(const Image& image, const DepthMap& depth, const Camera& camera,
                                                const BokehOptions& options, int threads, BokehStatistics& stats) {
  const int w = image.width, h = image.height;
  // Room for the second parts of split edge pixels (mixed_pixels), so that they are appended
  // without a copy of the frame's sources: reserved address space costs nothing until touched, and
  // on a virtual machine touching fresh memory is what costs (docs/performance.md).
  const std::size_t pixels = static_cast<std::size_t>(w) * h;
  ScatterSources sources;
  sources.reserve(pixels + pixels / 4);
  sources.resize(pixels);
  std::size_t clamped = 0;
  double coc_min = kInfinity, coc_max = -kInfinity;
#pragma omp parallel for num_threads(threads) schedule(static) reduction(+ : clamped) reduction(min : coc_min) reduction(max : coc_max)
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      ScatterSource& s = sources[static_cast<std::size_t>(y) * w + x];
      s.x = x;
      s.y = y;
      s.rgb = {image.at(x, y, 0), image.at(x, y, 1), image.at(x, y, 2)};
      s.inverse_depth_per_mm = clamp_inverse_depth(camera, inverse_depth_per_mm(depth.at(x, y)), options.max_blur_px, clamped);
      s.coc_px = camera.signed_coc_px(s.inverse_depth_per_mm);
      coc_min = std::min(coc_min, s.coc_px);
      coc_max = std::max(coc_max, s.coc_px);
    }
  }
  stats.source_pixels = sources.size();
  stats.clamped_depths = clamped;
  stats.max_abs_coc_px = std::max(std::abs(coc_min), std::abs(coc_max));
  return sources;
}

}  // namespace lensmith::render_detail
