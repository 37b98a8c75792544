// EWA surface splatting with depth of field (Křivánek, Žára & Bouatouch 2003; ewa_renderer.h says
// what lensmith does differently): the lens's PSF moments tabulated over the frame and depth, the
// pixels as surfels in a level-of-detail hierarchy of blocks, one Gaussian splat per drawn node into
// an A-buffer of a few fragments per pixel, bands of rows per thread, and the fragments composited
// front to back.
#include "lensmith/render/ewa_renderer.h"

#include <omp.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>
#include <vector>

#include "lensmith/core/errors.h"
#include "lensmith/core/huge_page_allocator.h"
#include "lensmith/core/units.h"
#include "psf_table.h"
#include "scatter_source.h"

namespace lensmith {

namespace {

using render_detail::PsfEntry;
using render_detail::PsfTable;
using render_detail::Variance;
using render_detail::variance_of;

// A surfel's own kernel on top of its blur (px): small enough that an in-focus picture comes back
// nearly unchanged (a neighbour gets exp(-1 / 2 sigma^2) = 0.4 % of a pixel's light), wide enough
// that a sub-pixel shift (distortion) spreads the light over the pixels around.
constexpr double kSharpSigmaPx = 0.3;
// Splats are cut off at this many standard deviations (1.1 % of a Gaussian's mass lies beyond 3
// sigma; the per-splat normalisation gives it back to the rest).
constexpr double kCutoffSigmas = 3.0;
// The L2-best Gaussian of a uniform disc has variance R^2 / (2 ln 4): the disc's second moment R^2
// / 4 times 2 / ln 4 (ewa_renderer.h).
const double kL2Scale = 2.0 / std::log(4.0);
// Fragments per pixel of the A-buffer.
constexpr int kFragments = 4;
// Signed blurs (px) of one surface: within max(kSurfaceBlurFloorPx, kSurfaceBlurTolerance x |blur|).
constexpr double kSurfaceBlurFloorPx = 1.0;
constexpr double kSurfaceBlurTolerance = 0.2;
// The coarsest level of detail (blocks of 2^6 = 64 px), and the standard deviation of a level's
// Gaussians per block width: a grid of Gaussians of sigma 0.6 s at spacing s sums to 1 within
// 2 exp(-2 pi^2 0.36) = 0.2 % (Poisson summation), so coarse splats leave no ripple.
constexpr int kMaxLevel = 6;
constexpr double kLevelSigma = 0.6;
// The variance (px^2) the levels' binomial filters add up to at level spacing s: each level's
// [1 3 3 1] / 8 has variance 3/4 of the spacing below squared, sum_l 3/4 4^(l-1) = (s^2 - 1) / 4.
double level_variance(double s) { return (s * s - 1.0) / 4.0; }
// Below this smaller principal variance (px^2) a splat is normalised by the sum of its discrete
// weights; above, by the Gaussian's integral (their difference is below 1e-4 from sigma 0.7 px).
constexpr double kDiscreteNormVariance = 0.5;
// Bands of rows per thread.
constexpr int kBandsPerThread = 4;

// A node of the level-of-detail hierarchy: a 2^L x 2^L block of pixels (fewer at the frame's
// right and bottom edges), as sums over its pixels.
struct Node {
  float count = 0.0f;            // pixels
  float sx = 0.0f, sy = 0.0f;    // sums of their centres, px
  float r = 0.0f, g = 0.0f, b = 0.0f;  // sums of their colours
  double inverse_depth = 0.0;    // sum of their inverse depths, 1/mm
  float blur_min = 0.0f, blur_max = 0.0f;  // signed blur, px
  bool surface = true;           // its pixels lie on one surface
};

// Whether signed blurs a and b (px) are one surface.
bool one_surface(double a, double b) {
  return std::abs(a - b) <= std::max(kSurfaceBlurFloorPx, kSurfaceBlurTolerance * std::max(std::abs(a), std::abs(b)));
}

// One Gaussian splat: centre (px), conic (the inverse variance: Q = a dx^2 + 2 b dx dy + c dy^2),
// the weight its peak gets (normalised so that its weights sum to its pixel count), its light per
// unit weight, its inverse depth and signed blur, and its rows.
struct Splat {
  float cx = 0.0f, cy = 0.0f;
  float a = 1.0f, b = 0.0f, c = 1.0f;
  float norm = 0.0f;
  float r = 0.0f, g = 0.0f, bl = 0.0f;
  float inverse_depth = 0.0f, blur = 0.0f;
  int y0 = 0, y1 = -1;  // rows [y0, y1] it reaches (clamped to the frame)
};

// An A-buffer fragment: sums of weight, weighted light and weighted inverse depth, and the signed
// blur of its first contribution (what later ones are compared with).
struct Fragment {
  float weight, r, g, b, inverse_depth, blur;
};

// x range [lo, hi] (pixel indices) of a splat's row at vertical offset dy from its centre; false
// when the row misses the cut-off ellipse.
bool row_span(const Splat& s, double dy, double cut2, double& dx_lo, double& dx_hi) {
  const double a = s.a, b = s.b, c = s.c;
  const double disc = b * b * dy * dy - a * (c * dy * dy - cut2);
  if (disc < 0.0) return false;
  const double root = std::sqrt(disc);
  dx_lo = (-b * dy - root) / a;
  dx_hi = (-b * dy + root) / a;
  return true;
}

// Calls f(x, weight) for the pixels (x, y) of row y the splat reaches, weight = exp(-Q / 2) (x not
// clamped to the frame: the caller decides). Evaluated incrementally along the row (Q is quadratic
// in x: each step multiplies by a ratio that itself changes by exp(-a)).
template <class F>
void for_row(const Splat& s, int y, double cut2, F&& f) {
  const double dy = y + 0.5 - s.cy;
  double lo = 0.0, hi = 0.0;
  if (!row_span(s, dy, cut2, lo, hi)) return;
  const int x0 = static_cast<int>(std::ceil(s.cx + lo - 0.5)), x1 = static_cast<int>(std::floor(s.cx + hi - 0.5));
  if (x1 < x0) return;
  const double a = s.a, b = s.b, c = s.c;
  double dx = x0 + 0.5 - s.cx;
  double value = std::exp(-0.5 * (a * dx * dx + 2.0 * b * dx * dy + c * dy * dy));
  double ratio = std::exp(-0.5 * (2.0 * a * dx + a + 2.0 * b * dy));
  const double step = std::exp(-a);
  for (int x = x0; x <= x1; ++x) {
    f(x, value);
    value *= ratio;
    ratio *= step;
  }
}

}  // namespace

void EwaOptions::validate() const {
  if (threads < 0) throw OptionsError("threads must be >= 0 (0 = all), got " + std::to_string(threads));
  if (!(std::isfinite(max_blur_px) && max_blur_px >= 1.0)) {
    throw OptionsError("max blur must be a finite diameter >= 1 px, got " + std::to_string(max_blur_px));
  }
}

std::string EwaOptions::to_string() const {
  std::ostringstream os;
  os << "EwaOptions(" << (lens_psf ? "the lens's PSF" : "circular Gaussians of the CoC") << ", level of detail "
     << (level_of_detail ? "on" : "off") << ", vignetting " << (vignetting ? "on" : "off") << ", threads " << threads << ")";
  return os.str();
}

std::string EwaStatistics::to_string() const {
  std::ostringstream os;
  os << "EwaStatistics(" << splats << " splats (";
  for (int l = 0; l <= kMaxLevel; ++l) os << (l ? " / " : "") << splats_per_level[l];
  os << " by level), " << pixel_writes << " pixel writes, " << overflow_merges << " overflow merges, " << unfilled_pixels
     << " unfilled pixels, " << clamped_depths << " clamped depths)";
  return os.str();
}

Image render_ewa(const Image& image, const DepthMap& depth, const RayModel& model, const Aperture& aperture,
                 const EwaOptions& options, EwaStatistics* statistics) {
  options.validate();
  const Camera& camera = model.camera();
  const int w = camera.frame().width_px(), h = camera.frame().height_px();
  render_detail::check_flat_input(image, depth, camera, aperture, "render_ewa", "ewa");
  const int threads = options.threads > 0 ? options.threads : omp_get_max_threads();
  EwaStatistics stats;

  // The pixels' inverse depths, clamped as the scatter method's.
  const render_detail::ClampedDepths depths = render_detail::clamped_inverse_depths(camera, depth, options.max_blur_px, threads);
  const std::vector<double>& inverse = depths.inverse;
  const double w_min = depths.w_min, w_max = depths.w_max, max_blur = depths.max_blur_px;
  stats.clamped_depths = depths.clamped;
  // Level 0: the pixels, and beyond the frame a margin where the picture continues as its edge
  // pixels (as the multiview and lightfield methods' layers do), so that splats from outside the
  // frame reach in as the scene's light would: without it a lens whose centroids move inwards
  // (distortion) left the frame's last column unreached, and blur near the edge had only half its
  // sources. The margin (frame_margin_px): how far a splat reaches (3 sigma of the L2 Gaussian: 0.9
  // blur diameters) and the lens's shift of the frame's edges.
  // (+2 px for the surfel's own kernel and the coarse levels' filters.) The blocks of the coarse
  // levels start at the margin's corner: their phase against the frame changes how a fine periodic
  // texture aliases (tests/render/ewa_test.cpp: 0.0076 at this margin, 0.0129 two pixels less).
  const int margin = render_detail::frame_margin_px(model, kCutoffSigmas * std::sqrt(kL2Scale / 4.0) * 0.5 * max_blur) + 2;
  const int sw = w + 2 * margin, sh = h + 2 * margin;
  render_detail::PsfTableOptions table;
  table.lens_psf = options.lens_psf;
  table.vignetting = options.vignetting;
  table.variance_scale = kL2Scale;
  const PsfTable psf(model, aperture, w_min, w_max, margin, table, threads);
  std::vector<LargeVector<Node>> levels(1, LargeVector<Node>(static_cast<std::size_t>(sw) * static_cast<std::size_t>(sh)));
  std::vector<std::array<int, 2>> sizes{{sw, sh}};
#pragma omp parallel for schedule(static) num_threads(threads)
  for (int y = 0; y < sh; ++y) {
    for (int x = 0; x < sw; ++x) {
      const int fx = std::clamp(x - margin, 0, w - 1), fy = std::clamp(y - margin, 0, h - 1);
      const std::size_t p = static_cast<std::size_t>(fy) * static_cast<std::size_t>(w) + static_cast<std::size_t>(fx);
      Node& n = levels[0][static_cast<std::size_t>(y) * static_cast<std::size_t>(sw) + static_cast<std::size_t>(x)];
      n.count = 1.0f;
      n.sx = static_cast<float>(x - margin) + 0.5f;
      n.sy = static_cast<float>(y - margin) + 0.5f;
      n.r = image.data[3 * p];
      n.g = image.data[3 * p + 1];
      n.b = image.data[3 * p + 2];
      n.inverse_depth = inverse[p];
      n.blur_min = n.blur_max = static_cast<float>(camera.signed_coc_px(n.inverse_depth));
    }
  }

  // Coarser levels: the level below filtered by the binomial [1 3 3 1] / 8 in each axis and taken
  // at every other node (a 2 x 2 box, tried first, let a period-11 texture alias into a 29 px beat
  // under a 24 px blur: 0.016 of 0.25 where drawing every pixel has none; the binomial damps the
  // texture 4 times more). A node is on one surface where its 4 x 4 children are and their blurs
  // agree. Sums, so that each child's weight is shared out whole (3/4 and 1/4 per axis).
  constexpr std::array<float, 4> kBinomial{0.25f, 0.75f, 0.75f, 0.25f};
  const int top = options.level_of_detail ? kMaxLevel : 0;
  for (int l = 1; l <= top && (sizes.back()[0] > 1 || sizes.back()[1] > 1); ++l) {
    const int fw = sizes.back()[0], fh = sizes.back()[1];
    const int cw = (fw + 1) / 2, ch = (fh + 1) / 2;
    LargeVector<Node> coarse(static_cast<std::size_t>(cw) * static_cast<std::size_t>(ch));
    const LargeVector<Node>& fine = levels.back();
#pragma omp parallel for schedule(static) num_threads(threads)
    for (int y = 0; y < ch; ++y) {
      for (int x = 0; x < cw; ++x) {
        Node n;
        n.blur_min = std::numeric_limits<float>::infinity();
        n.blur_max = -std::numeric_limits<float>::infinity();
        for (int k = 0; k < 16; ++k) {
          const int fx = 2 * x - 1 + (k & 3), fy = 2 * y - 1 + (k >> 2);
          if (fx < 0 || fy < 0 || fx >= fw || fy >= fh) continue;
          const float wt = kBinomial[static_cast<std::size_t>(k & 3)] * kBinomial[static_cast<std::size_t>(k >> 2)];
          const Node& f = fine[static_cast<std::size_t>(fy) * static_cast<std::size_t>(fw) + static_cast<std::size_t>(fx)];
          n.count += wt * f.count;
          n.sx += wt * f.sx;
          n.sy += wt * f.sy;
          n.r += wt * f.r;
          n.g += wt * f.g;
          n.b += wt * f.b;
          n.inverse_depth += wt * f.inverse_depth;
          n.blur_min = std::min(n.blur_min, f.blur_min);
          n.blur_max = std::max(n.blur_max, f.blur_max);
          n.surface = n.surface && f.surface;
        }
        n.surface = n.surface && one_surface(n.blur_min, n.blur_max);
        coarse[static_cast<std::size_t>(y) * static_cast<std::size_t>(cw) + static_cast<std::size_t>(x)] = n;
      }
    }
    levels.push_back(std::move(coarse));
    sizes.push_back({cw, ch});
  }

  // Which nodes are drawn, from the coarsest level down: a node on one surface whose blur can absorb
  // its block's width, unless an ancestor is drawn (0: open, 1: drawn, 2: under a drawn one).
  const int level_count = static_cast<int>(levels.size());
  std::vector<std::vector<std::uint8_t>> state(static_cast<std::size_t>(level_count));
  for (int l = level_count - 1; l >= 0; --l) {
    const int lw = sizes[static_cast<std::size_t>(l)][0], lh = sizes[static_cast<std::size_t>(l)][1];
    std::vector<std::uint8_t>& st = state[static_cast<std::size_t>(l)];
    st.assign(static_cast<std::size_t>(lw) * static_cast<std::size_t>(lh), 0);
    const double s = std::ldexp(1.0, l);
    const double needed = kLevelSigma * kLevelSigma * s * s + level_variance(s) - kSharpSigmaPx * kSharpSigmaPx;
#pragma omp parallel for schedule(static) num_threads(threads)
    for (int y = 0; y < lh; ++y) {
      for (int x = 0; x < lw; ++x) {
        const std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(lw) + static_cast<std::size_t>(x);
        if (l + 1 < level_count) {
          const auto pw = static_cast<std::size_t>(sizes[static_cast<std::size_t>(l) + 1][0]);
          const std::uint8_t parent = state[static_cast<std::size_t>(l) + 1][static_cast<std::size_t>(y / 2) * pw + static_cast<std::size_t>(x / 2)];
          if (parent != 0) {
            st[i] = 2;
            continue;
          }
        }
        const Node& n = levels[static_cast<std::size_t>(l)][i];
        if (l == 0) {
          st[i] = 1;
          continue;
        }
        if (!n.surface) continue;
        const PsfEntry e = psf.at(n.sx / n.count, n.sy / n.count, n.inverse_depth / n.count);
        if (variance_of(e).smaller_eigenvalue() >= needed) st[i] = 1;
      }
    }
  }

  // The splats of the drawn nodes, coarsest first.
  for (int l = 0; l < level_count; ++l) {
    const std::vector<std::uint8_t>& st = state[static_cast<std::size_t>(l)];
    stats.splats_per_level[l] = static_cast<std::size_t>(std::count(st.begin(), st.end(), std::uint8_t{1}));
    stats.splats += stats.splats_per_level[l];
  }
  LargeVector<std::array<int, 2>> drawn;  // (level, node)
  drawn.reserve(stats.splats);
  for (int l = level_count - 1; l >= 0; --l) {
    const std::vector<std::uint8_t>& st = state[static_cast<std::size_t>(l)];
    for (std::size_t i = 0; i < st.size(); ++i) {
      if (st[i] == 1) drawn.push_back({l, static_cast<int>(i)});
    }
  }
  const double cut2 = kCutoffSigmas * kCutoffSigmas;
  LargeVector<Splat> splats(drawn.size());
#pragma omp parallel for schedule(dynamic, 1024) num_threads(threads)
  for (std::size_t k = 0; k < drawn.size(); ++k) {
    const auto [l, i] = drawn[k];
    const Node& n = levels[static_cast<std::size_t>(l)][static_cast<std::size_t>(i)];
    const double px = n.sx / n.count, py = n.sy / n.count, node_inverse = n.inverse_depth / n.count;
    const PsfEntry e = psf.at(px, py, node_inverse);
    Variance v = variance_of(e);
    // The blur less what the level's filter already did, plus the surfel's own kernel
    // (ewa_renderer.h).
    const double extra = kSharpSigmaPx * kSharpSigmaPx - level_variance(std::ldexp(1.0, l));
    v.xx += extra;
    v.yy += extra;
    Splat& sp = splats[k];
    sp.cx = static_cast<float>(px + e.dx);
    sp.cy = static_cast<float>(py + e.dy);
    const double det = v.xx * v.yy - v.xy * v.xy;
    sp.a = static_cast<float>(v.yy / det);
    sp.b = static_cast<float>(-v.xy / det);
    sp.c = static_cast<float>(v.xx / det);
    // The sum of its weights before normalising: the Gaussian's integral over the cut-off ellipse, or
    // for a narrow splat by the sum of its discrete weights.
    double total = 0.0;
    const double reach_y = kCutoffSigmas * std::sqrt(v.yy);
    if (v.smaller_eigenvalue() >= kDiscreteNormVariance) {
      total = 2.0 * kPi * std::sqrt(det) * (1.0 - std::exp(-0.5 * cut2));
    } else {
      const int r0 = static_cast<int>(std::floor(sp.cy - reach_y)), r1 = static_cast<int>(std::ceil(sp.cy + reach_y));
      for (int y = r0; y <= r1; ++y) for_row(sp, y, cut2, [&](int, double g) { total += g; });
    }
    // Its weights sum to the output area it stands for, so that an opaque surface's weights sum to
    // 1 in every pixel whatever the lens's magnification (its coverage, not more or less); its
    // light per unit weight is its radiance times the lens's throughput (the ray model's weights
    // are normalised so that the centre of a surface in focus keeps its radiance, as the scatter
    // method's light over coverage does).
    const double mass = n.count * static_cast<double>(e.area);
    sp.norm = total > 0.0 ? static_cast<float>(mass / total) : 0.0f;
    const double light = e.throughput / n.count;
    sp.r = static_cast<float>(light * n.r);
    sp.g = static_cast<float>(light * n.g);
    sp.bl = static_cast<float>(light * n.b);
    sp.inverse_depth = static_cast<float>(node_inverse);
    sp.blur = static_cast<float>(camera.signed_coc_px(node_inverse));
    sp.y0 = std::max(0, static_cast<int>(std::floor(sp.cy - reach_y)));
    sp.y1 = std::min(h - 1, static_cast<int>(std::ceil(sp.cy + reach_y)));
  }

  // Bands of rows, each with the splats that reach it (in splat order, so the sums are the same
  // whatever the threads).
  const int bands = std::max(1, std::min(h, threads * kBandsPerThread));
  std::vector<int> band_of_row(static_cast<std::size_t>(h));
  for (int b = 0; b < bands; ++b) {
    for (int y = b * h / bands; y < (b + 1) * h / bands; ++y) band_of_row[static_cast<std::size_t>(y)] = b;
  }
  // Counted, then placed: band b's splats are members[member_begin[b] .. member_begin[b + 1]).
  std::vector<std::size_t> member_begin(static_cast<std::size_t>(bands) + 1, 0);
  auto bands_of = [&](const Splat& sp) {
    if (sp.y1 < sp.y0 || !(sp.norm > 0.0f)) return std::array<int, 2>{1, 0};
    return std::array<int, 2>{band_of_row[static_cast<std::size_t>(sp.y0)], band_of_row[static_cast<std::size_t>(sp.y1)]};
  };
  for (const Splat& sp : splats) {
    const auto [b0, b1] = bands_of(sp);
    for (int b = b0; b <= b1; ++b) ++member_begin[static_cast<std::size_t>(b) + 1];
  }
  for (std::size_t b = 0; b < static_cast<std::size_t>(bands); ++b) member_begin[b + 1] += member_begin[b];
  LargeVector<std::uint32_t> members(member_begin.back());
  {
    std::vector<std::size_t> next(member_begin.begin(), member_begin.end() - 1);
    for (std::size_t k = 0; k < splats.size(); ++k) {
      const auto [b0, b1] = bands_of(splats[k]);
      for (int b = b0; b <= b1; ++b) members[next[static_cast<std::size_t>(b)]++] = static_cast<std::uint32_t>(k);
    }
  }

  Image out(w, h, 3);
  std::size_t writes = 0, overflow = 0, unfilled = 0;
  std::atomic<int> bands_done{0};
#pragma omp parallel num_threads(threads) reduction(+ : writes, overflow, unfilled)
  {
    const int max_rows = (h + bands - 1) / bands + 1;
    LargeVector<Fragment> fragments(static_cast<std::size_t>(max_rows) * static_cast<std::size_t>(w) * kFragments);
    std::vector<std::uint8_t> counts(static_cast<std::size_t>(max_rows) * static_cast<std::size_t>(w));
#pragma omp for schedule(dynamic, 1)
    for (int b = 0; b < bands; ++b) {
      const int row_begin = b * h / bands, row_end = (b + 1) * h / bands;
      std::fill(counts.begin(), counts.end(), std::uint8_t{0});
      for (std::size_t m = member_begin[static_cast<std::size_t>(b)]; m < member_begin[static_cast<std::size_t>(b) + 1]; ++m) {
        const Splat& s = splats[members[m]];
        for (int y = std::max(s.y0, row_begin); y <= std::min(s.y1, row_end - 1); ++y) {
          const std::size_t row = static_cast<std::size_t>(y - row_begin) * static_cast<std::size_t>(w);
          for_row(s, y, cut2, [&](int x, double g) {
            if (x < 0 || x >= w) return;
            const auto weight = static_cast<float>(s.norm * g);
            if (!(weight > 1e-7f)) return;
            ++writes;
            std::uint8_t& count = counts[row + static_cast<std::size_t>(x)];
            Fragment* f = fragments.data() + (row + static_cast<std::size_t>(x)) * kFragments;
            // The fragment of the same surface, or a new one, or (full) the nearest in blur.
            int best = -1;
            double best_gap = kInfinity;
            for (int j = 0; j < count; ++j) {
              const double gap = std::abs(static_cast<double>(f[j].blur) - s.blur);
              if (gap < best_gap) {
                best_gap = gap;
                best = j;
              }
            }
            if (best < 0 || !one_surface(f[best].blur, s.blur)) {
              if (count < kFragments) {
                f[count] = {0.0f, 0.0f, 0.0f, 0.0f, 0.0f, s.blur};
                best = count++;
              } else {
                ++overflow;
              }
            }
            Fragment& into = f[best];
            into.weight += weight;
            into.r += weight * s.r;
            into.g += weight * s.g;
            into.b += weight * s.bl;
            into.inverse_depth += weight * s.inverse_depth;
          });
        }
      }
      // Resolve: each pixel's fragments front to back (nearest first), each covering its summed
      // weight (at most 1); renormalised by what they cover together.
      for (int y = row_begin; y < row_end; ++y) {
        for (int x = 0; x < w; ++x) {
          const std::size_t local = static_cast<std::size_t>(y - row_begin) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x);
          const int count = counts[local];
          Fragment* f = fragments.data() + local * kFragments;
          std::sort(f, f + count, [](const Fragment& p, const Fragment& q) {
            return p.inverse_depth / p.weight > q.inverse_depth / q.weight;
          });
          double r = 0.0, g = 0.0, bl = 0.0, pass = 1.0;
          for (int j = 0; j < count && pass > 0.0; ++j) {
            const double alpha = std::min(1.0, static_cast<double>(f[j].weight));
            const double scale = pass * alpha / f[j].weight;
            r += scale * f[j].r;
            g += scale * f[j].g;
            bl += scale * f[j].b;
            pass *= 1.0 - alpha;
          }
          const double covered = 1.0 - pass;
          const std::size_t p = static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x);
          if (!(covered > 1e-6)) {
            ++unfilled;
            for (std::size_t c = 0; c < 3; ++c) out.data[3 * p + c] = image.data[3 * p + c];
            continue;
          }
          out.data[3 * p] = static_cast<float>(std::max(0.0, r / covered));
          out.data[3 * p + 1] = static_cast<float>(std::max(0.0, g / covered));
          out.data[3 * p + 2] = static_cast<float>(std::max(0.0, bl / covered));
        }
      }
      if (options.progress) {
        const double fraction = static_cast<double>(++bands_done) / bands;
#pragma omp critical(lensmith_ewa_progress)
        options.progress(fraction);
      }
    }
  }
  stats.pixel_writes = writes;
  stats.overflow_merges = overflow;
  stats.unfilled_pixels = unfilled;
  if (statistics) *statistics = stats;
  return out;
}

}  // namespace lensmith
