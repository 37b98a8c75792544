// Depth layers of the scatter (Lee, Eisemann & Seidel, "Depth-of-field rendering with multiview
// synthesis", SIGGRAPH Asia 2009, sec. 4: layers evenly spaced in signed circle of confusion): each
// layer is scattered alone and composited front over back, so a blurred background never spreads
// over a sharp foreground while a blurred foreground spreads over what lies behind it.
#pragma once

#include <algorithm>
#include <array>
#include <vector>

#include "scatter_source.h"

namespace lensmith::render_detail {

// The layers of a pixel's parts (one, or two for a split edge pixel) and their coverage.
struct PixelLayers {
  std::array<int, 2> layer{-1, -1};
  std::array<float, 2> coverage{0.0f, 0.0f};
  bool in(int l) const { return layer[0] == l || layer[1] == l; }
  // Fraction of the pixel that parts nearer than layer l cover (hidden from l), at most 1.
  float nearer_than(int l) const {
    return std::min(1.0f, (layer[0] > l ? coverage[0] : 0.0f) + (layer[1] > l ? coverage[1] : 0.0f));
  }
  // Fraction of the pixel on layer l.
  float on(int l) const { return (layer[0] == l ? coverage[0] : 0.0f) + (layer[1] == l ? coverage[1] : 0.0f); }
};

struct DepthLayers {
  double coc_min_px = 0.0;  // signed blur of layer 0's lower edge (the farthest sources)
  double spacing_px = 0.0;  // signed-blur step between layers
  int count = 0;            // layer 0 is the farthest, count - 1 the nearest
  LargeVector<PixelLayers> pixels;         // per pixel (row-major)
  std::vector<LargeVector<int>> members;   // per layer: indices of its sources
  std::vector<double> max_blur_px;           // per layer: largest |signed blur| of its sources
  std::vector<double> nearer_blur_px;        // per layer: largest |signed blur| of every nearer layer

  int layer_at(double coc_px) const;
};

// Layers `spacing_px` apart (widened so there are at most `max_layers`), farthest first. `sources`
// are the parts of the pixels of an image `width` wide.
DepthLayers make_depth_layers(const ScatterSources& sources, int width, double spacing_px, int max_layers);

}  // namespace lensmith::render_detail
