#include "sharp_pixels.h"

#include <omp.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

#include "footprint.h"
#include "illumination_table.h"
#include "lensmith/core/units.h"

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

// A source's reach (px) from its centre: its blur radius, and kReachCells of its splat grid.
double reach_px(double coc_px) {
  const double size = std::abs(coc_px);
  return 0.5 * size + kReachCells * static_cast<double>(1 << grid_level(size));
}
// Reach map values: a sharp whole pixel of the layer looked at (a candidate for the copy), and a
// pixel where no source of that layer lies or can lie (a farther one's).
constexpr float kCandidate = -1.0f;
constexpr float kNothing = -2.0f;
constexpr float kNearer = -3.0f;  // a nearer pixel's, until the layer's largest blur is known

// The least blur (px) that spacing.layer_at puts in layer `l` or a nearer one: -infinity for the
// first layer, +infinity beyond the last. layer_at is monotone in the blur, so a bisection over the
// doubles in their order finds it exactly, and `blur < least_blur_of_layer(l)` is layer_at(blur) < l.
double least_blur_of_layer(const LayerSpacing& spacing, int l) {
  if (l <= 0) return -kInfinity;
  if (l >= spacing.count) return kInfinity;
  // Doubles in order as integers: non-negative ones by their bits, negative ones by their bits' negated size.
  const auto key_of = [](double v) {
    const auto bits = std::bit_cast<std::int64_t>(v);
    return bits >= 0 ? bits : -(bits & std::numeric_limits<std::int64_t>::max());
  };
  const auto value_of = [](std::int64_t k) {
    return k >= 0 ? std::bit_cast<double>(k) : -std::bit_cast<double>(-k);
  };
  // Below is layer 0 and above the last layer (layer_at clamps to them).
  std::int64_t below = key_of(spacing.coc_min_px - spacing.spacing_px);
  std::int64_t above = key_of(spacing.coc_min_px + (spacing.count + 1) * spacing.spacing_px);
  // (Their difference taken unsigned: it may exceed the largest signed one.)
  const auto gap = [&] { return static_cast<std::uint64_t>(above) - static_cast<std::uint64_t>(below); };
  while (gap() > 1) {
    const std::int64_t mid = below + static_cast<std::int64_t>(gap() / 2);
    (spacing.layer_at(value_of(mid)) >= l ? above : below) = mid;
  }
  return value_of(above);
}

// A source whose footprint is a point at its pixel's centre, where the tent gives all of it to that
// pixel: it reaches no other (a layer's hidden sources are at their pixels' centres, interpolated
// from its pixels: such points where those are).
bool point_at_centre(const ScatterSource& s) {
  return std::abs(s.coc_px) < kSharpBlurPx && s.offset_x_px == 0.0f && s.offset_y_px == 0.0f;
}

bool sharp_whole(const ScatterSource& s) {
  return point_at_centre(s) && s.coverage == 1.0f && s.hidden == 0.0f && !s.coverage_only;
}

}  // namespace

bool copies_sharp_pixels(const RayModel& model, const Aperture& aperture, const BokehOptions& options) {
  return options.copy_sharp_pixels && model.kind() == RayModelKind::Thin && aperture.kind() != Aperture::Kind::Mask &&
         !IlluminationTable::applies(model, aperture, options.vignetting, true);
}

