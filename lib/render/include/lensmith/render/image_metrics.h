// Image comparison metrics for checking the defocus renderer against a reference: PSNR and SSIM
// (Wang, Bovik, Sheikh & Simoncelli, "Image quality assessment: from error visibility to structural
// similarity", IEEE Trans. Image Processing 13(4):600-612, 2004) on Reinhard tone-mapped values,
// over the whole frame and over a band around depth discontinuities, where defocus renderers differ.
#pragma once

#include <cstddef>
#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

#include "lensmith/render/image.h"

namespace lensmith {

// Reinhard's global operator x / (1 + x) applied to every channel, so that HDR highlights (radiance
// 20-200) count at most 1 and do not dominate a comparison. Negative values (non-physical, e.g.
// filter ringing) map to 0, +infinity to 1; NaN stays NaN so that it shows in the metrics.
Image tone_map_reinhard(const Image& image);

// Peak signal-to-noise ratio in dB of the tone-mapped images, peak 1: 10 log10(1 / MSE), the MSE
// taken over every channel of the selected pixels. mask (optional) holds one value per pixel, row
// major like Image; nonzero (1) includes the pixel. Returns +infinity for identical images.
// Throws OptionsError when sizes or channel counts differ, the mask has the wrong length, or it
// selects no pixel.
double psnr(const Image& a, const Image& b, const std::vector<std::uint8_t>* mask = nullptr);

// Mean SSIM of the tone-mapped images (Wang et al. 2004, eq. 13 with C1 = (K1 L)^2, C2 = (K2 L)^2,
// K1 = 0.01, K2 = 0.03, L = 1), local statistics under a normalised Gaussian window of sigma 1.5 px
// truncated to 11 x 11. As in the paper's reference code (and scikit-image), the SSIM map exists
// only where the whole window lies inside the image, i.e. 5 px away from every border; it is
// computed per channel and the per-channel means over the selected pixels are averaged. mask as for
// psnr(). Returns 1 for identical images. Throws OptionsError when sizes or channel counts differ,
// the image is smaller than 11 x 11, or the mask has the wrong length or selects no pixel at least
// 5 px from the border.
double ssim(const Image& a, const Image& b, const std::vector<std::uint8_t>* mask = nullptr);

// The band around depth discontinuities, one value per pixel (1 = in the band), row major.
// Definition: two 4-neighbouring pixels form a discontinuity when their depths differ by more than
// relative_jump times the nearer depth, or when one is +infinity and the other finite; both pixels
// of such a pair are edge pixels. A pixel is in the band when the Euclidean distance between its
// centre and the centre of the nearest edge pixel is <= band_radius_px (so radius 0 gives the edge
// pixels themselves). Throws OptionsError for a negative or non-finite radius, relative_jump <= 0,
// or a depth that is NaN or <= 0 (naming the pixel).
std::vector<std::uint8_t> depth_edge_band(const DepthMap& depth, double band_radius_px,
                                          double relative_jump = 0.05);

// Per-pixel |tone_map(a) - tone_map(b)| as a 3-channel image for a PNG error map: a 1-channel input
// is repeated into grey, inputs with 3 or more channels give their first three. Throws OptionsError
// when sizes or channel counts differ or the images have 2 channels.
Image error_map(const Image& a, const Image& b);

// Whole-frame and depth-edge-band scores of a rendered image against a reference.
struct ImageComparison {
  double psnr_db = 0.0;       // whole frame, dB (+inf when identical)
  double ssim = 0.0;          // whole frame, in [-1, 1]
  double edge_psnr_db = 0.0;  // over the depth-edge band; NaN when the band is empty
  double edge_ssim = 0.0;     // over the band pixels >= 5 px from the border; NaN when there are none
  std::size_t edge_pixels = 0;  // pixels in the depth-edge band
  // "ImageComparison(PSNR 34.2 dB, SSIM 0.9871; edge band 5120 px: PSNR 28.4 dB, SSIM 0.9312)"
  std::string to_string() const;
  friend std::ostream& operator<<(std::ostream& os, const ImageComparison& c) { return os << c.to_string(); }
};

// Scores result against reference over the whole frame and over depth_edge_band(depth,
// band_radius_px) with the default relative jump. depth must have the images' size. Throws
// OptionsError as psnr(), ssim() and depth_edge_band() do, and when the depth map's size differs.
ImageComparison compare_images(const Image& result, const Image& reference, const DepthMap& depth,
                               double band_radius_px);

}  // namespace lensmith
