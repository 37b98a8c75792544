// Compositing of the depth layers (Porter & Duff, "Compositing digital images", SIGGRAPH 1984:
// "over" on premultiplied colour). Within a layer, overlapping footprints of one surface average
// (its coverage is at most 1); layers go back to front, each over the result so far. Where no
// layer covers fully at the end (the frame's borders, where part of the blur would come from
// outside it, and seams between layers), the rest is filled with the colour of the fully covered
// pixels around by push-pull, never with the pixel's own light: a flat image keeps its mean and a
// lone highlight is not amplified.
#pragma once

#include <vector>

#include "lensmith/render/image.h"

namespace lensmith::render_detail {

// result (premultiplied RGB + coverage, double, w x h x 4) = layer rows [row_begin, row_end) over result.
void composite_layer_over(const std::vector<float>& layer_rgba, std::vector<double>& result, int width, int row_begin,
                          int row_end);

// The output picture: the result with its uncovered remainder filled.
Image finish_composite(const std::vector<double>& result, int width, int height);

}  // namespace lensmith::render_detail
