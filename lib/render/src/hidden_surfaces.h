// What a single image cannot show: the part of a depth layer hidden behind nearer pixels. A real
// lens sees some of it: around a blurred foreground (which turns partly transparent at its edge),
// and around a sharp one too, because a blurred background point spreads its light past the sharp
// silhouette in front of it. So each layer gets hidden sources under the nearer pixels within
// reach of its own pixels: half the blur of the layer itself and of every nearer layer, plus the
// 2 px tent. Their coverage is the part of the pixel the nearer layers take and no sample of a
// layered input is known to fill (DepthLayers::unknown_behind); their inverse depth is
// interpolated from the layer's own pixels by push-pull (Gortler et al., "The Lumigraph", 1996).
//
// HiddenSurfaces::Extend also interpolates their colour (in x / (1 + x), so that a few HDR
// highlights do not flood it): a plausible guess, not knowledge. HiddenSurfaces::Stretch invents no
// colour: its hidden sources only add coverage, and the layer's own colours are renormalised over it.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "depth_layers.h"
#include "push_pull.h"
#include "scatter_source.h"

namespace lensmith::render_detail {

// Frame-sized working memory of append_hidden_sources, kept from layer to layer: fresh memory is faulted
// in page by page, which cost more than the work itself (docs/performance.md).
struct HiddenScratch {
  UnconstructedVector<int> row_distance;  // (written whole for each layer)
  UnconstructedVector<std::uint8_t> within;
  std::vector<std::size_t> targets;
  std::vector<std::size_t> target_cells;  // the targets' cells in the push-pull's window
  std::vector<std::vector<std::size_t>> block_targets;  // each thread's block of rows' targets, before they join `targets`
  std::vector<PushPullCell<5>> own;         // the targets' colour (tone-mapped), inverse depth, weight
  std::vector<PushPullCell<2>> own_shares;  // the targets' visible share of the layer, weight
  PushPullScratch<5> push_pull;
  PushPullScratch<2> push_pull_shares;
};

// Appends to `out` the hidden sources of `layer`, under the nearer pixels within `reach_px` (a
// square) of its own pixels of an image `width` x `height`; coverage-only for
// HiddenSurfaces::Stretch. Returns how many it appended.
std::size_t append_hidden_sources(const ScatterSources& sources, const DepthLayers& layers, int layer, int width, int height,
                                  double reach_px, HiddenSurfaces mode, const Camera& camera, int threads,
                                  HiddenScratch& scratch, ScatterSources& out);

}  // namespace lensmith::render_detail
