#include "depth_layers.h"

#include <algorithm>
#include <cmath>

#include "lensmith/core/units.h"

namespace lensmith::render_detail {

int DepthLayers::layer_at(double coc_px) const {
  return std::clamp(static_cast<int>(std::floor((coc_px - coc_min_px) / spacing_px)), 0, count - 1);
}

DepthLayers make_depth_layers(const ScatterSources& sources, int width, double spacing_px, int max_layers) {
  DepthLayers l;
  double coc_min = kInfinity, coc_max = -kInfinity;
  for (const ScatterSource& s : sources) {
    coc_min = std::min(coc_min, s.coc_px);
    coc_max = std::max(coc_max, s.coc_px);
  }
  l.coc_min_px = coc_min;
  l.spacing_px = std::max(spacing_px, (coc_max - coc_min) / max_layers);
  l.count = std::max(1, static_cast<int>(std::floor((coc_max - coc_min) / l.spacing_px)) + 1);
  l.members.assign(static_cast<std::size_t>(l.count), {});
  l.max_blur_px.assign(static_cast<std::size_t>(l.count), 0.0);
  std::size_t pixel_count = 0;
  for (const ScatterSource& s : sources) pixel_count = std::max(pixel_count, static_cast<std::size_t>(s.y) * width + s.x + 1);
  l.pixels.assign(pixel_count, {});
  for (std::size_t i = 0; i < sources.size(); ++i) {
    const int k = std::min(l.count - 1, static_cast<int>(std::floor((sources[i].coc_px - coc_min) / l.spacing_px)));
    PixelLayers& p = l.pixels[static_cast<std::size_t>(sources[i].y) * width + sources[i].x];
    const std::size_t part = p.layer[0] < 0 ? 0 : 1;
    p.layer[part] = k;
    p.coverage[part] = sources[i].coverage;
    l.members[static_cast<std::size_t>(k)].push_back(static_cast<int>(i));
    l.max_blur_px[static_cast<std::size_t>(k)] = std::max(l.max_blur_px[static_cast<std::size_t>(k)], std::abs(sources[i].coc_px));
  }
  l.nearer_blur_px.assign(static_cast<std::size_t>(l.count), 0.0);
  for (int k = l.count - 2; k >= 0; --k) {
    const auto u = static_cast<std::size_t>(k);
    l.nearer_blur_px[u] = std::max(l.nearer_blur_px[u + 1], l.max_blur_px[u + 1]);
  }
  return l;
}

}  // namespace lensmith::render_detail
