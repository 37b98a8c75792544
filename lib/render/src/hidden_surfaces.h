// What a single image cannot show: the part of a depth layer hidden behind nearer pixels, which a
// real lens sees around blurred edges. HiddenSurfaces::Extend continues the layer under the nearer
// pixels within reach of it, with colours and inverse depths interpolated from the layer's own
// pixels by push-pull (Gortler et al. 1996), in x / (1 + x) so that a few HDR highlights do not
// flood the invented surface: a plausible guess, not knowledge.
#pragma once

#include <vector>

#include "depth_layers.h"
#include "lensmith/render/image.h"
#include "scatter_source.h"

namespace lensmith::render_detail {

// Sources continuing `layer` under the nearer pixels within `reach_px` (a square) of its own pixels.
std::vector<ScatterSource> extend_layer(const Image& image, const DepthMap& depth, const Camera& camera,
                                        const DepthLayers& layers, int layer, double reach_px, int threads);

}  // namespace lensmith::render_detail
