#include "sharp_pixels.h"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <vector>

#include "footprint.h"
#include "illumination_table.h"

namespace lensmith::render_detail {

namespace {

// Blur (px) under which a whole pixel is copied: half the planner's point threshold (footprint.h),
// which it tests on the probe's extent, not on the blur itself.
constexpr double kSharpBlurPx = 0.5 * kPointFootprintPx;
// How far beyond its blur radius another source's footprint reaches, in cells of its splat grid:
// the tent (kTentMarginPx) and one cell more, within which a merged source's centre moves
// (source_merging).
constexpr double kReachCells = kTentMarginPx + 1.0;
// A pixel's reach is drawn only where it can matter: at the border of the pixels that reach
// anywhere, or where it reaches farther than a 4-neighbour by more than this (px). Inside, the
// neighbours' reaches cover its own: a sharp pixel within reach of an inner pixel lies on the far
// side of a border pixel whose reach is at most this much less per pixel of the way (a footprint
// of radius r >= 3 is covered by its 4-neighbours' of r - kInnerSlackPx). Border reaches are drawn
// kBorderGrowthPx larger for the pixel grid's corners on that way.
constexpr double kInnerSlackPx = 0.5;
constexpr double kBorderGrowthPx = 1.0;

bool sharp_whole(const ScatterSource& s) {
  return std::abs(s.coc_px) < kSharpBlurPx && s.coverage == 1.0f && s.hidden == 0.0f && !s.coverage_only && s.offset_x_px == 0.0f &&
         s.offset_y_px == 0.0f;
}

}  // namespace

bool copies_sharp_pixels(const RayModel& model, const Aperture& aperture, const BokehOptions& options) {
  return options.copy_sharp_pixels && model.kind() == RayModelKind::Thin && aperture.kind() != Aperture::Kind::Mask &&
         !IlluminationTable::applies(model, aperture, options.vignetting, true);
}

std::size_t mark_sharp_pixels(ScatterSources& sources, int width, int height, double layer_spacing_px, int threads) {
  const std::size_t pixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  if (width < 1 || height < 1 || sources.size() < pixels) return 0;
  // Per pixel, how far (px) its footprints reach from its centre; -1 for a sharp whole pixel.
  std::vector<float> reach(pixels);
  auto reach_of = [layer_spacing_px](const ScatterSource& s) {
    const double size = std::abs(s.coc_px);
    return 0.5 * size + kReachCells * static_cast<double>(1 << grid_level(size)) + 0.5 * layer_spacing_px;
  };
  bool any_sharp = false;
#pragma omp parallel for num_threads(threads) schedule(static) reduction(|| : any_sharp)
  for (int y = 0; y < height; ++y) {
    const std::size_t row = static_cast<std::size_t>(y) * width;
    for (int x = 0; x < width; ++x) {
      const ScatterSource& s = sources[row + x];
      const bool sharp = sharp_whole(s);
      any_sharp = any_sharp || sharp;
      reach[row + x] = sharp ? -1.0f : static_cast<float>(reach_of(s));
    }
  }
  if (!any_sharp) return 0;
  // Parts beyond one a pixel (a split pixel's far part): that pixel is not whole.
  for (std::size_t i = pixels; i < sources.size(); ++i) {
    const ScatterSource& s = sources[i];
    if (s.x < 0 || s.y < 0 || s.x >= width || s.y >= height) continue;
    float& r = reach[static_cast<std::size_t>(s.y) * width + s.x];
    r = std::max({r, static_cast<float>(reach_of(s)), 0.0f});
  }
  // The pixels whose reach is drawn, row by row, and the farthest reach.
  std::vector<std::vector<int>> drawn(static_cast<std::size_t>(height));
  float farthest = 0.0f;
#pragma omp parallel for num_threads(threads) schedule(static) reduction(max : farthest)
  for (int y = 0; y < height; ++y) {
    const std::size_t row = static_cast<std::size_t>(y) * width;
    std::vector<int>& list = drawn[static_cast<std::size_t>(y)];
    for (int x = 0; x < width; ++x) {
      const float r = reach[row + x];
      if (r < 0.0f) continue;
      // Beyond the frame the scatter's margin repeats the edge pixel: a neighbour as far-reaching.
      const float floor = r - static_cast<float>(kInnerSlackPx);
      const bool inner = (x == 0 || reach[row + x - 1] >= floor) && (x + 1 == width || reach[row + x + 1] >= floor) &&
                         (y == 0 || reach[row - width + x] >= floor) && (y + 1 == height || reach[row + width + x] >= floor);
      if (inner) continue;
      list.push_back(x);
      farthest = std::max(farthest, r);
    }
  }
  // Per row, where the drawn reaches that begin at each column end (the largest), then a sweep:
  // each thread its band of rows, from the drawn pixels within the farthest reach of it.
  const int window = static_cast<int>(std::ceil(farthest + kBorderGrowthPx));
  // (Each thread writes only its own rows' ends: they are first touched, and set, there.)
  const std::unique_ptr<int[]> ends(new int[pixels]);
  std::size_t copied = 0;
#pragma omp parallel num_threads(threads) reduction(+ : copied)
  {
    const int t = omp_get_thread_num(), n = omp_get_num_threads();
    const int y0 = static_cast<int>(static_cast<long long>(height) * t / n), y1 = static_cast<int>(static_cast<long long>(height) * (t + 1) / n);
    std::fill(ends.get() + static_cast<std::size_t>(y0) * width, ends.get() + static_cast<std::size_t>(y1) * width, -1);
    for (int sy = std::max(0, y0 - window); sy < std::min(height, y1 + window); ++sy) {
      const std::size_t srow = static_cast<std::size_t>(sy) * width;
      for (const int sx : drawn[static_cast<std::size_t>(sy)]) {
        const double r = reach[srow + sx] + kBorderGrowthPx;
        const int rows = static_cast<int>(r);
        for (int y = std::max(y0, sy - rows); y <= std::min(y1 - 1, sy + rows); ++y) {
          const double dy = y - sy;
          const int half = static_cast<int>(std::sqrt(r * r - dy * dy));
          int& end = ends[static_cast<std::size_t>(y) * width + static_cast<std::size_t>(std::max(0, sx - half))];
          end = std::max(end, sx + half);
        }
      }
    }
    for (int y = y0; y < y1; ++y) {
      const std::size_t row = static_cast<std::size_t>(y) * width;
      int reached_to = -1;
      for (int x = 0; x < width; ++x) {
        reached_to = std::max(reached_to, ends[row + x]);
        if (x > reached_to && reach[row + x] < 0.0f) {
          sources[row + x].copied = true;
          ++copied;
        }
      }
    }
  }
  return copied;
}

}  // namespace lensmith::render_detail
