#include "depth_layers.h"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "first_touch.h"
#include "lensmith/core/errors.h"
#include "lensmith/core/units.h"

namespace lensmith::render_detail {

LayerSpacing LayerSpacing::over(double coc_min_px, double coc_max_px, double spacing_px, int max_layers) {
  LayerSpacing l;
  const double range = coc_max_px - coc_min_px;
  // The bins lie on a grid with one centred on blur 0, the focus plane: sharp points then share a
  // layer only with what is blurred by less than half a spacing. Within a layer footprints
  // average by coverage, and with the grid starting at the smallest blur a sharp light 3 m away
  // shared its layer with a black wall at 6 m blurred by 1.85 px (pbrt-dgauss-50mm at f/2, 320 px
  // wide): where the wall's blur reached the light's pixels, the light was averaged with it and
  // kept 74 % of its light (paraxial; 87 % exact).
  auto place = [&](double spacing) {
    l.spacing_px = spacing;
    l.coc_min_px = (std::floor((coc_min_px + 0.5 * spacing) / spacing) - 0.5) * spacing;
    l.count = std::max(1, static_cast<int>(std::floor((coc_max_px - l.coc_min_px) / spacing)) + 1);
  };
  place(std::max(spacing_px, range / max_layers));
  // The grid's offset can cost one bin more than the range needs: widened to fit the cap.
  if (l.count > max_layers && max_layers > 1) place(range / (max_layers - 1));
  l.count = std::min(l.count, std::max(1, max_layers));
  // The focus bin cut in three: a sharp light in front of a wall blurred by 0.9 px (the case above,
  // the wall at 4 m) still kept 85 % of its light, averaged with the wall where its 0.9 px reached.
  if (l.coc_min_px <= 0.0 && 0.0 < l.coc_min_px + l.count * l.spacing_px) {
    l.focus_split = true;
    l.count += 2;
  }
  return l;
}

int LayerSpacing::layer_at(double coc_px) const {
  const int grid = count - (focus_split ? 2 : 0);
  const int g = std::clamp(static_cast<int>(std::floor((coc_px - coc_min_px) / spacing_px)), 0, grid - 1);
  if (!focus_split) return g;
  const int focus = static_cast<int>(std::floor(-coc_min_px / spacing_px));
  if (g < focus) return g;
  if (g > focus) return g + 2;
  const double cut = kFocusCut * spacing_px;
  return g + (coc_px < -cut ? 0 : coc_px < cut ? 1 : 2);
}

DepthLayers make_depth_layers(const ScatterSources& sources, int width, int height, const LayerSpacing& spacing, int threads,
                              bool pixels_first) {
  DepthLayers l;
  l.pixels_first = pixels_first && sources.size() >= static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  static_cast<LayerSpacing&>(l) = spacing;
  l.max_blur_px.assign(static_cast<std::size_t>(l.count), 0.0);
  l.copied_members.assign(static_cast<std::size_t>(l.count), 0);
  const std::size_t pixel_count = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  // Each source's layer, once (2 bytes: BokehOptions::max_layers is at most 1024, and the focus
  // split adds 2).
  if (l.count < 1 || l.count > std::numeric_limits<std::uint16_t>::max()) {
    throw OptionsError("depth layers: " + std::to_string(l.count) + " layers; 1 to 65535 are possible");
  }
  const auto n = static_cast<std::ptrdiff_t>(sources.size());
  const auto layer_count = static_cast<std::size_t>(l.count);
  // (The frame-sized arrays' fresh pages faulted in by the threads first: first_touch.h.)
  const int teams = std::max(1, threads);
  UnconstructedVector<std::uint16_t> layer_of;  // (its arrays are written whole by the threads below)
  fault_in(layer_of, sources.size(), teams);
  layer_of.resize(sources.size());
  // The layers' members are placed at their final positions (grown by doubling, the lists were
  // copied to fresh memory again and again: half a thousand page faults on a 600 x 400 frame), each
  // list in source order: each thread takes a contiguous share of the sources, finds their layers
  // (a source blurred as the one before it, most of a row of a wall, takes its layer over) and counts
  // them per layer; then places its share's members after those of the shares before it.
  std::vector<std::size_t> share_count(static_cast<std::size_t>(teams) * layer_count, 0);
  std::vector<double> share_blur(share_count.size(), 0.0);
  std::vector<std::size_t> share_copied(share_count.size(), 0);
  l.member_begin.assign(layer_count + 1, 0);
  fault_in(l.member_store, sources.size(), teams);
  l.member_store.resize(sources.size());
#pragma omp parallel num_threads(teams)
  {
    const std::ptrdiff_t t = omp_get_thread_num(), count = omp_get_num_threads();
    const std::ptrdiff_t first = n * t / count, last = n * (t + 1) / count;
    // (Counted in the thread's own arrays, then stored: the shares' counts side by side shared cache
    // lines, which the two threads' increments passed back and forth: 2.2 ms on the fence at 6 m.)
    std::vector<std::size_t> counted(layer_count, 0), copied(layer_count, 0);
    std::vector<double> blur(layer_count, 0.0);
    double last_coc = std::numeric_limits<double>::quiet_NaN();
    std::uint16_t last_layer = 0;
    for (std::ptrdiff_t i = first; i < last; ++i) {
      const ScatterSource& s = sources[static_cast<std::size_t>(i)];
      if (!(s.coc_px == last_coc)) {
        last_layer = static_cast<std::uint16_t>(spacing.layer_at(s.coc_px));
        last_coc = s.coc_px;
      }
      layer_of[static_cast<std::size_t>(i)] = last_layer;
      ++counted[last_layer];
      blur[last_layer] = std::max(blur[last_layer], std::abs(s.coc_px));
      copied[last_layer] += s.copied ? 1 : 0;
    }
    std::copy(counted.begin(), counted.end(), share_count.begin() + t * static_cast<std::ptrdiff_t>(layer_count));
    std::copy(blur.begin(), blur.end(), share_blur.begin() + t * static_cast<std::ptrdiff_t>(layer_count));
    std::copy(copied.begin(), copied.end(), share_copied.begin() + t * static_cast<std::ptrdiff_t>(layer_count));
#pragma omp barrier
#pragma omp single
    {
      for (std::size_t k = 0; k < layer_count; ++k) {
        std::size_t total = 0;
        for (std::size_t u = 0; u < static_cast<std::size_t>(count); ++u) {
          total += share_count[u * layer_count + k];
          l.max_blur_px[k] = std::max(l.max_blur_px[k], share_blur[u * layer_count + k]);
          l.copied_members[k] += share_copied[u * layer_count + k];
        }
        l.member_begin[k + 1] = l.member_begin[k] + total;
      }
    }
    // (The single's end is a barrier.) This share's place in each list: after the shares before it.
    std::vector<std::size_t> at(layer_count);
    for (std::size_t k = 0; k < layer_count; ++k) {
      at[k] = l.member_begin[k];
      for (std::size_t u = 0; u < static_cast<std::size_t>(t); ++u) at[k] += share_count[u * layer_count + k];
    }
    for (std::ptrdiff_t i = first; i < last; ++i) l.member_store[at[layer_of[static_cast<std::size_t>(i)]]++] = static_cast<int>(i);
  }
  // Parts grouped by pixel, each pixel's in source order: counted, then placed from each pixel's end,
  // sources in reverse, without a copy of the pixels' positions (4 bytes a pixel of first-touched
  // memory): each pixel's end moves down to its start, part_begin[p + 1] to where p's parts begin.
  // Sources beyond the frame (the scatter's margin) are no pixel's parts: they only scatter. Where
  // the first sources are the pixels in raster order, each of those is its pixel's first part (on the
  // threads), and only the parts appended after them (a split pixel's second part) are looked at one
  // by one.
  auto inside = [&](const ScatterSource& s) { return s.x >= 0 && s.y >= 0 && s.x < width && s.y < height; };
  const std::size_t ordered = l.pixels_first ? pixel_count : 0;
  fault_in(l.part_begin, pixel_count + 1, teams);
  l.part_begin.resize(pixel_count + 1);
  const auto pixels = static_cast<std::ptrdiff_t>(pixel_count);
#pragma omp parallel for num_threads(teams) schedule(static)
  for (std::ptrdiff_t p = 0; p <= pixels; ++p) l.part_begin[static_cast<std::size_t>(p)] = p > 0 && ordered > 0 ? 1 : 0;
  for (std::size_t i = ordered; i < sources.size(); ++i) {
    const ScatterSource& s = sources[i];
    if (inside(s)) ++l.part_begin[static_cast<std::size_t>(s.y) * width + s.x + 1];
  }
  // part_begin[p + 1]: where pixel p's parts end.
  for (std::size_t p = 0; p < pixel_count; ++p) l.part_begin[p + 1] += l.part_begin[p];
  fault_in(l.parts, l.part_begin[pixel_count], teams);
  l.parts.resize(l.part_begin[pixel_count]);
  auto place = [&](std::size_t i) {
    const ScatterSource& s = sources[i];
    PixelPart& part = l.parts[--l.part_begin[static_cast<std::size_t>(s.y) * width + s.x + 1]];
    part.layer = static_cast<int>(layer_of[i]);
    part.visible = s.coverage - s.hidden;
    part.hidden = s.hidden;
  };
  for (std::size_t i = sources.size(); i-- > ordered;) {
    if (inside(sources[i])) place(i);
  }
#pragma omp parallel for num_threads(teams) schedule(static)
  for (std::ptrdiff_t p = 0; p < static_cast<std::ptrdiff_t>(ordered); ++p) place(static_cast<std::size_t>(p));
  // Now part_begin[p + 1] is where p's parts begin: each moves down one place, and the end is the total.
  std::copy(l.part_begin.begin() + 1, l.part_begin.end(), l.part_begin.begin());
  l.part_begin[pixel_count] = static_cast<std::uint32_t>(l.parts.size());
  l.nearer_blur_px.assign(static_cast<std::size_t>(l.count), 0.0);
  for (int k = l.count - 2; k >= 0; --k) {
    const auto u = static_cast<std::size_t>(k);
    l.nearer_blur_px[u] = std::max(l.nearer_blur_px[u + 1], l.max_blur_px[u + 1]);
  }
  return l;
}

LayerSpacing layer_spacing_of(const ScatterSources& sources, double spacing_px, int max_layers, int threads) {
  double coc_min = kInfinity, coc_max = -kInfinity;
  const auto n = static_cast<std::ptrdiff_t>(sources.size());
#pragma omp parallel for num_threads(threads) schedule(static) reduction(min : coc_min) reduction(max : coc_max)
  for (std::ptrdiff_t i = 0; i < n; ++i) {
    coc_min = std::min(coc_min, sources[static_cast<std::size_t>(i)].coc_px);
    coc_max = std::max(coc_max, sources[static_cast<std::size_t>(i)].coc_px);
  }
  if (sources.empty()) coc_min = coc_max = 0.0;
  return LayerSpacing::over(coc_min, coc_max, spacing_px, max_layers);
}

}  // namespace lensmith::render_detail
