// Scatter-as-you-gather depth of field at half resolution (Jimenez 2014) and Tan et al.'s traced
// holes (gather_renderer.h says what lensmith does differently): the lens's footprints tabulated
// (psf_table.h), a half-resolution buffer of presorted, prefiltered samples, tiles of the nearest
// depth and largest footprint dilated by their reach, a ring gather per half-resolution pixel,
// the median, the optional ray mask and traced rays, and the composite over the sharp picture.
#include "lensmith/render/gather_renderer.h"

#include <omp.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>
#include <vector>

#include "lensmith/core/errors.h"
#include "lensmith/core/units.h"
#include "psf_table.h"
#include "scatter_source.h"

namespace lensmith {

namespace {

using render_detail::PsfEntry;
using render_detail::PsfTable;
using render_detail::Variance;
using render_detail::variance_of;

// Tiles of this many output px (8 half-resolution pixels), as Jimenez's 16-20 px.
constexpr int kTilePx = 16;
// The spread's soft edge, output px (Jimenez's spread falls from 1 to 0 over one pixel of his
// half-resolution buffer beyond the CoC; the footprints' centres here are not on that grid, and
// with two px an in-focus highlight spread over 3 x 3 half-resolution pixels, which the median
// keeps: one px).
constexpr double kSpreadEdgePx = 1.0;
// A sample's weight as background rises from 0 to 1 as its blur diameter departs from the blur of
// its tile's nearest surface by 0 to this many px (two surfaces whose blurs differ by less are
// one layer to the eye).
constexpr double kLayerBlurPx = 4.0;
// A tile whose largest kernel radius is below this (output px) is in focus: not gathered (the
// spread's edge, 1 px, plus a blur of 1 px diameter and a margin).
constexpr double kSharpKernelPx = 2.0;
// The composite: a pixel is sharp below kSharpBlurPx of blur diameter and the gathered result above
// kSharpBlurPx + kBlendBlurPx, linearly between.
constexpr double kSharpBlurPx = 1.0;
constexpr double kBlendBlurPx = 2.0;
// Fixed-point steps from an output pixel to the point the lens moves onto it (the composite's sharp
// picture): the displacement changes slowly across the frame (a few px over tens), so two steps
// bring it within a small fraction of a pixel.
constexpr int kSourceSteps = 2;
// The hybrid's ray mask: Tan et al.'s scale s of the Sobel magnitude (per px of blur per output
// px), and the least mask value that gets rays.
constexpr double kMaskScale = 0.5;
constexpr double kMinMask = 0.05;
// A gradient of the blur map below this (px of blur per output px) is a sloping surface, no edge.
constexpr double kRampBlurPerPx = 0.5;

double smoothstep01(double t) {
  t = std::clamp(t, 0.0, 1.0);
  return t * t * (3.0 - 2.0 * t);
}
double saturate(double t) { return std::clamp(t, 0.0, 1.0); }
// How blurred a point of signed blur diameter `blur_px` counts: 0 (sharp) below kSharpBlurPx, 1
// from kSharpBlurPx + kBlendBlurPx (the composite, the layers' sums and the ray mask all use it).
double blurriness(double blur_px) { return saturate((std::abs(blur_px) - kSharpBlurPx) / kBlendBlurPx); }

// A half-resolution sample: its footprint's centroid (output px), the inverse of its covariance
// (x^T V^-1 x = a x^2 + 2 b x y + c y^2), its reach (output px: half the footprint's longer axis),
// the light per area (alpha), its presort weight as background, signed blur, inverse depth and
// prefiltered colour (times the lens's throughput).
struct Sample {
  float cx = 0.0f, cy = 0.0f;
  float ia = 1.0f, ib = 0.0f, ic = 1.0f;
  float reach = 0.0f;
  float alpha = 0.0f;
  float background = 0.0f;
  float blur = 0.0f;
  double inverse_depth = 0.0;
  std::array<float, 3> rgb{};
};

// A tile: over its own samples (reach box in output px, nearest inverse depth, largest reach, the
// range of centroid shifts), then, dilated, over every tile that reaches it.
struct Tile {
  double x0 = kInfinity, y0 = kInfinity, x1 = -kInfinity, y1 = -kInfinity;  // reach box
  double nearest = -kInfinity;  // largest inverse depth, 1/mm
  double reach = 0.0;
  double sx0 = kInfinity, sy0 = kInfinity, sx1 = -kInfinity, sy1 = -kInfinity;  // centroid shifts
};

// Bilinear read of `channels`-channel rows at output position (x, y) px (pixel centres at +0.5),
// clamped to the edge.
template <class Get>
auto bilinear(int w, int h, double x, double y, Get&& get) {
  const double fx = std::clamp(x - 0.5, 0.0, w - 1.0), fy = std::clamp(y - 0.5, 0.0, h - 1.0);
  const int x0 = std::min(static_cast<int>(fx), w - 1), y0 = std::min(static_cast<int>(fy), h - 1);
  const int x1 = std::min(x0 + 1, w - 1), y1 = std::min(y0 + 1, h - 1);
  const double tx = fx - x0, ty = fy - y0;
  return get(x0, y0) * ((1 - tx) * (1 - ty)) + get(x1, y0) * (tx * (1 - ty)) + get(x0, y1) * ((1 - tx) * ty) + get(x1, y1) * (tx * ty);
}

}  // namespace

void GatherOptions::validate() const {
  if (threads < 0) throw OptionsError("threads must be >= 0 (0 = all), got " + std::to_string(threads));
  if (rings != 3 && rings != 4) {
    throw OptionsError("gather rings must be 3 (Jimenez 2014, 48 taps) or 4 (Tan et al. 2022, 80 taps), got " + std::to_string(rings));
  }
  if (!(std::isfinite(max_blur_px) && max_blur_px >= 1.0)) {
    throw OptionsError("max blur must be a finite diameter >= 1 px, got " + std::to_string(max_blur_px));
  }
  if (trace_rays < 1 || trace_rays > 4096) throw OptionsError("trace rays must be 1 to 4096 per pixel, got " + std::to_string(trace_rays));
}

std::string GatherOptions::to_string() const {
  std::ostringstream os;
  os << "GatherOptions(" << (lens_psf ? "the lens's PSF ellipses" : "circles of the CoC") << ", " << rings << " rings, median "
     << (median ? "on" : "off") << ", vignetting " << (vignetting ? "on" : "off");
  if (trace) os << ", traced holes up to " << trace_rays << " rays per half-resolution pixel";
  os << ", threads " << threads << ")";
  return os.str();
}

std::string GatherStatistics::to_string() const {
  std::ostringstream os;
  os << "GatherStatistics(" << half_width << " x " << half_height << " half resolution, " << tiles << " tiles, " << taps
     << " taps, largest kernel " << max_kernel_radius_px << " px, " << gathered_pixels << " gathered, " << traced_pixels << " traced with "
     << traced_rays << " rays, " << clamped_depths << " clamped depths)";
  return os.str();
}

Image render_gather(const Image& image, const DepthMap& depth, const RayModel& model, const Aperture& aperture,
                    const GatherOptions& options, GatherStatistics* statistics) {
  options.validate();
  const Camera& camera = model.camera();
  const int w = camera.frame().width_px(), h = camera.frame().height_px();
  render_detail::check_flat_input(image, depth, camera, aperture, "render_gather", "gather");
  const int threads = options.threads > 0 ? options.threads : omp_get_max_threads();
  const std::size_t pixels = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
  GatherStatistics stats;
  auto report = [&options](double f) {
    if (options.progress) options.progress(f);
  };

  // Full resolution: the pixels' inverse depths, clamped as the other methods', and their blurs.
  const render_detail::ClampedDepths depths = render_detail::clamped_inverse_depths(camera, depth, options.max_blur_px, threads);
  const std::vector<double>& inverse = depths.inverse;
  const double w_min = depths.w_min, w_max = depths.w_max, max_blur = depths.max_blur_px;
  stats.clamped_depths = depths.clamped;
  std::vector<float> blur(pixels);
#pragma omp parallel for schedule(static) num_threads(threads)
  for (std::size_t p = 0; p < pixels; ++p) blur[p] = static_cast<float>(camera.signed_coc_px(inverse[p]));
  // The footprints, over the frame and the margin the taps may read beyond it (the picture
  // continues as its edge pixels, as textures clamp to their edge in the real-time methods).
  const int margin = render_detail::frame_margin_px(model, 0.5 * max_blur + kSpreadEdgePx);
  render_detail::PsfTableOptions table_options;
  table_options.lens_psf = options.lens_psf;
  table_options.vignetting = options.vignetting;
  const PsfTable table(model, aperture, w_min, w_max, margin, table_options, threads);
  report(0.1);

  // Half resolution: sample (i, j) stands for the pixels [2i, 2i + 2) x [2j, 2j + 2).
  const int hw = (w + 1) / 2, hh = (h + 1) / 2;
  const std::size_t half_pixels = static_cast<std::size_t>(hw) * static_cast<std::size_t>(hh);
  stats.half_width = hw;
  stats.half_height = hh;
  std::vector<Sample> samples(half_pixels);
#pragma omp parallel for schedule(static) num_threads(threads)
  for (int j = 0; j < hh; ++j) {
    for (int i = 0; i < hw; ++i) {
      // Jimenez's: the farthest depth of the 2 x 2 pixels (a foreground does not spill into the
      // background's samples).
      double wf = kInfinity;
      int count = 0;
      for (int y = 2 * j; y < std::min(2 * j + 2, h); ++y) {
        for (int x = 2 * i; x < std::min(2 * i + 2, w); ++x) {
          wf = std::min(wf, inverse[static_cast<std::size_t>(y) * w + x]);
          ++count;
        }
      }
      const double px = 2.0 * i + 1.0, py = 2.0 * j + 1.0;
      const PsfEntry e = table.at(px, py, wf);
      Variance v = variance_of(e);
      // (Not widened by the sample's 2 x 2 block: at small blurs the half-resolution buffer then
      // blurred a 2 px disc to 8 px; a floor of 0.1 px keeps the ellipse invertible.)
      v.xx += 0.01;
      v.yy += 0.01;
      const double det = v.determinant();
      Sample& s = samples[static_cast<std::size_t>(j) * hw + i];
      s.cx = static_cast<float>(px + e.dx);
      s.cy = static_cast<float>(py + e.dy);
      s.ia = static_cast<float>(v.yy / det);
      s.ib = static_cast<float>(-v.xy / det);
      s.ic = static_cast<float>(v.xx / det);
      // Semi-axes of the footprint (a disc of radius R has variance R^2 / 4) and the area of the
      // spread over it, 1 inside falling linearly to 0 over kSpreadEdgePx beyond: for a disc
      // pi (R^2 + R e + e^2 / 3), for an ellipse with the semi-axes' product and mean.
      const double a = 2.0 * std::sqrt(v.larger_eigenvalue()), b = 2.0 * std::sqrt(std::max(v.smaller_eigenvalue(), 0.0));
      const double e_px = kSpreadEdgePx;
      const double area = kPi * (a * b + 0.5 * e_px * (a + b) + e_px * e_px / 3.0);
      s.reach = static_cast<float>(a);
      s.alpha = static_cast<float>(static_cast<double>(count) * e.area / area);
      s.blur = static_cast<float>(camera.signed_coc_px(wf));
      s.inverse_depth = wf;
      s.rgb = {e.throughput, e.throughput, e.throughput};  // times the prefiltered colour, below
    }
  }

  // Tiles: their own samples' reach, then spread to every tile they reach.
  const int tile_half = kTilePx / 2;
  const int tx_count = (hw + tile_half - 1) / tile_half, ty_count = (hh + tile_half - 1) / tile_half;
  stats.tiles = tx_count * ty_count;
  std::vector<Tile> own(static_cast<std::size_t>(tx_count) * ty_count);
  for (int j = 0; j < hh; ++j) {
    for (int i = 0; i < hw; ++i) {
      const Sample& s = samples[static_cast<std::size_t>(j) * hw + i];
      Tile& t = own[static_cast<std::size_t>(j / tile_half) * tx_count + i / tile_half];
      const double r = s.reach + kSpreadEdgePx;
      t.x0 = std::min(t.x0, s.cx - r);
      t.x1 = std::max(t.x1, s.cx + r);
      t.y0 = std::min(t.y0, s.cy - r);
      t.y1 = std::max(t.y1, s.cy + r);
      t.nearest = std::max(t.nearest, s.inverse_depth);
      t.reach = std::max(t.reach, r);
      const double sx = s.cx - (2.0 * i + 1.0), sy = s.cy - (2.0 * j + 1.0);
      t.sx0 = std::min(t.sx0, sx);
      t.sx1 = std::max(t.sx1, sx);
      t.sy0 = std::min(t.sy0, sy);
      t.sy1 = std::max(t.sy1, sy);
    }
  }
  std::vector<Tile> tiles = own;
  for (const Tile& t : own) {
    const int ux0 = std::max(0, static_cast<int>(std::floor(t.x0 / kTilePx))), ux1 = std::min(tx_count - 1, static_cast<int>(std::floor(t.x1 / kTilePx)));
    const int uy0 = std::max(0, static_cast<int>(std::floor(t.y0 / kTilePx))), uy1 = std::min(ty_count - 1, static_cast<int>(std::floor(t.y1 / kTilePx)));
    for (int uy = uy0; uy <= uy1; ++uy) {
      for (int ux = ux0; ux <= ux1; ++ux) {
        Tile& u = tiles[static_cast<std::size_t>(uy) * tx_count + ux];
        u.nearest = std::max(u.nearest, t.nearest);
        u.reach = std::max(u.reach, t.reach);
        u.sx0 = std::min(u.sx0, t.sx0);
        u.sx1 = std::max(u.sx1, t.sx1);
        u.sy0 = std::min(u.sy0, t.sy0);
        u.sy1 = std::max(u.sy1, t.sy1);
      }
    }
  }
  // Each tile's kernel: centred where its light comes from (the pixel less the mean shift), wide
  // enough for the largest footprint reaching it and the spread of the shifts.
  std::vector<double> kernel(tiles.size()), shift_x(tiles.size()), shift_y(tiles.size()), near_blur(tiles.size());
  for (std::size_t t = 0; t < tiles.size(); ++t) {
    const Tile& u = tiles[t];
    shift_x[t] = 0.5 * (u.sx0 + u.sx1);
    shift_y[t] = 0.5 * (u.sy0 + u.sy1);
    kernel[t] = u.reach + std::hypot(0.5 * (u.sx1 - u.sx0), 0.5 * (u.sy1 - u.sy0));
    near_blur[t] = camera.signed_coc_px(u.nearest);
    stats.max_kernel_radius_px = std::max(stats.max_kernel_radius_px, kernel[t]);
  }
  auto tile_of = [&](int i, int j) { return static_cast<std::size_t>(j / tile_half) * tx_count + static_cast<std::size_t>(i / tile_half); };

  // Presort and prefilter: each sample's background weight against its tile's nearest surface, and
  // its colour from 9 bilateral taps over a square of half side R / (2 rings).
  const int rings = options.rings;
#pragma omp parallel for schedule(static) num_threads(threads)
  for (int j = 0; j < hh; ++j) {
    for (int i = 0; i < hw; ++i) {
      Sample& s = samples[static_cast<std::size_t>(j) * hw + i];
      const std::size_t t = tile_of(i, j);
      s.background = static_cast<float>(smoothstep01(std::abs(s.blur - near_blur[t]) / kLayerBlurPx));
      // Less the half-resolution grid's own 1 px (its samples already average 2 x 2 pixels: where
      // the rings' spacing is within the grid's, the taps reach every sample and a prefilter only
      // blurs; the occluder scene's 4 px checker blur came out twice as wide), and at most half the
      // sample's own reach (a sharp sample is gathered only by the taps next to it).
      const double half_side = std::min(kernel[t] / (2.0 * rings) - 1.0, 0.5 * static_cast<double>(s.reach));
      const double tolerance = std::max(2.0, 0.25 * std::abs(s.blur));
      const double px = 2.0 * i + 1.0, py = 2.0 * j + 1.0;
      double sum[3] = {0, 0, 0}, weight = 0.0;
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const double x = px + dx * half_side, y = py + dy * half_side;
          const double tap_blur = bilinear(w, h, x, y, [&](int xx, int yy) { return static_cast<double>(blur[static_cast<std::size_t>(yy) * w + xx]); });
          // (Below half a pixel the centre's bilinear read, the 2 x 2 block's mean, is all.)
          if ((dx != 0 || dy != 0) && half_side < 0.5) continue;
          const double wt = (dx == 0 && dy == 0) ? 1.0 : saturate(1.0 - std::abs(tap_blur - s.blur) / tolerance);
          if (!(wt > 0.0)) continue;
          for (int c = 0; c < 3; ++c) {
            sum[c] += wt * bilinear(w, h, x, y, [&](int xx, int yy) {
                        return static_cast<double>(image.data[(static_cast<std::size_t>(yy) * w + xx) * 3 + c]);
                      });
          }
          weight += wt;
        }
      }
      for (int c = 0; c < 3; ++c) s.rgb[c] = static_cast<float>(s.rgb[c] * sum[c] / weight);
    }
  }
  report(0.3);

  // The taps: the centre and rings k = 1..K of 8k taps at radius k / K (uniform in area: each
  // stands for pi R^2 / (4 K^2)), alternate rings turned by half a step.
  std::vector<std::array<double, 2>> taps{{0.0, 0.0}};
  for (int k = 1; k <= rings; ++k) {
    for (int m = 0; m < 8 * k; ++m) {
      const double angle = 2.0 * kPi * (m + 0.5 * (k % 2)) / (8.0 * k);
      taps.push_back({std::cos(angle) * k / rings, std::sin(angle) * k / rings});
    }
  }
  stats.taps = static_cast<int>(taps.size());
  const double tap_share = kPi / (4.0 * rings * rings);  // of R^2

  // Main pass: per half-resolution pixel, the foreground and background sums of the taps whose
  // footprints cover it: the background's mean, the blurred foreground's mean and its coverage.
  // (The composite lays them over the sharp picture: the background where the pixel itself is
  // blurred, the foreground by its coverage, each alpha once.)
  using Colour = std::array<float, 3>;
  std::vector<Colour> back(half_pixels), front(half_pixels);
  std::vector<float> coverage(half_pixels, 0.0f);
  // The blurred foreground's share of the weight gathered: in (0, 1) where it lies over something
  // else (its silhouette), 1 inside it. (Its coverage estimate is too noisy inside a surface whose
  // blur is smaller than its tile's kernel, where few taps fall within it, to find silhouettes.)
  std::vector<float> front_share(half_pixels, 0.0f);
  std::size_t gathered_count = 0;
