// The bokeh renderer: an all-in-focus image and its planar depth, photographed through a ray
// model (docs/bokeh.md).
//
// Every source pixel is a small patch of the scene at its depth. Its point-spread function comes
// from the ray model: the aperture's outline mapped to the sensor (one uniformly lit polygon for the
// thin and paraxial models, whose map is affine in the pupil) or a pupil mesh mapped triangle by
// triangle (seidel, exact: uneven light, folds and caustics included). Footprints are deposited
// exactly, at a cost that grows with their height, not their area (SplatBuffer), so a highlight
// becomes a solid, noise-free disc at any size; nothing is random, so output is deterministic.
//
// Visibility (Lee, Eisemann & Seidel 2009): pixels are split into depth layers spaced evenly in
// signed circle of confusion; each layer is scattered alone into colour and coverage, then layers
// are composited front over back. A blurred background never spreads over a sharp foreground, and
// a blurred foreground spreads over what lies behind it. What a single image cannot show (the
// background hidden behind a foreground edge) is estimated: with HiddenSurfaces::Extend each layer
// is continued under nearer pixels by push-pull interpolation of its own colours, as far as the
// nearer layers' blur reaches; with Stretch nothing is invented and the visible colours are
// renormalised over the gap.
//
// Colour: each pixel's linear Rec.709 RGB becomes a smooth spectrum (SpectralBasis); its light is
// carried at the wavelength nodes of a SpectralQuadrature, grouped where the lens's chromatic
// spread for that pixel is below a tolerance, and integrated back with the CIE 1931 observer, so
// grey stays grey wherever the lens does not separate colours.
#pragma once

#include <cstddef>
#include <functional>
#include <ostream>
#include <string>

#include "lensmith/camera/aperture.h"
#include "lensmith/camera/ray_model.h"
#include "lensmith/core/stage_times.h"
#include "lensmith/render/image.h"
#include "lensmith/render/splat_buffer.h"

