// Depth of field by EWA surface splatting through a real lens (`lensmith bokeh --method ewa`,
// docs/methods.md): J. Křivánek, J. Žára, K. Bouatouch, "Fast depth of field rendering with surface
// splatting", Computer Graphics International 2003 (seeds/001). Every pixel of the all-in-focus
// picture is a surfel; its screen-space Gaussian is widened by the blur of its depth, coarser
// surfels of a level-of-detail hierarchy stand in for fine ones where the blur is large (so the cost
// stays nearly flat as blur grows), and an A-buffer keeps the fragments of different surfaces apart
// and composites them front to back.
//
// The paper's method, and what lensmith does differently:
//   - The blur kernel (sec. 3.2): the paper replaces the circle of confusion's uniform disc of
//     radius R by the Gaussian closest to it in the L2 norm. The seed's text of that result is
//     garbled ("lution ln yielding variance matrix vi ln ln"); minimising the L2 distance between
//     the disc 1/(pi R^2) and the Gaussian exp(-r^2 / 2a) / (2 pi a) gives exp(-R^2 / 2a) = 1/4,
//     a = R^2 / (2 ln 4) = 0.361 R^2 (the disc's own second moment is R^2 / 4; the L2-best Gaussian
//     is wider). EwaOptions::lens_psf = false uses exactly that, centred on the pinhole position.
//     By default, beyond the paper, each surfel's Gaussian is the lens's: the covariance of where
//     the ray model puts the rays of its pupil (a table over the frame and depth, RayModel::map at
//     the reference wavelength), scaled by the same 2 / ln 4 (so a uniform disc gets the paper's
//     Gaussian), centred on the rays' centroid (distortion, coma's shift) and dimmed by the share of
//     the light the lens lets through (vignetting): a cat's eye becomes an elongated Gaussian.
//   - Surfels and their reconstruction kernel (sec. 2): the paper's points are irregular samples
//     of a surface, each with a reconstruction kernel plus the screen's anti-aliasing prefilter
//     (variance I). Pixels are a regular grid already at the output's resolution: a surfel's kernel
//     is its blur plus a small Gaussian of sigma 0.3 px, and each splat is normalised over
//     the pixels it covers (the paper's "post-normalisation" replaced by an exact per-splat one), so
//     an in-focus picture comes back nearly unchanged.
//   - Level of detail (sec. 4): the paper's surfel tree is built over an object's surface; here
//     level L is the picture filtered by binomial [1 3 3 1] / 8 filters and taken every 2^L px (a
//     Gaussian pyramid; a 2 x 2 box let fine periodic texture alias into slow beats), a node on one
//     surface where its children are (signed blurs within kSurfaceBlurTolerance). A node is drawn
//     where its blur's smaller principal variance can absorb the level's own filter (variance
//     (4^L - 1) / 4) and still leave a Gaussian of sigma 0.6 x 2^L to rebuild the grid without
//     ripple: its Gaussian is the blur less the level's filter, as the paper subtracts Q_l.
//   - Coverage and magnification: each splat's weights sum to the output area its pixels map to
//     (the Jacobian of the rays' centroids), so that an opaque surface covers each pixel once
//     whether the lens magnifies or compresses the pinhole's picture (focus breathing, distortion).
//   - A-buffer (sec. 5): fragments of one pixel whose signed blurs differ by less than
//     max(1 px, 20 %) are one surface and merge (the paper's depth threshold, in blur: what the
//     eye can tell apart); at most kFragments per pixel (then the nearest in blur merges). Each
//     fragment's coverage is its summed weight (at most 1), composited front to back; a pixel
//     covered less than fully (the frame's edge, a blurred foreground whose background the picture
//     hides) is renormalised by its coverage.
//   - Not implemented: colour (every surfel at the reference wavelength: no axial or lateral
//     colour), aperture pictures (masks), layered (deep) input, the hidden background (what the
//     picture does not show stays missing, as in the paper).
#pragma once

#include <cstddef>
#include <functional>
#include <string>

#include "lensmith/camera/aperture.h"
#include "lensmith/camera/ray_model.h"
#include "lensmith/render/image.h"

namespace lensmith {

struct EwaOptions {
  int threads = 0;              // 0 = all hardware threads
  bool vignetting = true;       // as BokehOptions::vignetting
  bool lens_psf = true;         // the lens's PSF covariance; false: the paper's circular Gaussian of the CoC
  bool level_of_detail = true;  // coarser surfels where the blur is large (false: every pixel a splat)
  double max_blur_px = 1000.0;  // nearer points are clamped to this blur diameter (output px)
  std::function<void(double)> progress;  // fraction done, from one thread at a time
  void validate() const;  // throws OptionsError naming the option
  std::string to_string() const;
};

struct EwaStatistics {
  std::size_t splats = 0;            // splats drawn (surfels after the level of detail)
  std::size_t splats_per_level[8]{};  // of those, per level (0: pixels, L: 2^L x 2^L blocks)
  std::size_t pixel_writes = 0;      // (splat, pixel) weights added
  std::size_t overflow_merges = 0;   // contributions merged into another surface for want of a fragment
  std::size_t unfilled_pixels = 0;   // output pixels no splat reached (they keep their input colour)
  std::size_t clamped_depths = 0;    // depths brought back to max_blur_px or in front of the lens
  std::string to_string() const;
};

// The picture `model` takes of the scene (image: linear Rec.709 RGB, 3 channels; depth: planar
// metres, same size). Output: linear RGB, the input's size. Throws OptionsError for mismatched
// sizes, bad options or a mask aperture.
Image render_ewa(const Image& image, const DepthMap& depth, const RayModel& model, const Aperture& aperture,
                 const EwaOptions& options = {}, EwaStatistics* statistics = nullptr);

}  // namespace lensmith
