// Depth layers of the scatter (Lee, Eisemann & Seidel, "Depth-of-field rendering with multiview
// synthesis", SIGGRAPH Asia 2009, sec. 4: layers evenly spaced in signed circle of confusion): each
// layer is scattered alone and composited front over back, so a blurred background never spreads
// over a sharp foreground while a blurred foreground spreads over what lies behind it.
#pragma once

#include <algorithm>
#include <cstdint>
#include <span>
#include <vector>

#include "layer_spacing.h"
#include "scatter_source.h"

namespace lensmith::render_detail {

// One part of a pixel: a surface of one layer (a flat picture's pixel has one part, or two where an
// edge pixel is split; a layered input's pixel one per layer its samples fall in).
struct PixelPart {
  int layer = -1;
  float visible = 0.0f;  // share of the pixel this part covers as the pinhole sees it
  float hidden = 0.0f;   // share it covers behind nearer parts of the pixel (known only from layered input)
};

// The layers (LayerSpacing: layer 0 is the farthest, count - 1 the nearest) and their sources.
struct DepthLayers : LayerSpacing {
  // Per pixel (row-major) its parts: parts[part_begin[p] .. part_begin[p + 1]).
  UnconstructedVector<std::uint32_t> part_begin;
  UnconstructedVector<PixelPart> parts;
  // Per layer its sources' indices, in source order: member_store[member_begin[l] .. member_begin[l + 1]).
  // One block for all layers: a block per layer came from the heap in 4 KiB pages, which cost the
  // street scene's process about 3 ms of faults on one thread (docs/performance.md).
  UnconstructedVector<int> member_store;
  std::vector<std::size_t> member_begin;
  std::span<const int> members(int l) const {
    const auto u = static_cast<std::size_t>(l);
    return {member_store.data() + member_begin[u], member_begin[u + 1] - member_begin[u]};
  }
  std::vector<double> max_blur_px;           // per layer: largest |signed blur| of its sources
  std::vector<double> nearer_blur_px;        // per layer: largest |signed blur| of every nearer layer
  std::vector<std::size_t> copied_members;   // per layer: its members marked copied (sharp_pixels.h), not scattered
  bool pixels_first = false;  // the first width x height sources are the pixels in raster order (a flat picture's)

  // Whether pixel p has a part on layer l.
  bool in(std::size_t p, int l) const {
    for (std::uint32_t i = part_begin[p]; i < part_begin[p + 1]; ++i) {
      if (parts[i].layer == l) return true;
    }
    return false;
  }
  // The share of pixel p that parts nearer than layer l cover and where layer l is not known: what
  // they cover (at most 1) less what the pixel's own parts on layer l are known to cover behind them
  // (layered input). The hidden-surface extension of layer l fills this share. Parts known on
  // farther layers do not reduce it: the extension also closes the seams where one surface crosses
  // from layer to layer (a tilted floor), whose blurred edges do not add up to full coverage, and
  // a known wall behind the floor would show through them.
  float unknown_behind(std::size_t p, int l) const {
    float nearer = 0.0f, known = 0.0f;
    for (std::uint32_t i = part_begin[p]; i < part_begin[p + 1]; ++i) {
      if (parts[i].layer > l) nearer += parts[i].visible;
      else if (parts[i].layer == l) known += parts[i].hidden;
    }
    return std::max(0.0f, std::min(1.0f, nearer) - known);
  }
};

// The layers of `sources` (the parts of the pixels of an image `width` x `height`), farthest first,
// at `spacing`; `threads` find each source's layer.
// `pixels_first`: the first width x height sources are the pixels in raster order (a flat picture's).
DepthLayers make_depth_layers(const ScatterSources& sources, int width, int height, const LayerSpacing& spacing, int threads,
                              bool pixels_first);
// Layers `spacing_px` apart over the sources' own range of blur (widened so there are at most
// `max_layers`).
LayerSpacing layer_spacing_of(const ScatterSources& sources, double spacing_px, int max_layers, int threads);

}  // namespace lensmith::render_detail