namespace lensmith {

enum class HiddenSurfaces {
  Extend,   // continue each depth layer under nearer layers (push-pull), as far as their blur reaches
  Stretch,  // invent nothing: renormalise the visible layers' colours over what no layer covers
};
std::string_view to_string(HiddenSurfaces h);
HiddenSurfaces parse_hidden_surfaces(std::string_view text);  // "extend" | "stretch"; OptionsError otherwise

struct BokehOptions {
  int threads = 0;                       // 0 = all hardware threads
  SplatOptions splat;                    // sub-rows per pixel row of the scatter
  double layer_spacing_px = 2.0;         // signed circle-of-confusion step between depth layers (> 0)
  int max_layers = 64;                   // cap; the spacing grows when the blur range needs more (1..1024)
  HiddenSurfaces hidden = HiddenSurfaces::Extend;
  bool split_edge_pixels = true;         // split anti-aliased depth-edge pixels between their two surfaces
  // true: a point is as bright as the lens makes it (the rays' radiometric weights: cos^4-type
  // falloff, the growth of the real pupil off axis; clear apertures that clip a beam darken it).
  // false: every point as bright as on the axis, for those who want only the blur; a clipped beam
  // keeps its cat's-eye shape but not the loss of light.
  bool vignetting = true;
  bool spectral = true;                  // false: every ray at the reference wavelength, RGB as given
  int spectral_samples = 16;             // wavelength nodes of the quadrature (3..64)
  double chromatic_tolerance_px = 0.5;   // largest colour separation left unresolved within a pixel's bokeh
  double max_blur_px = 1000.0;           // nearer points are clamped to this blur diameter (output px)
  // true: along a row of pixels, a footprint that differs from its neighbour's by under 1/16 px
  // beyond the move of its chief ray draws that neighbour's mapped shape, at its own place and with
  // its own light (paraxial and Seidel models; docs/bokeh.md). false: every footprint mapped on its
  // own, slower, for checking.
  bool reuse_shapes = true;
  // true: the exact and poly models' rays of a rotationally symmetric lens through a circular
  // aperture interpolated from a table over field radius and inverse depth (nodes every 8 px of field
  // and 1 px of blur; docs/bokeh.md), not aimed and traced per pixel. false: every footprint's rays
  // from the model itself, much slower, for checking.
  bool interpolated_rays = true;
  // true: with interpolated rays, a footprint is drawn from a light image of its table node (the
  // node's mesh deposited once, filtered, and sampled turned to each pixel's azimuth; docs/bokeh.md,
  // "Light images"). false: every footprint's mesh triangles deposited, slower, for checking.
  bool light_images = true;
  // true: with the thin lens, a sharp pixel that no other pixel's blur reaches is copied to the
  // output as the scatter would draw it (exactly, in its own place and brightness), not scattered
  // (docs/bokeh.md, "Sharp pixels"). false: every pixel scattered, slower, for checking.
  bool copy_sharp_pixels = true;
  // Called with the fraction done (0..1) after each band of rows of each layer, from the rendering
  // threads one at a time (never concurrently): it must not assume the calling thread.
  std::function<void(double)> progress;
  void validate() const;                 // throws OptionsError naming the option
  std::string to_string() const;
};

struct BokehStatistics {
  int layers = 0;                   // non-empty depth layers
  double layer_spacing_px = 0.0;    // signed CoC spacing used
  std::size_t source_pixels = 0;    // input pixels scattered
  std::size_t hidden_sources = 0;   // hidden-surface sources added behind nearer pixels (hidden_surfaces.h)
  std::size_t split_edge_pixels = 0;     // anti-aliased edge pixels split into a near and a far part
  std::size_t redepthed_edge_pixels = 0; // edge pixels whose colour is one surface's, moved to its depth
  std::size_t copied_pixels = 0;    // sharp pixels copied, not scattered (BokehOptions::copy_sharp_pixels)
  std::size_t footprints = 0;       // (pixel, wavelength group) footprints deposited
  std::size_t triangles = 0;        // mesh triangles deposited (seidel, exact, masks)
  std::size_t light_images = 0;     // light images made (exact, poly: BokehOptions::light_images)
  std::size_t reused_shapes = 0;    // mesh footprints drawn from a neighbour's mapped shape (BokehOptions::reuse_shapes)
  std::size_t clamped_depths = 0;   // pixels brought back to max_blur_px or in front of the lens
  double max_abs_coc_px = 0.0;      // largest |signed CoC| among the source pixels
  std::size_t deep_samples = 0;     // samples of a layered (deep) input
  std::size_t volume_slabs = 0;     // slabs its volumetric samples were cut into
  std::size_t unaimed_rays = 0;     // rays the model could not aim (RayModel::unaimed_rays), drawn as stopped
  // How far inside the output frame the input's edge lands (output px; a tilt, shift or distortion moves
  // it): the pixels outside it are copies of the input's edge. Render the input with overscan.
  double edge_gap_px = 0.0;
  // Wall-clock time of each stage of the render (sources, edge split, layering, each layer's copy,
  // hidden surfaces, planning and deposit summed over the layers, finishing): `--timings`.
  StageTimes stages;
  std::string to_string() const;
  friend std::ostream& operator<<(std::ostream& os, const BokehStatistics& s) { return os << s.to_string(); }
};

// The picture `model` takes of the scene (image: linear Rec.709 RGB, 3 channels; depth: planar
// metres, same size, all valid). Output: linear RGB, the input's size and framing.
// Throws OptionsError for mismatched sizes or options.
Image render_bokeh(const Image& image, const DepthMap& depth, const RayModel& model, const Aperture& aperture,
                   const BokehOptions& options = {}, BokehStatistics* statistics = nullptr);

struct DeepImage;  // lensmith/render/deep_image.h

// The picture `model` takes of a layered scene (deep_image.h): every sample of a pixel scattered in
// its own depth layer, so what lies behind an edge or behind a whole foreground comes from the file
// where it has it; the hidden-surface extension fills only what it does not know. Output: linear
// RGB premultiplied over black where the samples leave a pixel uncovered (render the alpha with a
// DeepImage whose colours are its alphas). Throws OptionsError for another framing or bad options.
Image render_bokeh(const DeepImage& deep, const RayModel& model, const Aperture& aperture, const BokehOptions& options = {},
                   BokehStatistics* statistics = nullptr);

}  // namespace lensmith
