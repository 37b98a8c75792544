// Depth layers of the scatter (Lee, Eisemann & Seidel, "Depth-of-field rendering with multiview
// synthesis", SIGGRAPH Asia 2009, sec. 4: layers evenly spaced in signed circle of confusion): each
// layer is scattered alone and composited front over back, so a blurred background never spreads
// over a sharp foreground while a blurred foreground spreads over what lies behind it.
#pragma once

#include <vector>

#include "scatter_source.h"

namespace lensmith::render_detail {

struct DepthLayers {
  double coc_min_px = 0.0;  // signed blur of layer 0's lower edge (the farthest sources)
  double spacing_px = 0.0;  // signed-blur step between layers
  int count = 0;            // layer 0 is the farthest, count - 1 the nearest
  std::vector<int> layer_of;                 // per source pixel (row-major): its layer
  std::vector<std::vector<int>> members;     // per layer: indices of its sources
  std::vector<double> max_blur_px;           // per layer: largest |signed blur| of its sources
  std::vector<double> nearer_blur_px;        // per layer: largest |signed blur| of every nearer layer

  int layer_at(double coc_px) const;
};

// Layers `spacing_px` apart (widened so there are at most `max_layers`), farthest first.
DepthLayers make_depth_layers(const std::vector<ScatterSource>& sources, double spacing_px, int max_layers);

}  // namespace lensmith::render_detail
