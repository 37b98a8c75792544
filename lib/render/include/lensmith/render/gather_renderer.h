// Depth of field by scatter-as-you-gather at half resolution through a real lens (`lensmith bokeh
// --method gather`, docs/methods.md): the real-time family of J. Jimenez, "Next generation post
// processing in Call of Duty: Advanced Warfare", SIGGRAPH 2014 course "Advances in real-time
// rendering", as surveyed in Marsicano 2023 (seeds/004, sec. 5.0.1 and 5.1.1), and the hybrid of
// Y. Tan, N. Chua, C. Koh, A. Bhojan, "RTDOF: real-time depth of field rendering using hybrid
// ray tracing", 2022 (seeds/004, sec. 5.0.2-5.0.3), which traces rays where the picture cannot
// know what is behind a blurred foreground.
//
// The method (Jimenez), and what lensmith does differently:
//   - Tiles (Jimenez: 16-20 px tiles of the nearest depth and the largest CoC, dilated over their
//     3 x 3 neighbours): tiles of kTilePx px; each tile's largest footprint is spread to every tile
//     it reaches (a dilation by the blur itself, not by one tile: a 3 x 3 dilation cuts a
//     foreground's blur off beyond one tile), with the nearest inverse depth among them and the
//     range of the lens's centroid shifts (below).
//   - Footprints: Jimenez's samples have a circular CoC centred where they are. Beyond the paper,
//     each sample's footprint is the lens's: the ellipse of the covariance of where the ray model
//     puts its pupil's rays (a uniform disc of radius R has variance R^2 / 4; the ellipse is
//     x^T V^-1 x <= 4), centred on the rays' centroid (distortion, coma) and dimmed by the lens's
//     throughput (vignetting), from the table that `ewa` uses (psf_table.h); a cat's eye gathers as
//     an ellipse. A thin lens (or GatherOptions::lens_psf = false) is Jimenez's circle.
//   - Presort (per half-resolution sample): its weight as background rises from 0 to 1
//     (smoothstep) as its blur departs from the blur of the nearest surface of its tile by 0 to
//     kLayerBlurPx px (Jimenez compares depths against a scene-tuned scale; blur is the scale the
//     eye sees), times its alpha, the light per area: 1 / (the area of its footprint with the
//     spread's soft edge).
//   - Prefilter: 9 bilateral taps (weights fall with the difference in blur) over a square of half
//     side R / (2 rings) around each half-resolution sample (Jimenez: R / 6 for 3 rings; Tan et al.:
//     R / 8 for 4), R the tile's kernel radius, at least 1 px; the half-resolution sample's depth
//     is the farthest of its 2 x 2 pixels (Jimenez's). The Karis average (a luminance-weighted
//     prefilter against flicker) is not implemented: it dims highlights, and lensmith renders one
//     frame.
//   - Main pass: the centre and rings k = 1..K of 8k taps at radius k R / K (K = 3: Jimenez's 48
//     taps; K = 4: Tan et al.'s 80), point-sampled; a tap's sample counts where its footprint
//     covers the pixel (the spread: 1 inside, falling to 0 over one half-resolution pixel beyond
//     its edge), into a foreground or background sum by its presort weights. Background: the
//     weighted mean. Foreground: the weighted mean, over the background with the alpha of its
//     coverage (the taps' estimate of the light per area landing on the pixel: the sum over taps
//     of alpha times spread times the area a tap stands for). The taps are centred where the
//     pixel's light comes from: the pixel less the tile's mean centroid shift.
//   - Postfilter: the 3 x 3 median of each channel at half resolution (Jimenez's, against the
//     undersampled rings' noise).
//   - Composite: the half-resolution result, bilinearly upsampled, over the sharp picture (at full
//     resolution, moved by the lens's centroid shift at its pixel and dimmed by its throughput),
//     by the pixel's own blur (sharp below 1 px, blurred above 3 px) or the foreground's coverage,
//     whichever is larger.
//   - Known behaviour, kept as the family has it: a blurred foreground is the mean of the
//     foreground samples in the whole kernel (over-blurred and flattened where the tile's largest
//     blur exceeds its own); the picture does not know what a blurred foreground hides, so the
//     background behind it is the visible background's mean (or missing); fine texture at half
//     resolution loses detail where slightly blurred.
//
// Tan et al.'s hybrid (GatherOptions::trace, `--hidden trace` where the scene is known):
//   - Ray mask: a 5 x 5 Sobel of the half-resolution blur map (Tan et al.: of depth and normals,
//     after a Gaussian), x = |gradient| s, x_n = 1 - 1 / (x + 1) (their eq. 5.2-5.3), counted only
//     where a side of the edge is blurred (an edge between two sharp surfaces hides nothing the
//     lens shows). The temporally accumulated variance term (eq. 5.4) has no meaning for one
//     frame: lensmith adds instead 4 h (1 - h), h the blurred foreground's share of the weight a
//     pixel gathers (their hit ratio, estimated by the taps): 1 inside a blurred surface, in
//     between where it lies over another, where the picture's missing background shows.
//   - Rays: about m x_f per half-resolution pixel, m = GatherOptions::trace_rays, a quarter of them
//     through each of its output pixels (Tan et al. trace at half resolution; at 256 rays the
//     occluder scene's depth-edge band scored 25.85 dB this way against 25.32 dB at half
//     resolution, the fence 23.48 against 23.53), each an exact ray through the real lens (Tan et
//     al.: a thin lens) from a uniform point of the pixel and of the pupil (the caller's tracer).
//   - Composite: the traced mean (their near and far fields blended by the hit ratio h, eq. 5.5,
//     is that mean) over the post-process by x_f (Tan et al.'s zone and hit-ratio rules are
//     ambiguous, sec. 5.1.2). No temporal accumulation and no denoising of the traced colour: in
//     one frame, 16 rays per pixel (m = 64) cost the occluder scene 5 dB in the depth-edge band
//     in noise; 64 (m = 256, the default) about break even with the holes they fill.
//   - Not implemented (gather): colour (every footprint at the reference wavelength: no axial or
//     lateral colour), aperture pictures (masks), layered (deep) input, alpha.
#pragma once

