// The spacing of the depth layers (depth_layers.h), apart so that sources can be merged per layer
// before the layers are made (a layered input's samples, scatter_source.h).
#pragma once

namespace lensmith::render_detail {

// Signed-blur layers evenly spaced: layer k holds blurs [coc_min_px + k spacing, + (k + 1) spacing),
// on a grid with a layer centred on blur 0 (coc_min_px at most the smallest blur).
struct LayerSpacing {
  double coc_min_px = 0.0;
  double spacing_px = 0.0;
  int count = 1;
  // `spacing_px` apart (widened so there are at most `max_layers`) over [coc_min, coc_max].
  static LayerSpacing over(double coc_min_px, double coc_max_px, double spacing_px, int max_layers);
  int layer_at(double coc_px) const;
};

}  // namespace lensmith::render_detail