#pragma omp parallel for schedule(dynamic, 4) num_threads(threads) reduction(+ : gathered_count)
  for (int j = 0; j < hh; ++j) {
    for (int i = 0; i < hw; ++i) {
      const std::size_t o = static_cast<std::size_t>(j) * hw + i;
      const std::size_t t = tile_of(i, j);
      const double radius = kernel[t];
      back[o] = front[o] = samples[o].rgb;
      if (radius < kSharpKernelPx) continue;
      ++gathered_count;
      const double ox = 2.0 * i + 1.0, oy = 2.0 * j + 1.0;
      const double cx = ox - shift_x[t], cy = oy - shift_y[t];
      // Sums of weighted colour and weight: background, foreground, and the foreground's samples
      // that are themselves blurred (an in-focus foreground is the sharp picture's already).
      double bg[4] = {0, 0, 0, 0}, fg[4] = {0, 0, 0, 0}, blurred_fg[4] = {0, 0, 0, 0};
      for (const auto& tap : taps) {
        const double x = cx + radius * tap[0], y = cy + radius * tap[1];
        // The sample there (point sampling); beyond the frame, the edge's sample moved out.
        const int si = static_cast<int>(std::floor(0.5 * x)), sj = static_cast<int>(std::floor(0.5 * y));
        const int ci = std::clamp(si, 0, hw - 1), cj = std::clamp(sj, 0, hh - 1);
        const Sample& s = samples[static_cast<std::size_t>(cj) * hw + ci];
        const double dx = ox - (s.cx + 2.0 * (si - ci)), dy = oy - (s.cy + 2.0 * (sj - cj));
        const double m2 = s.ia * dx * dx + 2.0 * s.ib * dx * dy + s.ic * dy * dy;
        const double d = std::hypot(dx, dy);
        // The spread: 1 inside the ellipse x^T V^-1 x <= 4, falling to 0 over kSpreadEdgePx beyond
        // along the ray from its centre (whose edge lies at distance 2 d / sqrt(m2)).
        const double spread = m2 < 1e-12 ? 1.0 : saturate((2.0 * d / std::sqrt(m2) - d) / kSpreadEdgePx + 1.0);
        if (!(spread > 0.0)) continue;
        // Each layer's sums count its blurred samples only: a sharp sample is the sharp picture's
        // already (as a half-resolution sample, upsampled into its blurred neighbours, an in-focus
        // light behind blurred branches became an 8 px blob).
        const double blurry = blurriness(s.blur);
        const double weight = s.alpha * spread;
        const double wb = weight * s.background * blurry, wf = weight * (1.0 - s.background);
        const double wbf = wf * blurry;
        for (int c = 0; c < 3; ++c) {
          bg[c] += wb * s.rgb[c];
          fg[c] += wf * s.rgb[c];
          blurred_fg[c] += wbf * s.rgb[c];
        }
        bg[3] += wb;
        fg[3] += wf;
        blurred_fg[3] += wbf;
      }
      // The background: its mean, or where none covers, the blurred foreground's, or the
      // foreground's (Jimenez's layers share the pixel).
      const double* b = bg[3] > 0.0 ? bg : blurred_fg[3] > 0.0 ? blurred_fg : fg[3] > 0.0 ? fg : nullptr;
      if (b) back[o] = {static_cast<float>(b[0] / b[3]), static_cast<float>(b[1] / b[3]), static_cast<float>(b[2] / b[3])};
      if (blurred_fg[3] > 0.0) {
        front[o] = {static_cast<float>(blurred_fg[0] / blurred_fg[3]), static_cast<float>(blurred_fg[1] / blurred_fg[3]),
                    static_cast<float>(blurred_fg[2] / blurred_fg[3])};
      }
      // The blurred foreground's coverage: the light per area landing here, each tap standing for
      // tap_share R^2 px^2 (a quarter as many samples).
      coverage[o] = static_cast<float>(saturate(blurred_fg[3] * tap_share * radius * radius / 4.0));
      if (bg[3] + fg[3] > 0.0) front_share[o] = static_cast<float>(blurred_fg[3] / (bg[3] + fg[3]));
    }
  }
  stats.gathered_pixels = gathered_count;
  report(0.6);

  // Postfilter: the 3 x 3 median of each channel where the tile was gathered.
  if (options.median) {
    for (std::vector<Colour>* layer : {&back, &front}) {
      const std::vector<Colour> gathered = *layer;
#pragma omp parallel for schedule(static) num_threads(threads)
      for (int j = 0; j < hh; ++j) {
        for (int i = 0; i < hw; ++i) {
          if (kernel[tile_of(i, j)] < kSharpKernelPx) continue;
          for (int c = 0; c < 3; ++c) {
            std::array<float, 9> v{};
            int n = 0;
            for (int dy = -1; dy <= 1; ++dy) {
              for (int dx = -1; dx <= 1; ++dx) {
                const int x = std::clamp(i + dx, 0, hw - 1), y = std::clamp(j + dy, 0, hh - 1);
                v[static_cast<std::size_t>(n++)] = gathered[static_cast<std::size_t>(y) * hw + x][static_cast<std::size_t>(c)];
              }
            }
            std::nth_element(v.begin(), v.begin() + 4, v.end());
            (*layer)[static_cast<std::size_t>(j) * hw + i][static_cast<std::size_t>(c)] = v[4];
          }
        }
      }
    }
  }

  // Tan et al.'s hybrid: a ray mask from the blur map's edges and the foreground's partial
  // coverage, rays traced through the lens there, their mean over the post-process by the mask.
  // (Traced at full resolution: the rays keep the sharp detail they see, which half-resolution
  // traced colours blurred at every in-focus edge near a blurred foreground.)
  std::vector<Colour> traced(pixels);
  std::vector<float> traced_share(pixels, 0.0f);
  if (options.trace) {
    std::vector<float> smooth(half_pixels);
    // A 3 x 3 binomial Gaussian of the blur map, then the 5 x 5 Sobel (normalised to the gradient
    // per output px).
    auto blur_at = [&](int i, int j) { return samples[static_cast<std::size_t>(std::clamp(j, 0, hh - 1)) * hw + std::clamp(i, 0, hw - 1)].blur; };
    for (int j = 0; j < hh; ++j) {
      for (int i = 0; i < hw; ++i) {
        double s = 0.0;
        for (int dy = -1; dy <= 1; ++dy) {
          for (int dx = -1; dx <= 1; ++dx) s += (dx ? 1.0 : 2.0) * (dy ? 1.0 : 2.0) * static_cast<double>(blur_at(i + dx, j + dy));
        }
        smooth[static_cast<std::size_t>(j) * hw + i] = static_cast<float>(s / 16.0);
      }
    }
    static constexpr int kSmooth[5] = {1, 4, 6, 4, 1}, kDerivative[5] = {-1, -2, 0, 2, 1};
    std::vector<float> edge(half_pixels);
    for (int j = 0; j < hh; ++j) {
      for (int i = 0; i < hw; ++i) {
        double gx = 0.0, gy = 0.0;
        for (int b = 0; b < 5; ++b) {
          for (int a = 0; a < 5; ++a) {
            const double v = smooth[static_cast<std::size_t>(std::clamp(j + b - 2, 0, hh - 1)) * hw + std::clamp(i + a - 2, 0, hw - 1)];
            gx += kDerivative[a] * kSmooth[b] * v;
            gy += kSmooth[a] * kDerivative[b] * v;
          }
        }
        // A unit ramp per half-resolution pixel gives 128; per output px, twice that.
        const double gradient = std::hypot(gx, gy) / 256.0;
        // An edge between surfaces that are both in focus hides nothing the lens would show: only
        // edges with a blurred side count (the largest blur within the Sobel's window).
        double widest = 0.0;
        for (int b = -2; b <= 2; ++b) {
          for (int a = -2; a <= 2; ++a) widest = std::max(widest, std::abs(static_cast<double>(blur_at(i + a, j + b))));
        }
        // (A sloping surface's blur changes smoothly, by less than kRampBlurPerPx per px unless
        // seen at grazing angles: its gradient is no edge. Without this the crossing planes were
        // traced all over, and their rays' noise cost 5 dB.)
        const double x = std::max(0.0, gradient - kRampBlurPerPx) * kMaskScale * blurriness(widest);
        edge[static_cast<std::size_t>(j) * hw + i] = static_cast<float>(saturate(1.0 - 1.0 / (x + 1.0)));
      }
    }
    // Tiles with an edge, spread over the tiles within their kernel's reach: the presort's soft
    // layers make h partial on any surface whose blur varies across a kernel (the crossing planes),
    // where nothing is hidden; holes lie within a blur's reach of an edge.
    std::vector<std::uint8_t> tile_edge(tiles.size(), 0), near_edge(tiles.size(), 0);
    for (int j = 0; j < hh; ++j) {
      for (int i = 0; i < hw; ++i) {
        if (edge[static_cast<std::size_t>(j) * hw + i] >= kMinMask) tile_edge[tile_of(i, j)] = 1;
      }
    }
    for (int ty = 0; ty < ty_count; ++ty) {
      for (int tx = 0; tx < tx_count; ++tx) {
        const std::size_t t = static_cast<std::size_t>(ty) * tx_count + tx;
        const int reach = static_cast<int>(std::ceil(kernel[t] / kTilePx));
        for (int uy = std::max(0, ty - reach); uy <= std::min(ty_count - 1, ty + reach) && !near_edge[t]; ++uy) {
          for (int ux = std::max(0, tx - reach); ux <= std::min(tx_count - 1, tx + reach); ++ux) {
            if (tile_edge[static_cast<std::size_t>(uy) * tx_count + ux]) near_edge[t] = 1;
          }
        }
      }
    }
    std::vector<GatherTraceRequest> requests;
    std::vector<std::size_t> request_pixel;
    for (int j = 0; j < hh; ++j) {
      for (int i = 0; i < hw; ++i) {
        const std::size_t o = static_cast<std::size_t>(j) * hw + i;
        const double x_n = edge[o];
        const double a = near_edge[tile_of(i, j)] ? front_share[o] : 0.0;
        const double x_f = saturate(x_n + 4.0 * a * (1.0 - a));
        if (x_f < kMinMask) continue;
        // The half-resolution pixel's rays, shared among its output pixels.
        const int rays = std::max(1, static_cast<int>(std::ceil(options.trace_rays * x_f / 4.0)));
        for (int y = 2 * j; y < std::min(2 * j + 2, h); ++y) {
          for (int x2 = 2 * i; x2 < std::min(2 * i + 2, w); ++x2) {
            GatherTraceRequest r;
            r.x_px = static_cast<float>(x2);
            r.y_px = static_cast<float>(y);
            r.size_px = 1.0f;
            r.rays = rays;
            requests.push_back(r);
            const std::size_t q = static_cast<std::size_t>(y) * w + static_cast<std::size_t>(x2);
            request_pixel.push_back(q);
            traced_share[q] = static_cast<float>(x_f);
          }
        }
      }
    }
    report(0.65);
    options.trace(requests);
    for (std::size_t k = 0; k < requests.size(); ++k) {
      const GatherTraceRequest& r = requests[k];
      const std::size_t o = request_pixel[k];
      stats.traced_rays += static_cast<std::size_t>(r.rays);
      if (r.reached <= 0) {
        traced_share[o] = 0.0f;
        continue;
      }
      ++stats.traced_pixels;
      // (A few rays' mean of a saturated colour's smooth spectrum can dip below zero: clamped.)
      for (int c = 0; c < 3; ++c) traced[o][static_cast<std::size_t>(c)] = std::max(r.rgb[static_cast<std::size_t>(c)], 0.0f);
    }
  }
  report(0.9);

  // Composite at full resolution, each half-resolution buffer upsampled bilinearly: the sharp
  // picture (moved and dimmed as the lens does at its pixel's depth), the background over it by
  // the pixel's own blur, the blurred foreground over that by its coverage, the traced colour over
  // all by the ray mask.
  Image out(w, h, 3, 0.0f);
