// The renderer's unit of work: a source pixel (or a part of one) sent through the lens as one
// footprint: where it is, the light it sends, how much of the pixel it covers and how far it is.
// Built from the all-in-focus image and its depth; nearer than 1 mm in front of the lens and
// blur beyond BokehOptions::max_blur_px are clamped (the count goes to the statistics).
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "lensmith/camera/aperture.h"
#include "lensmith/camera/camera.h"
#include "lensmith/camera/ray_model.h"
#include "lensmith/core/huge_page_allocator.h"
#include "layer_spacing.h"
#include "lensmith/render/bokeh_renderer.h"
#include "lensmith/render/deep_image.h"
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
  bool copied = false;              // a sharp pixel no footprint reaches: copied, not scattered (sharp_pixels.h)
  float hidden = 0.0f;              // the part of `coverage` that nearer parts of its pixel hide (layered input)
  double inverse_depth_per_mm = 0.0;
  double coc_px = 0.0;              // signed blur diameter at the reference wavelength (Camera::signed_coc_px)
};

// A frame's worth of sources (huge pages: docs/performance.md). Unconstructed by resize: every place
// that grows it so writes each new source whole on the threads (make_scatter_sources,
// split_mixed_pixels' far parts, append_hidden_sources); a resize that constructed them wrote the
// frame's 13 MB on one thread first.
using ScatterSources = UnconstructedVector<ScatterSource>;

// Where a source's light leaves from, output px (pixel (i, j) covers [i, i+1] x [j, j+1]).
inline PixelPoint source_centre(const ScatterSource& s) {
  return {s.x + 0.5 + static_cast<double>(s.offset_x_px), s.y + 0.5 + static_cast<double>(s.offset_y_px)};
}

// The margin beyond the frame where a method continues the picture as its edge pixels, px each
// side, so that the scene beyond the frame sends its light in: how far a point's light reaches from
// where it is (`reach_px`), plus how far the lens moves the frame's edges from the pinhole's
// (distortion, focus breathing: the chief rays at the edges' midpoints and corners, reference
// wavelength, focus distance), plus the 2 px tent; at most 256 px. Without the lens's shift, where
// the Canon 35 mm's distortion moves the edges 4.4 px inwards at 640 px, the last columns were
// covered only by inner points' blur (scatter: renormalised, their colour drifted to blue).
int frame_margin_px(const RayModel& model, double reach_px);

// How far inside the output frame the input's edge lands (output px, the largest over the edges'
// midpoints and corners, as frame_margin_px maps them; 0 when the lens moves no edge inwards): a tilt,
// a shift or distortion photographs beyond the input's frame there, and those pixels are made of the
// margin's copies of the input's edge (streaks): an input with overscan is needed.
double frame_edge_gap_px(const RayModel& model);

// Inverse depth (1/mm) clamped to 1 mm in front of the lens and to `max_blur_px`; `clamped` counts
// the changed ones.
// `coc_px`, when given, gets the signed blur (px) at the returned inverse depth (Camera::signed_coc_px),
// which the clamp computes anyway.
double clamp_inverse_depth(const Camera& camera, double inverse_depth_per_mm, double max_blur_px, std::size_t& clamped,
                           double* coc_px = nullptr);

// The one-surface-per-pixel methods' inputs checked: the picture (3 channels) and its depth both the
// camera's size, and an aperture they can draw (no mask). OptionsError naming `function` and
// `method` otherwise.
void check_flat_input(const Image& image, const DepthMap& depth, const Camera& camera, const Aperture& aperture,
                      const std::string& function, const std::string& method);

// Every pixel's inverse depth (1/mm, row-major) clamped as above, their range, the largest blur
// diameter among them (px) and how many were clamped: the one-surface-per-pixel methods' input.
struct ClampedDepths {
  std::vector<double> inverse;
  double w_min = 0.0, w_max = 0.0, max_blur_px = 0.0;
  std::size_t clamped = 0;
};
ClampedDepths clamped_inverse_depths(const Camera& camera, const DepthMap& depth, double max_blur_px, int threads);

// Sources of a layered picture and the layers they were merged for. Per pixel, front to back: a
// volume is cut into slabs of at most kVolumeSlabPx of blur each (alpha and colour by the OpenEXR
// rule for part of a uniform volume: alpha' = 1 - (1 - alpha)^f, colour scaled by alpha' / alpha,
// f the slab's share of the thickness in z). Each sample is a source at its own depth covering its
// own alpha (`hidden`: the part that nearer layers of its pixel hide), so behind an edge or a
// peeled foreground the renderer scatters what the file knows is there; samples of one pixel that
// share a layer are weighted by what that layer's nearer ones let through (front over back: within
// a layer footprints average; one source at a coverage-weighted depth gave a small light before a
// wall the wall's blur). A pixel the samples do not cover fully gets a black source infinitely far
// for the rest, in a layer of its own behind all others.
struct DeepSources {
  ScatterSources sources;
  LayerSpacing spacing;
  std::size_t samples = 0;      // samples read
  std::size_t volume_slabs = 0;  // slabs cut from volumetric samples
};
inline constexpr double kVolumeSlabPx = 1.0;
// A pixel whose samples leave less than this uncovered is opaque (float alphas of 1 - 2^-24 and
// products of many of them).
inline constexpr double kOpaqueRemainder = 1e-4;
inline constexpr int kMaxVolumeSlabs = 64;
DeepSources make_deep_sources(const DeepImage& deep, const Camera& camera, const BokehOptions& options, BokehStatistics& stats);

// One source per pixel, row-major, with its signed blur; statistics: source_pixels,
// clamped_depths, max_abs_coc_px.
ScatterSources make_scatter_sources(const Image& image, const DepthMap& depth, const Camera& camera,
                                                const BokehOptions& options, int threads, BokehStatistics& stats);

}  // namespace lensmith::render_detail
