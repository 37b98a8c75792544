// Compositing of the depth layers (Porter & Duff, "Compositing digital images", SIGGRAPH 1984:
// "over" on premultiplied colour). Within a layer, overlapping footprints of one surface average
// (its coverage is at most 1); layers go back to front, each over the result so far. Where the
// layers do not cover fully at the end (the frame's borders, where part of the blur would come
// from beyond the frame), the covered part's colour stands for the whole pixel, as in a normalised
// gather; a pixel covered less than 5 % takes the colour of the fully covered pixels around it by
// push-pull, never its own amplified light. A flat image keeps its mean. Beyond the lens's image
// circle (image_circle.h) neither: what light arrived stays as it is, the rest is dark.
#pragma once

#include <array>
#include <vector>

#include "lensmith/core/huge_page_allocator.h"
#include "image_circle.h"
#include "push_pull.h"

#include "lensmith/render/image.h"

namespace lensmith::render_detail {

// result (premultiplied RGB + coverage, float, w x h x 4; each layer composited in double: the picture
// is float, and a frame's doubles were 8 MB of first-touched memory at 600 x 400) = a layer's rows
// [row_begin, row_end) over result. `layer_rows`: those rows of the layer alone (w x (row_end - row_begin)
// x 4 floats, premultiplied RGB + coverage). `hole_rows` (HiddenSurfaces::Stretch, else null): the
// same rows' coverage of the layer's hidden sources in channel 3; the layer's colour is renormalised over it.
void composite_layer_over(const float* layer_rows, const float* hole_rows, UnconstructedVector<float>& result, int width, int row_begin,
                          int row_end);

// Whether some pixel of the result is covered less than half (then the image circle is measured),
// on `threads` threads.
bool has_gaps(const UnconstructedVector<float>& result, int threads);

// The output picture: the result with its uncovered remainder filled, on `threads` threads, except
// beyond the lens's image circle, where the uncovered part stays dark and the covered part's light
// is not spread over the pixel; `gaps`: has_gaps(result); `fill` and `scratch` are working memory
// kept by the caller (their contents are overwritten).
Image finish_composite(const UnconstructedVector<float>& result, int width, int height, int threads, bool gaps,
                       LargeVector<PushPullCell<5>>& fill, PushPullScratch<5>& scratch, const ImageCircle& circle);

}  // namespace lensmith::render_detail