#pragma omp parallel for schedule(static) num_threads(threads)
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const std::size_t p = static_cast<std::size_t>(y) * w + x;
      const double qx = x + 0.5, qy = y + 0.5;
      // The sharp picture's light here is that of the point the lens moves onto this pixel, dimmed
      // as the lens dims that point (the table is indexed by where a point is, not where it lands):
      // its displacement found by fixed-point steps from this pixel's. With the pixel's own entry, a
      // retrofocus's 16 % barrel lit its frame's corner with the frame corner's own light (0.34 of
      // the centre through the exact model, where the ground truth has 0.05: lentil 0005).
      PsfEntry e = table.at(qx, qy, inverse[p]);
      for (int k = 0; k < kSourceSteps; ++k) e = table.at(qx - e.dx, qy - e.dy, inverse[p]);
      const double hx = 0.5 * qx, hy = 0.5 * qy;  // in half-resolution pixels
      auto half = [&](const auto& get) { return bilinear(hw, hh, hx, hy, get); };
      const double a = half([&](int i, int j) { return static_cast<double>(coverage[static_cast<std::size_t>(j) * hw + i]); });
      const double share = traced_share[p];
      const double own_blur = blurriness(blur[p]);
      for (int c = 0; c < 3; ++c) {
        const auto channel = static_cast<std::size_t>(c);
        const double sharp = e.throughput * bilinear(w, h, qx - e.dx, qy - e.dy, [&](int i, int j) {
                               return static_cast<double>(image.data[(static_cast<std::size_t>(j) * w + i) * 3 + channel]);
                             });
        const double b = half([&](int i, int j) { return static_cast<double>(back[static_cast<std::size_t>(j) * hw + i][channel]); });
        const double f = half([&](int i, int j) { return static_cast<double>(front[static_cast<std::size_t>(j) * hw + i][channel]); });
        double v = sharp + own_blur * (b - sharp);
        v += a * (f - v);
        v += share * (traced[p][channel] - v);
        out.data[p * 3 + c] = static_cast<float>(v);
      }
    }
  }
  report(1.0);
  if (statistics) *statistics = stats;
  return out;
}

}  // namespace lensmith
