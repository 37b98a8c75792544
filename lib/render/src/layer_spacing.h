// The spacing of the depth layers (depth_layers.h), apart so that sources can be merged per layer
// before the layers are made (a layered input's samples, scatter_source.h).
#pragma once

namespace lensmith::render_detail {

// Signed-blur layers evenly spaced: layer k holds blurs [coc_min_px + k spacing, + (k + 1) spacing),
// on a grid with a layer centred on blur 0 (coc_min_px at most the smallest blur).
// The layer centred on blur 0, where the range holds it, is cut in three at +-kFocusCut spacings
// (focus_split): what is sharp gets a layer of its own, apart from what is blurred by more than an
// eighth of a spacing (0.25 px at the default 2 px).
struct LayerSpacing {
  static constexpr double kFocusCut = 0.125;
  double coc_min_px = 0.0;
  double spacing_px = 0.0;
  int count = 1;             // layers in all (grid bins, plus 2 where the focus bin is cut)
  bool focus_split = false;
  // `spacing_px` apart (widened so there are at most `max_layers`) over [coc_min, coc_max].
  static LayerSpacing over(double coc_min_px, double coc_max_px, double spacing_px, int max_layers);
  int layer_at(double coc_px) const;
};

}  // namespace lensmith::render_detail
