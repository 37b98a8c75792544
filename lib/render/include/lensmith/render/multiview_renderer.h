// Multiview synthesis through a real lens (`lensmith bokeh --method multiview`, docs/multiview.md):
// Lee, Eisemann & Seidel, "Depth-of-field rendering with multiview synthesis", SIGGRAPH Asia 2009
// (seeds/003). The scene is a layered image (a deep image, or a flat picture with its depth as one
// layer); per output pixel, N lens rays are followed through it and their colours averaged.
//
// The paper's method, and what lensmith does differently:
//   - Layers (paper sec. 4.1, eq. 4): the samples are split into M layers evenly spaced in signed
//     circle of confusion, which is linear in inverse depth; each layer keeps, per pixel, what lies
//     in its depth interval (the paper keeps the nearest fragment; lensmith composites all of the
//     interval's samples front to back, so anti-aliased and transparent samples keep their alpha).
//   - Lens rays (eq. 2-3): a ray's pinhole-image position is linear in inverse depth, p(w) = p_inf +
//     w k. The paper's rays are a thin lens's; lensmith's come from the ray model (lens_ray_table.h):
//     LensCamera's backward trace for exact and poly, the forward map inverted for thin, paraxial
//     and seidel, so aberrations, cat's-eye vignetting, natural falloff and colour are the lens's.
//     Spectral: each lens sample carries one wavelength of the quadrature the scatter path uses,
//     and colour is integrated with the CIE observer, so grey stays grey.
//   - Height-field intersection (sec. 4.3): the paper refines by false position along each layer's
//     ray segment; lensmith walks the segment pixel by pixel (its length is at most the layer
//     spacing in pixels times the sample's pupil radius), hitting where the ray first passes behind
//     the layer's surface: exact on the pixel grid, no missed thin features. A hit of alpha < 1
//     leaves the rest of the ray's light to go on behind it.
//   - Early culling (sec. 4.3): per layer, 16 x 16 px tiles that hold no sample are skipped.
//   - Jittered sampling (sec. 4.5): a fixed set of 2N lens samples (Halton points in bases 3 and 5
//     over the pupil, wavelengths in strata), each pixel using N consecutive ones from its own
//     offset, so neighbouring pixels see different views and the noise is fine-grained, not banded;
//     deterministic.
//   - Approximate cone tracing on mipmapped layers (sec. 4.4): as the paper's (on by default; the
//     cone's diameter is lambda |CoC| with lambda = sqrt(pi / 4N), the side of one sample's share
//     of the pupil, where the paper measures the mean distance between its samples).
//   - Beyond the frame the layers continue as their edge pixels (the paper discards rays that leave
//     the frame, which makes every blurred pixel near the border noisier and biased). For an opaque
//     input, the share of a ray that falls through every layer (where the input does not know what
//     is behind) is left out of the pixel's average; for an input with transparent pixels the rest
//     of the light of a ray that passes everything is the output's transparency (alpha).
#pragma once

#include <cstddef>
#include <functional>
#include <string>

#include "lensmith/camera/aperture.h"
#include "lensmith/camera/ray_model.h"
#include "lensmith/render/deep_image.h"
#include "lensmith/render/image.h"

namespace lensmith {

struct MultiviewOptions {
  int threads = 0;               // 0 = all hardware threads
  int samples = 32;              // lens rays per output pixel (1..4096)
  int layers = 8;                // depth layers evenly spaced in signed circle of confusion (1..64)
  bool vignetting = true;        // as BokehOptions::vignetting
  bool spectral = true;          // false: every ray at the reference wavelength, RGB as given
  int spectral_samples = 16;     // wavelength nodes (3..64)
  int ray_grid_px = 16;          // lens rays computed every this many output pixels and interpolated (1..64)
  // Lee et al.'s approximate cone tracing (their sec. 4.4): a ray that hits a layer takes the mean
  // colour and coverage over its cone's window of the mipmapped layer, so few samples give smooth
  // bokeh instead of sparkles (docs/multiview.md); the cone shrinks as 1/sqrt(samples).
  bool cone_tracing = true;
  std::function<void(double)> progress;  // fraction done, from one thread at a time
  void validate() const;         // throws OptionsError naming the option
  std::string to_string() const;
};

struct MultiviewStatistics {
  int layers = 0;                 // non-empty layers
  double layer_spacing_px = 0.0;  // their spacing in signed circle of confusion (output px)
  double max_abs_coc_px = 0.0;    // largest |signed CoC| of the scene's depths
  std::size_t rays = 0;           // lens rays followed
  std::size_t stopped_rays = 0;   // stopped by the lens (vignetting, outside the aperture's shape)
  std::size_t lost_rays = 0;      // fell through every layer of an opaque input before being fully covered
  std::size_t outside_rays = 0;   // read the layers beyond the frame (continued as their edge pixels)
  std::size_t cells_visited = 0;  // pixel cells the rays walked through
  std::size_t direct_rays = 0;    // rays computed for a pixel instead of interpolated (beam edges)
  std::size_t chromatic_samples = 0;  // pupil samples followed in every wavelength band (the lens separates them)
  std::string to_string() const;
};

// The picture `model` takes of the layered scene `scene` (its framing: `model`'s camera). Output: 4
// channels, linear RGB premultiplied and alpha (1 where the input is opaque).
// Throws OptionsError for another size or bad options.
Image render_multiview(const DeepImage& scene, const RayModel& model, const Aperture& aperture,
                       const MultiviewOptions& options = {}, MultiviewStatistics* statistics = nullptr);

// A flat picture (3 channels) and its planar depth (metres) as a layered scene of one opaque sample
// per pixel, for render_multiview.
DeepImage deep_image_from_flat(const Image& image, const DepthMap& depth);

}  // namespace lensmith
