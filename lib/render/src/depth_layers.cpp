#include "depth_layers.h"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>

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
  // Each source's layer, once (threads; 2 bytes: BokehOptions::max_layers is at most 1024, and the
  // focus split adds 2); the passes below are serial, as each places in source order.
  if (l.count < 1 || l.count > std::numeric_limits<std::uint16_t>::max()) {
    throw OptionsError("depth layers: " + std::to_string(l.count) + " layers; 1 to 65535 are possible");
  }
  const auto n = static_cast<std::ptrdiff_t>(sources.size());
  LargeVector<std::uint16_t> layer_of(sources.size());
  // Each thread a contiguous share; a source blurred as the one before it (most of a row of a wall)
  // takes its layer over.
#pragma omp parallel num_threads(threads)
  {
    const std::ptrdiff_t t = omp_get_thread_num(), count = omp_get_num_threads();
    double last_coc = std::numeric_limits<double>::quiet_NaN();
    std::uint16_t last_layer = 0;
    for (std::ptrdiff_t i = n * t / count; i < n * (t + 1) / count; ++i) {
      const double coc = sources[static_cast<std::size_t>(i)].coc_px;
      if (!(coc == last_coc)) {
        last_layer = static_cast<std::uint16_t>(spacing.layer_at(coc));
        last_coc = coc;
      }
      layer_of[static_cast<std::size_t>(i)] = last_layer;
    }
  }
  // Parts grouped by pixel: counted, then placed (a split pixel's second part comes at the end of
  // the sources). Sources beyond the frame (the scatter's margin) are no pixel's parts: they only
  // scatter. The layers' members are placed at their final positions: grown by doubling, the lists
  // were copied to fresh memory again and again (half a thousand page faults on a 600 x 400 frame).
  l.part_begin.assign(pixel_count + 1, 0);
  auto inside = [&](const ScatterSource& s) { return s.x >= 0 && s.y >= 0 && s.x < width && s.y < height; };
  std::vector<std::size_t> member_count(static_cast<std::size_t>(l.count), 0);
  for (std::size_t i = 0; i < sources.size(); ++i) {
    const ScatterSource& s = sources[i];
    if (inside(s)) ++l.part_begin[static_cast<std::size_t>(s.y) * width + s.x + 1];
    ++member_count[layer_of[i]];
  }
  // part_begin[p + 1]: where pixel p's parts end.
  for (std::size_t p = 0; p < pixel_count; ++p) l.part_begin[p + 1] += l.part_begin[p];
  l.parts.resize(l.part_begin[pixel_count]);
  l.member_begin.assign(member_count.size() + 1, 0);
  for (std::size_t k = 0; k < member_count.size(); ++k) l.member_begin[k + 1] = l.member_begin[k] + member_count[k];
  l.member_store.resize(sources.size());
  // Placed from each list's end, sources in reverse (so each list is in source order), without a
  // copy of the pixels' or the layers' positions (4 bytes a pixel of first-touched memory): each
  // pixel's end moves down to its start, part_begin[p + 1] to where p's parts begin.
  std::vector<std::size_t> member_end(l.member_begin.begin() + 1, l.member_begin.end());
  for (std::size_t i = sources.size(); i-- > 0;) {
    const ScatterSource& s = sources[i];
    const std::size_t k = layer_of[i];
    if (inside(s)) {
      PixelPart& part = l.parts[--l.part_begin[static_cast<std::size_t>(s.y) * width + s.x + 1]];
      part.layer = static_cast<int>(k);
      part.visible = s.coverage - s.hidden;
      part.hidden = s.hidden;
    }
    l.member_store[--member_end[k]] = static_cast<int>(i);
    l.max_blur_px[k] = std::max(l.max_blur_px[k], std::abs(s.coc_px));
    l.copied_members[k] += s.copied ? 1 : 0;
  }
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