std::size_t mark_sharp_pixels(ScatterSources& sources, int width, int height, const LayerSpacing& spacing, int threads) {
  const std::size_t pixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  if (width < 1 || height < 1 || sources.size() < pixels || spacing.count < 1) return 0;
  std::size_t copied = 0;
  std::vector<float> reach(pixels);
  std::vector<std::vector<int>> drawn(static_cast<std::size_t>(height));
  const std::unique_ptr<int[]> ends(new int[pixels]);
  // The layers a sharp pixel can fall in (usually the focus layer alone: LayerSpacing::focus_split).
  for (int sharp_layer = spacing.layer_at(-kSharpBlurPx); sharp_layer <= spacing.layer_at(kSharpBlurPx); ++sharp_layer) {
    // This layer's blurs, [lo, hi) exactly as layer_at bins them: farther ones below, nearer above.
    const double lo = least_blur_of_layer(spacing, sharp_layer), hi = least_blur_of_layer(spacing, sharp_layer + 1);
    const auto reach_of = [&](const ScatterSource& s) -> float {
      if (s.coc_px < lo) return kNothing;
      if (s.coc_px >= hi) return kNearer;
      return point_at_centre(s) ? kNothing : static_cast<float>(reach_px(s.coc_px));
    };
    // Per pixel, how far (px) the footprints of this layer's sources there reach from its centre:
    // kCandidate for a sharp whole pixel of the layer, kNothing where none lies or can lie, kNearer
    // (until the layer's largest blur is known) over a nearer pixel.
    bool any_sharp = false;
    double largest_blur = 0.0;
#pragma omp parallel for num_threads(threads) schedule(static) reduction(|| : any_sharp) reduction(max : largest_blur)
    for (int y = 0; y < height; ++y) {
      const std::size_t row = static_cast<std::size_t>(y) * width;
      for (int x = 0; x < width; ++x) {
        const ScatterSource& s = sources[row + x];
        const bool in_layer = s.coc_px >= lo && s.coc_px < hi, sharp = in_layer && sharp_whole(s);
        any_sharp = any_sharp || sharp;
        largest_blur = std::max(largest_blur, in_layer ? std::abs(s.coc_px) : 0.0);
        reach[row + x] = sharp ? kCandidate : reach_of(s);
      }
    }
    if (!any_sharp) continue;
    // Parts beyond one a pixel (a split pixel's far part), inside the frame.
    const auto in_frame = [&](const ScatterSource& s) { return s.x >= 0 && s.y >= 0 && s.x < width && s.y < height; };
    for (std::size_t i = pixels; i < sources.size(); ++i) {
      const ScatterSource& s = sources[i];
      if (in_frame(s) && s.coc_px >= lo && s.coc_px < hi) largest_blur = std::max(largest_blur, std::abs(s.coc_px));
    }
    // A nearer pixel may have hidden sources of this layer under it, interpolated from the layer's own
    // blurs (a margin beyond the frame repeats its edge pixels' blurs).
    const float hidden_reach = largest_blur < kSharpBlurPx ? kNothing : static_cast<float>(reach_px(largest_blur));
#pragma omp parallel for num_threads(threads) schedule(static)
    for (std::ptrdiff_t i = 0; i < static_cast<std::ptrdiff_t>(pixels); ++i) {
      if (reach[static_cast<std::size_t>(i)] == kNearer) reach[static_cast<std::size_t>(i)] = hidden_reach;
    }
    // A part's pixel is not whole, and the part reaches as its layer says.
    for (std::size_t i = pixels; i < sources.size(); ++i) {
      const ScatterSource& s = sources[i];
      if (!in_frame(s)) continue;
      float& r = reach[static_cast<std::size_t>(s.y) * width + s.x];
      const float part = reach_of(s);
      r = std::max(r == kCandidate ? kNothing : r, part == kNearer ? hidden_reach : part);
    }
    // The pixels whose reach is drawn, row by row, and the farthest reach.
    float farthest = 0.0f;
#pragma omp parallel for num_threads(threads) schedule(static) reduction(max : farthest)
    for (int y = 0; y < height; ++y) {
      const std::size_t row = static_cast<std::size_t>(y) * width;
      std::vector<int>& list = drawn[static_cast<std::size_t>(y)];
      list.clear();
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
#pragma omp parallel num_threads(threads) reduction(+ : copied)
    {
      const int t = omp_get_thread_num(), n = omp_get_num_threads();
      const int y0 = static_cast<int>(static_cast<long long>(height) * t / n), y1 = static_cast<int>(static_cast<long long>(height) * (t + 1) / n);
      // (Each thread writes only its own rows' ends: they are first touched, and set, there.)
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
          if (x > reached_to && reach[row + x] == kCandidate) {
            sources[row + x].copied = true;
            ++copied;
          }
        }
      }
    }
  }
  return copied;
}

}  // namespace lensmith::render_detail
