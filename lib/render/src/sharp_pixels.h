// Sharp pixels that nothing of their own depth layer reaches. A pixel of the thin lens whose own
// footprint is a point (blur under kPointFootprintPx) lands at its own centre, where the splat's tent
// gives it all to its own pixel and none to its neighbours. If no other source of its depth layer
// (its hidden sources included) reaches the pixel, the layer there is that pixel alone, covering it
// fully: composited over the farther layers it hides them, and the nearer layers are composited over
// it. Such pixels are marked `copied`: they keep their place among the depth layers' pixels (the
// hidden-surface extension reads them as before), but are not planned or deposited; the renderer
// writes them to the result as they are at their layer's turn. The picture is the same
// (tests/render/bokeh_renderer_test.cpp); a frame with large sharp areas renders faster
// (docs/performance.md: the portrait focused on its wall at 5 m, 78 % copied; the fence focused on
// its wall at 6 m behind a blurred wire mesh, 84 %: 30 % while the blurs of other layers and the tent
// around points counted).
//
// Not from the papers: Lee, Eisemann & Seidel's layered scatter treats every pixel alike.
#pragma once

#include <cstddef>

#include "lensmith/camera/aperture.h"
#include "lensmith/camera/ray_model.h"
#include "layer_spacing.h"
#include "lensmith/render/bokeh_renderer.h"
#include "scatter_source.h"

namespace lensmith::render_detail {

// Whether the renderer may copy sharp pixels with this model, aperture and options: the thin lens,
// whose chief ray lands on the pixel's own centre, where its points are as bright as the input: an
// ideal thin lens, or the thin model of a real lens without vignetting (with it, the real lens's
// brightness across the frame: IlluminationTable), through an aperture that is not a picture (whose
// transmission scales a point's light); and options that ask for it (BokehOptions::copy_sharp_pixels).
bool copies_sharp_pixels(const RayModel& model, const Aperture& aperture, const BokehOptions& options);

// Marks `copied` the pixels of `sources` (one per pixel, row-major, width x height, then any appended
// parts: a split pixel's far part) that are sharp, whole (one part covering the pixel) and beyond
// the reach of every other source of their depth layer (`spacing`: the layers' bins): its blur
// radius plus the tent and a grid cell for merged sources, none beyond its own pixel for a point at
// its centre; a nearer pixel may have the layer's hidden sources under it, as blurred as the layer's
// most blurred source. Returns how many.
std::size_t mark_sharp_pixels(ScatterSources& sources, int width, int height, const LayerSpacing& spacing, int threads);

}  // namespace lensmith::render_detail
