// Light-field synthesis through a real lens (`lensmith bokeh --method lightfield`, docs/methods.md):
// X. Yu, R. Wang, J. Yu, "Real-time depth of field rendering via dynamic light field generation and
// filtering", Pacific Graphics 2010 (seeds/002). The all-in-focus picture is warped to N views, one
// per point of the lens's pupil, each view keeping the nearest surface at every pixel, and the views
// are averaged: an accumulation buffer whose views are not rendered but warped from one.
//
// The paper's method, and what lensmith does differently:
//   - Views (sec. 3.1, eq. 3-4): the paper's cameras sit on the lens plane and a point moves by its
//     disparity times the camera's offset, a thin lens. lensmith's view for pupil point u maps every
//     source pixel through the ray model (RayModel::map at u), so each view carries the lens's
//     aberrations, distortion and vignetting; the sensor is where the views are compared, so no
//     focal-disparity re-indexing (eq. 7) is needed.
//   - Colour (beyond the paper, which has one wavelength): with LightfieldOptions::spectral every
//     view is warped three times, once per RGB channel at that channel's centroid wavelength in
//     lensmith's spectral quadrature, each warp carrying its own channel, so the lens's axial and
//     lateral colour come with the views (three times the time; --no-spectral: one warp at the
//     reference wavelength carrying RGB as it is). Three wavelengths, not a spectrum: the scatter
//     method integrates 16; a channel's colour fringe is its centroid's. (Views cycling through
//     wavelength bands, tried first, put each highlight's bokeh down as dots of different colours:
//     with 36 views, one view per band point is colour noise.)
//   - Visibility (sec. 3.2): as the paper's atomic min on disparity, nearest wins per pixel and view.
//   - Holes (sec. 3.2): as the paper, a warped pixel's support is grown to the 2 x 2 pixels whose
//     centres surround where it lands, so rounding leaves no cracks; but only over pixels no source
//     lands in (nearest wins among those), so the growth fills cracks without moving a sloping
//     surface's colours or dilating a foreground. Pixels no source reaches in a view
//     (disocclusions, the frame's edge) are left out of that pixel's average, as the paper
//     discards invalid rays. A pixel no view reaches keeps its input colour (counted).
//   - Beyond the frame the picture continues as its edge pixels (as the multiview method's layers),
//     over a margin of half the largest blur and the lens's shift of the frame's edges (distortion):
//     views that move the picture inwards would otherwise
//     leave the frame's edge pixels holes.
//   - Sampling (sec. 4.2): Halton points over the pupil (bases 2 and 3: radius^2 and angle, uniform
//     in area), as the paper's jittered camera positions; a bladed iris weights each point by its
//     share of the area. Masks (pictures of an aperture) are not implemented here.
//   - Filtering (sec. 4.2, eq. 8): the paper reads each ray's colour from a Gaussian mipmap at a
//     level set by the ray's blur; its eq. 8 as printed divides the aperture by N, which for N = 36
//     views is no longer the spacing of the views. lensmith reads the mean over a window of
//     lambda |CoC| px, lambda = sqrt(pi / 4N) (the side of one view's share of the pupil, as the
//     multiview method's cone tracing), from a box mipmap.
//   - Radiometry (sec. 4.1, eq. 5-6): the paper weights each ray by cos^4; lensmith by the ray
//     model's radiometric weight (natural vignetting), and a ray the lens stops adds darkness.
#pragma once

#include <cstddef>
#include <functional>
#include <string>

#include "lensmith/camera/aperture.h"
#include "lensmith/camera/ray_model.h"
#include "lensmith/render/image.h"

namespace lensmith {

struct LightfieldOptions {
  int threads = 0;            // 0 = all hardware threads
  int views = 36;             // lens-plane views (1..1024; the paper's default 36)
  bool vignetting = true;     // as BokehOptions::vignetting
  bool mip_filter = true;     // Yu et al.'s pre-filter against undersampling (sec. 4.2)
  bool spectral = true;       // each RGB channel warped at its own wavelength (3x the time); false: one warp at the reference
  double max_blur_px = 1000.0;  // nearer points are clamped to this blur diameter (output px)
  std::function<void(double)> progress;  // fraction done, from one thread at a time
  void validate() const;  // throws OptionsError naming the option
  std::string to_string() const;
};

struct LightfieldStatistics {
  int views = 0;                 // views warped
  std::size_t warps = 0;         // (source pixel, view) pairs mapped
  std::size_t stopped = 0;       // of those, stopped by the lens
  std::size_t holes = 0;         // (output pixel, view) pairs no source reached
  std::size_t unfilled_pixels = 0;  // output pixels no view reached (they keep their input colour)
  std::size_t clamped_depths = 0;   // depths brought back to max_blur_px or in front of the lens
  std::string to_string() const;
};

// The picture `model` takes of the scene (image: linear Rec.709 RGB, 3 channels; depth: planar
// metres, same size). Output: linear RGB, the input's size. Throws OptionsError for mismatched
// sizes, bad options or a mask aperture.
Image render_lightfield(const Image& image, const DepthMap& depth, const RayModel& model, const Aperture& aperture,
                        const LightfieldOptions& options = {}, LightfieldStatistics* statistics = nullptr);

}  // namespace lensmith