#include <array>
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "lensmith/camera/aperture.h"
#include "lensmith/camera/ray_model.h"
#include "lensmith/render/image.h"

namespace lensmith {

// A request of the hybrid's ray tracer: `rays` rays through the square of the output
// [x_px, x_px + size_px) x [y_px, y_px + size_px) (output px, (0, 0) the top left corner), each
// through a uniform point of the square and of the lens's pupil. The tracer fills in the mean
// radiance of the rays that reach the scene (linear RGB) and how many did.
struct GatherTraceRequest {
  float x_px = 0.0f, y_px = 0.0f, size_px = 2.0f;
  int rays = 0;
  std::array<float, 3> rgb{};
  int reached = 0;
};
// Fills in the requests' results (called once, with every request).
using GatherTracer = std::function<void(std::vector<GatherTraceRequest>&)>;

struct GatherOptions {
  int threads = 0;             // 0 = all hardware threads
  bool vignetting = true;      // as BokehOptions::vignetting
  bool lens_psf = true;        // the lens's PSF ellipse; false: Jimenez's centred circle of the CoC
  int rings = 3;               // rings of taps: 3 (Jimenez 2014: 48 taps and the centre) or 4 (Tan et al. 2022: 80)
  bool median = true;          // Jimenez's 3 x 3 median postfilter
  double max_blur_px = 1000.0;  // nearer points are clamped to this blur diameter (output px)
  // Tan et al.'s hybrid: when set, rays are traced where the ray mask says, at most trace_rays per
  // half-resolution pixel (1..4096), a quarter of them through each of its output pixels.
  GatherTracer trace;
  int trace_rays = 256;
  std::function<void(double)> progress;  // fraction done, from one thread at a time
  void validate() const;  // throws OptionsError naming the option
  std::string to_string() const;
};

struct GatherStatistics {
  int half_width = 0, half_height = 0;  // the half-resolution buffers
  int tiles = 0;                   // tiles of the nearest depth and largest footprint
  int taps = 0;                    // taps per half-resolution pixel of the main pass (with the centre)
  double max_kernel_radius_px = 0.0;  // the largest tile kernel radius, output px
  std::size_t gathered_pixels = 0;  // half-resolution pixels the main pass gathered (the rest are sharp)
  std::size_t traced_pixels = 0;    // output pixels the hybrid traced
  std::size_t traced_rays = 0;      // rays traced
  std::size_t clamped_depths = 0;   // depths brought back to max_blur_px or in front of the lens
  std::string to_string() const;
};

// The picture `model` takes of the scene (image: linear Rec.709 RGB, 3 channels; depth: planar
// metres, same size). Output: linear RGB, the input's size. Throws OptionsError for mismatched
// sizes, bad options or a mask aperture.
Image render_gather(const Image& image, const DepthMap& depth, const RayModel& model, const Aperture& aperture,
                    const GatherOptions& options = {}, GatherStatistics* statistics = nullptr);

}  // namespace lensmith
