// Anti-aliased depth edges. A pixel on a silhouette mixes the colours of two surfaces while its
// depth names one of them (Cycles writes the depth of the pixel's first sample), or neither (a
// filtered depth between them). Scattered whole, its near surface's colour would spread with the
// far surface's blur (a halo of the subject around a sharp subject) or the reverse. Like the
// edge-aware defocus of compositors, which decompose edge pixels as a matte (Porter & Duff 1984:
// c = alpha c_near + (1 - alpha) c_far), the pixel is split into a near part of coverage alpha and a
// far part of coverage 1 - alpha, each at its surface's depth.
//
// alpha comes from colour where the two surfaces' colours differ clearly: the projection of the
// pixel's colour on the segment between the colours of a near and a far neighbour (3 x 3), the pair
// whose segment passes nearest the pixel's colour (a textured or highlighted side has no one colour);
// where they do not, from depth (a filtered depth between the surfaces gives its position between
// them; a depth equal to one surface's gives 0 or 1). A pixel whose colour is wholly one surface's
// takes that surface's depth. Pixels with no neighbour of the other kind (1-px features) are kept.
#pragma once

#include <vector>

#include "lensmith/camera/camera.h"
#include "lensmith/render/bokeh_renderer.h"
#include "scatter_source.h"

namespace lensmith::render_detail {

// `sources` holds one source per pixel (row-major, width x height); split pixels keep their near
// part at their index and get their far part appended. Statistics: split_edge_pixels,
// redepthed_edge_pixels.
void split_mixed_pixels(ScatterSources& sources, int width, int height, const Camera& camera, int threads,
                        BokehStatistics& stats);

}  // namespace lensmith::render_detail
