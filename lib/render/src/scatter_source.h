// The renderer's unit of work: a source pixel (or a part of one) sent through the lens as one
// footprint: where it is, the light it sends, how much of the pixel it covers and how far it is.
// Built from the all-in-focus image and its depth; nearer than 1 mm in front of the lens and
// blur beyond BokehOptions::max_blur_px are clamped (the count goes to the statistics).
#pragma once

#include <array>
#include <cstddef>
#include <vector>

#include "lensmith/camera/camera.h"
#include "lensmith/core/huge_page_allocator.h"
#include "lensmith/render/bokeh_renderer.h"
#include "lensmith/render/image.h"

namespace lensmith::render_detail {

struct ScatterSource {
  int x = 0;  // source pixel
  int y = 0;
  // Where its light leaves from, px from the pixel's centre: 0 for a pixel; the centre of the light
  // of the sources a merged one stands for (source_merging).
  float offset_x_px = 0.0f;
  float offset_y_px = 0.0f;
  std::array<float, 3> rgb{};       // linear radiance it sends (premultiplied by coverage)
  float coverage = 1.0f;            // fraction of the pixel's area this part stands for (0..1]
  bool coverage_only = false;       // a hidden source of HiddenSurfaces::Stretch: coverage, no light
  double inverse_depth_per_mm = 0.0;
  double coc_px = 0.0;              // signed blur diameter at the reference wavelength (Camera::signed_coc_px)
};

// A frame's worth of sources (huge pages: docs/performance.md).
using ScatterSources = LargeVector<ScatterSource>;

// Where a source's light leaves from, output px (pixel (i, j) covers [i, i+1] x [j, j+1]).
inline PixelPoint source_centre(const ScatterSource& s) {
  return {s.x + 0.5 + static_cast<double>(s.offset_x_px), s.y + 0.5 + static_cast<double>(s.offset_y_px)};
}

// Inverse depth (1/mm) clamped to 1 mm in front of the lens and to `max_blur_px`; `clamped` counts
// the changed ones.
double clamp_inverse_depth(const Camera& camera, double inverse_depth_per_mm, double max_blur_px, std::size_t& clamped);

// One source per pixel, row-major, with its signed blur; statistics: source_pixels,
// clamped_depths, max_abs_coc_px.
ScatterSources make_scatter_sources(const Image& image, const DepthMap& depth, const Camera& camera,
                                                const BokehOptions& options, int threads, BokehStatistics& stats);

}  // namespace lensmith::render_detail
