#include "mixed_pixels.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <span>

#include "first_touch.h"
#include "lensmith/core/units.h"

namespace lensmith::render_detail {

namespace {

// Neighbourhoods whose blur differs by less than this (px, signed CoC) hold no depth edge worth
// splitting at: the 2 px tent filter makes both parts land alike.
constexpr double kMinBlurDifferencePx = 1.0;
// Neighbours whose blur lies within this share of the range from its nearer or farther end (at
// least half of kMinBlurDifferencePx) stand for that surface.
constexpr double kEndShare = 0.15;
// Relative colour contrast |c_near - c_far| / (|c_near| + |c_far|) from which alpha comes wholly
// from colour, and below which wholly from depth (linear between).
constexpr double kColourContrastLow = 0.02;
constexpr double kColourContrastHigh = 0.10;
// Distance of the pixel's colour from the line through the two surfaces' colours, relative to their
// difference, up to which the two-colour model is trusted fully, and from which not at all (a
// textured surface whose neighbours do not describe the pixel).
constexpr double kFitResidualLow = 0.3;
constexpr double kFitResidualHigh = 0.6;
// Relative contrast |pixel - mix| / (|pixel| + |mix|) between a pixel and the best mix of the two
// surfaces' colours up to which the mix is trusted fully, and from which not at all: a pixel of the
// far surface beside a highlight on it (the highlight the only far neighbour not next to the step)
// lies beyond the near colour's end of the segment and is neither (tests/render/bokeh_edges_test.cpp).
constexpr double kModelContrastLow = 0.15;
constexpr double kModelContrastHigh = 0.3;
// A pixel at the near surface's depth that no mix explains and that is more than this many times
// as bright as either surface's colour holds light from behind the near surface's edge: a highlight
// mostly hidden behind a thin bar, a sliver of it in the bar's edge pixel. Kept whole, the sliver
// stayed a sharp bright dot on the bar; its light beyond the near colour goes to the far surface,
// where it blurs with the highlight's disc.
constexpr double kExcessBrightness = 2.0;
// The near part's coverage there, which no colour tells: a renderer's first sample, uniform over the
// pixel, names the near surface with probability equal to its coverage c, so a pixel that carries
// the near depth is covered E[c^2] / E[c] = 2/3 on average (c uniform).
constexpr double kExcessNearCoverage = 2.0 / 3.0;
// Near and far groups whose colours differ by less than this (relative contrast) look like one
// surface (decide() then looks one ring further out for the far one).
constexpr double kSameSurfaceContrast = 0.01;
// alpha within this of 0 or 1 is a pure pixel of one surface (noise of the colour estimate).
constexpr double kPureAlpha = 0.03;
// Passes that move pixels wholly to the surface their colour shows, before the split: a depth edge
// up to this many pixels beyond the colour edge (a grown or filtered depth) comes back to it, a pixel
// per pass, and one up to 2 px inside it (an eroded depth; see kSameSurfaceContrast). From 3 px inside
// it does not: those pixels see only the subject's colour within 2 px (tests/render/bokeh_edges_test.cpp).
constexpr int kMovePasses = 3;

// A surface on one side of a depth step: its colour, inverse depth (1/mm) and signed blur (px).
struct Surface {
  std::array<double, 3> rgb{};
  double inverse_depth_per_mm = 0.0;
  double coc_px = 0.0;
};

// The neighbours that stand for one surface, and their mean (Surface, after finish()).
struct Group : Surface {
  int count = 0;
  // The members' own colours (at most the 16 of a 5 x 5 border; a 3 x 3 has 8 neighbours). Only
  // the first stored() are read: not zeroed (four groups' 800 bytes in every decision).
  std::array<std::array<float, 3>, 16> members;
  int stored() const { return std::min(count, static_cast<int>(members.size())); }
  void add(const ScatterSource& s) {
    for (std::size_t c = 0; c < 3; ++c) rgb[c] += s.rgb[c];
    inverse_depth_per_mm += s.inverse_depth_per_mm;
    coc_px += s.coc_px;
    if (count < static_cast<int>(members.size())) members[static_cast<std::size_t>(count)] = s.rgb;
    ++count;
  }
  void finish() {
    for (double& v : rgb) v /= count;
    inverse_depth_per_mm /= count;
    coc_px /= count;
  }
};

double norm(const std::array<double, 3>& v) { return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

// Relative colour contrast of two colours: |a - b| / (|a| + |b|); of two surfaces, of their colours.
// (With their sizes |a| and |b| known.)
double contrast(const std::array<double, 3>& a, double a_norm, const std::array<double, 3>& b, double b_norm) {
  const double sum = a_norm + b_norm;
  return sum > 0.0 ? norm({a[0] - b[0], a[1] - b[1], a[2] - b[2]}) / sum : 0.0;
}
double contrast(const std::array<double, 3>& a, const std::array<double, 3>& b) { return contrast(a, norm(a), b, norm(b)); }
double contrast(const Surface& a, const Surface& b) { return contrast(a.rgb, b.rgb); }

// 1 up to `full`, 0 from `none`, linear between (either way round): how far a measure is trusted.
double ramp(double v, double full, double none) { return std::clamp((none - v) / (none - full), 0.0, 1.0); }

// How far two surfaces' colours of relative contrast c tell a pixel's coverage (kColourContrastLow..High).
double contrast_trust(double c) { return ramp(c, kColourContrastHigh, kColourContrastLow); }
// Squared contrasts that are clearly below kColourContrastLow and clearly above kColourContrastHigh
// (5 % off: far beyond the rounding of a root and a division), for tests without either.
constexpr double kSurelyLowContrast2 = (0.95 * kColourContrastLow) * (0.95 * kColourContrastLow);
constexpr double kSurelyHighContrast2 = (1.05 * kColourContrastHigh) * (1.05 * kColourContrastHigh);

double brightness(const std::array<float, 3>& c) { return static_cast<double>(c[0]) + c[1] + c[2]; }
double brightness(const std::array<double, 3>& c) { return c[0] + c[1] + c[2]; }

// Pairs explain the pixel about as well up to this share of its colour's size apart (the
// weights' spread in choose_colours).
constexpr double kMissShare = 0.1;

// The two surfaces' colours at pixel colour p: the pairs of a near and a far neighbour weighted by
// how nearly their segment passes p (a Gaussian in the distance beyond the nearest pair's, of width
// kMissShare |p|) and by how clearly they differ (the trust ramp of kColourContrastLow..High), then
// averaged; the groups' means where no pair differs. A group's mean stands for its surface only
// where the surface is one colour: a highlight among the far neighbours put their mean so far off
// that ordinary pixels of the far surface projected onto the near one, and moved there they came
// out sharp and dark over the highlight's blurred disc, each move pass taking the next ring of them
// (bench/blender's table scene: depth-edge band 32.6 -> 36.1 dB against the path-traced reference).
// Pairs of one colour are left out: a subject's pixels whose depth stops inside its silhouette are
// far neighbours of the subject's colour, and would explain a pixel of the subject as far. Weighted,
// not chosen, so that the colours move smoothly with the picture (a colour space's rounding changes
// no choice).
void choose_colours(const std::array<float, 3>& p, Group& near, Group& far) {
  struct Pair {
    std::array<double, 3> n, f;
    double miss, trust;
  };
  std::array<Pair, 16 * 16> pairs;
  std::size_t count = 0;
  double best = kInfinity;
  // The members' colours and their sizes, once (a pair's contrast needs both sizes).
  std::array<std::array<double, 3>, 16> far_rgb;
  std::array<double, 16> far_norm;
  for (std::size_t k = 0; k < static_cast<std::size_t>(far.stored()); ++k) {
    const auto& fk = far.members[k];
    far_rgb[k] = {fk[0], fk[1], fk[2]};
    far_norm[k] = norm(far_rgb[k]);
  }
  for (int j = 0; j < near.stored(); ++j) {
    const auto& nj = near.members[static_cast<std::size_t>(j)];
    const std::array<double, 3> n{nj[0], nj[1], nj[2]};
    const double n_norm = norm(n);
    for (std::size_t k = 0; k < static_cast<std::size_t>(far.stored()); ++k) {
      const std::array<double, 3>& f = far_rgb[k];
      // The pair's contrast |n - f| / (|n| + |f|) and its trust (contrast_trust), without a root or
      // a division where the contrast is clearly below kColourContrastLow (no trust) or above
      // kColourContrastHigh (full trust): the same values as computed in full. (With the span shared
      // by the projection below and by decide(), the edge stage of bench/blender's fence at 6 m,
      // 43 thousand decisions, went from 18.1 to 17.0 ms on one thread, best of 25.)
      const double sum = n_norm + far_norm[k];
      if (!(sum > 0.0)) continue;
      const std::array<double, 3> span{n[0] - f[0], n[1] - f[1], n[2] - f[2]};
      const double span2 = span[0] * span[0] + span[1] * span[1] + span[2] * span[2];
      const double sum2 = sum * sum;
      if (span2 <= kSurelyLowContrast2 * sum2) continue;
      const double trust = span2 >= kSurelyHighContrast2 * sum2 ? 1.0 : contrast_trust(std::sqrt(span2) / sum);
      if (!(trust > 0.0)) continue;
      // Where p projects on the segment from f to n (0 at f, clamped to it), and its distance from there.
      const std::array<double, 3> offset{p[0] - f[0], p[1] - f[1], p[2] - f[2]};
      const double t = std::clamp((offset[0] * span[0] + offset[1] * span[1] + offset[2] * span[2]) / span2, 0.0, 1.0);
      const double miss = norm({offset[0] - t * span[0], offset[1] - t * span[1], offset[2] - t * span[2]});
      pairs[count++] = {n, f, miss, trust};
      best = std::min(best, miss);
    }
  }
  if (count == 0) return;
  const double width = kMissShare * norm({p[0], p[1], p[2]});
  std::array<double, 3> n_sum{}, f_sum{};
  double w_sum = 0.0;
  for (std::size_t i = 0; i < count; ++i) {
    const Pair& q = pairs[i];
    const double excess = q.miss - best;
    if (excess > 0.0 && !(excess < 6.0 * width)) continue;  // a weight below 2e-8
    const double w = q.trust * (excess > 0.0 ? std::exp(-0.5 * excess * excess / (width * width)) : 1.0);
    for (std::size_t c = 0; c < 3; ++c) {
      n_sum[c] += w * q.n[c];
      f_sum[c] += w * q.f[c];
    }
    w_sum += w;
  }
  if (!(w_sum > 0.0)) return;
  for (std::size_t c = 0; c < 3; ++c) {
    near.rgb[c] = n_sum[c] / w_sum;
    far.rgb[c] = f_sum[c] / w_sum;
  }
}

// The pure pixels (not next to a depth step) on the 5 x 5 border around (x, y) whose blur `on_surface`
// accepts: a surface sampled one ring further out where the 3 x 3 cannot tell it.
// (`coc`: the sources' blurs packed, read before a source itself is.)
template <class OnSurface>
Group border_group(const ScatterSources& sources, const double* coc, const LargeVector<std::uint8_t>& next_to_step, int width, int height,
                   int x, int y, OnSurface on_surface) {
  Group g;
  for (int qy = std::max(0, y - 2); qy <= std::min(height - 1, y + 2); ++qy) {
    for (int qx = std::max(0, x - 2); qx <= std::min(width - 1, x + 2); ++qx) {
      if (std::max(std::abs(qx - x), std::abs(qy - y)) < 2) continue;
      const std::size_t q = static_cast<std::size_t>(qy) * width + qx;
      if (!next_to_step[q] && on_surface(coc[q])) g.add(sources[q]);
    }
  }
  return g;
}

// What to do with one pixel: nothing, move it wholly to one surface's depth, or split it.
struct Decision {
  enum class Kind { Keep, Move, Split } kind = Kind::Keep;
  double alpha = 1.0;  // coverage of the near part (Split)
  // Split: the near part takes the near surface's colour, the far part the rest of the light
  // (light from behind the near surface's edge; see kExcessBrightness).
  bool excess = false;
  Surface near, far;
};

// A pixel's step flags, from its own row's blurs (`mid`, px) and those of the rows above and below
// it, at columns l, x and r (x - 1 and x + 1 inside the frame): whether a 4-neighbour differs in
// blur by kMinBlurDifferencePx or more (such a pixel may be mixed itself, and decide() prefers
// neighbours that are not), and whether its 3 x 3 neighbourhood's blur spans that much (only there
// can decide() change anything). A row or column beyond the frame is given as the pixel's own,
// whose differences are 0 and whose extremes are the neighbourhood's own. No branches: a row of
// them vectorises.
inline void set_step_flags(const double* up, const double* mid, const double* down, int l, int x, int r, std::uint8_t& next_to_step,
                           std::uint8_t& spans) {
  const double c = mid[x];
  const bool beside = (std::abs(c - mid[l]) >= kMinBlurDifferencePx) | (std::abs(c - mid[r]) >= kMinBlurDifferencePx) |
                      (std::abs(c - up[x]) >= kMinBlurDifferencePx) | (std::abs(c - down[x]) >= kMinBlurDifferencePx);
  const double lo = std::min({up[l], up[x], up[r], mid[l], c, mid[r], down[l], down[x], down[r]});
  const double hi = std::max({up[l], up[x], up[r], mid[l], c, mid[r], down[l], down[x], down[r]});
  next_to_step = beside ? 1 : 0;
  spans = hi - lo >= kMinBlurDifferencePx ? 1 : 0;
}

// The step flags of pixel (x, y) of a width x height frame of blurs `coc`.
void set_step_flags_at(const double* coc, int width, int height, int x, int y, LargeVector<std::uint8_t>& next_to_step,
                       LargeVector<std::uint8_t>& spans) {
  const std::size_t row = static_cast<std::size_t>(y) * width;
  set_step_flags(coc + (y > 0 ? row - width : row), coc + row, coc + (y + 1 < height ? row + width : row), x > 0 ? x - 1 : x, x,
                 x + 1 < width ? x + 1 : x, next_to_step[row + x], spans[row + x]);
}

// (`coc`: the sources' blurs packed: the neighbourhoods are scanned for them, and only the
// neighbours that stand for a surface are read whole.)
Decision decide(const ScatterSources& sources, const double* coc, const LargeVector<std::uint8_t>& next_to_step, int width, int height,
                int x, int y) {
  const ScatterSource& p = sources[static_cast<std::size_t>(y) * width + x];
  Decision d;
  Group near, far;
  double lo = p.coc_px, hi = p.coc_px;
  const int x0 = std::max(0, x - 1), x1 = std::min(width - 1, x + 1);
  const int y0 = std::max(0, y - 1), y1 = std::min(height - 1, y + 1);
  for (int qy = y0; qy <= y1; ++qy) {
    for (int qx = x0; qx <= x1; ++qx) {
      const double c = coc[static_cast<std::size_t>(qy) * width + qx];
      lo = std::min(lo, c);
      hi = std::max(hi, c);
    }
  }
  if (hi - lo < kMinBlurDifferencePx) return d;
  // The two surfaces: the 8 neighbours at either end of the blur range (larger signed blur is
  // nearer: Camera::signed_coc_px grows with inverse depth). Neighbours between the ends (mixed
  // pixels of a filtered depth) describe neither.
  // Of those, the pure ones (not next to a depth step themselves) are preferred: a pixel next to
  // the step may be mixed too.
  const double tolerance = std::max(0.5 * kMinBlurDifferencePx, kEndShare * (hi - lo));
  Group near_pure, far_pure;
  for (int qy = y0; qy <= y1; ++qy) {
    for (int qx = x0; qx <= x1; ++qx) {
      if (qx == x && qy == y) continue;
      const std::size_t q = static_cast<std::size_t>(qy) * width + qx;
      if (coc[q] >= hi - tolerance) {
        near.add(sources[q]);
        if (!next_to_step[q]) near_pure.add(sources[q]);
      } else if (coc[q] <= lo + tolerance) {
        far.add(sources[q]);
        if (!next_to_step[q]) far_pure.add(sources[q]);
      }
    }
  }
  // A thin near structure (a bar, a wire: 1-3 px) has no pure pixel in the 3 x 3, and where a
  // highlight lies behind it, its edge pixels there hold the highlight's light: as the near colour
  // they made the highlight's own edge pixels look like the bar, which moved them onto it (sharp
  // bright dots on the bar). Where the 3 x 3's near pixels are more than kExcessBrightness times as
  // bright as the pure ones on the 5 x 5 border, the border's stand for the near surface.
  if (near_pure.count == 0 && near.count > 0) {
    const Group ring = border_group(sources, coc, next_to_step, width, height, x, y, [&](double c) { return c >= hi - tolerance; });
    // (Sums of colours: their means compared.)
    if (ring.count > 0 && brightness(near.rgb) / near.count > kExcessBrightness * brightness(ring.rgb) / ring.count) near_pure = ring;
  }
  if (near_pure.count > 0) near = near_pure;
  if (far_pure.count > 0) far = far_pure;
  if (near.count == 0 || far.count == 0) return d;  // a 1-px feature: nothing to unmix it with
  near.finish();
  far.finish();
  // A depth stopping inside the subject's silhouette (an eroded depth pass) leaves a pixel of the
  // subject with the far depth whose far neighbours are more of the same: both groups have one
  // colour, and the colour could not move it. Where they agree within kSameSurfaceContrast, the far
  // surface is sampled on the 5 x 5 border instead (pure pixels only), if that shows a clearly
  // different colour (kColourContrastHigh). A depth stopping 2 px inside then comes back to the
  // silhouette (tests/render/bokeh_edges_test.cpp); the Cycles street scene of docs/performance.md
  // moved 0.06 dB closer to its path-traced reference in the depth-edge band (a 2 % threshold here
  // cost it 0.04 dB).
  if (p.coc_px <= lo + tolerance && contrast(near, far) < kSameSurfaceContrast) {
    Group far_ring = border_group(sources, coc, next_to_step, width, height, x, y, [&](double c) { return c <= lo + tolerance; });
    if (far_ring.count > 0) {
      far_ring.finish();
      if (contrast(near, far_ring) >= kColourContrastHigh) far = far_ring;
    }
  }
  // alpha from depth: where the pixel's blur lies between the two surfaces'.
  const double alpha_depth = std::clamp((p.coc_px - far.coc_px) / (near.coc_px - far.coc_px), 0.0, 1.0);
  choose_colours(p.rgb, near, far);
  d.near = static_cast<const Surface&>(near);
  d.far = static_cast<const Surface&>(far);
  // alpha from colour: the projection on the segment from the far colour to the near one, trusted
  // where the colours differ clearly and the pixel lies near the line through them.
  const std::array<double, 3> span{near.rgb[0] - far.rgb[0], near.rgb[1] - far.rgb[1], near.rgb[2] - far.rgb[2]};
  double alpha = alpha_depth;
  bool excess = false;
  if (const double span2 = span[0] * span[0] + span[1] * span[1] + span[2] * span[2]; span2 > 0.0) {
    // Where p projects on the segment from the far colour to the near one, and its distance from
    // there (the span and its length computed once, for the surfaces' contrast too).
    const double span_length = std::sqrt(span2);
    const std::array<double, 3> offset{p.rgb[0] - far.rgb[0], p.rgb[1] - far.rgb[1], p.rgb[2] - far.rgb[2]};
    const double alpha_colour = std::clamp((offset[0] * span[0] + offset[1] * span[1] + offset[2] * span[2]) / span2, 0.0, 1.0);
    const double miss = norm({offset[0] - alpha_colour * span[0], offset[1] - alpha_colour * span[1], offset[2] - alpha_colour * span[2]});
    const double residual = miss / span_length;
    const double fit_trust = contrast_trust(span_length / (norm(near.rgb) + norm(far.rgb))) * ramp(residual, kFitResidualLow, kFitResidualHigh);
    const bool bright = alpha_depth >= 1.0 - kPureAlpha && brightness(p.rgb) > kExcessBrightness * std::max(brightness(near.rgb), brightness(far.rgb));
    // The mix that explains the pixel best, against the pixel itself: the residual above is relative
    // to the surfaces' difference, which a highlight on one of them makes so large that a pixel far
    // off both colours still fits. (Only where it can matter: a fit trusted at all, or a bright pixel.)
    double trust = 0.0;
    if (fit_trust > 0.0 || bright) {
      std::array<double, 3> model{};
      for (std::size_t c = 0; c < 3; ++c) model[c] = far.rgb[c] + alpha_colour * span[c];
      const double model_contrast = contrast({p.rgb[0], p.rgb[1], p.rgb[2]}, model);
      trust = fit_trust * ramp(model_contrast, kModelContrastLow, kModelContrastHigh);
      excess = bright && model_contrast > kModelContrastHigh;
    }
    alpha = trust * alpha_colour + (1.0 - trust) * alpha_depth;
  }
  if (excess) {
    d.kind = Decision::Kind::Split;
    d.alpha = kExcessNearCoverage;
    d.excess = true;
    return d;
  }
  if (alpha < kPureAlpha) alpha = 0.0;
  if (alpha > 1.0 - kPureAlpha) alpha = 1.0;
  d.alpha = alpha;
  if (alpha > 0.0 && alpha < 1.0) {
    d.kind = Decision::Kind::Split;
  } else {
    // Wholly one surface: move it there if its depth says otherwise.
    const Surface& own = alpha == 1.0 ? near : far;
    if (std::abs(p.coc_px - own.coc_px) >= 0.5 * kMinBlurDifferencePx) d.kind = Decision::Kind::Move;
  }
  return d;
}

// The part of `p` on surface `g`: its own depth if it lies on that surface, else the surface's.
void place_on(ScatterSource& part, const ScatterSource& p, const Surface& g, const Camera& camera) {
  if (std::abs(p.coc_px - g.coc_px) < 0.5 * kMinBlurDifferencePx) return;
  part.inverse_depth_per_mm = g.inverse_depth_per_mm;
  part.coc_px = camera.signed_coc_px(g.inverse_depth_per_mm);
}

// Pixel p moved wholly to the surface its decision names.
void move(ScatterSource& p, const Decision& d, const Camera& camera) { place_on(p, p, d.alpha == 1.0 ? d.near : d.far, camera); }

// Pixel p split: the near part replaces it, the far part goes to `far`.
void split(ScatterSource& p, const Decision& d, const Camera& camera, ScatterSource& far) {
  // Near part: the pixel less the far surface's share; the far part what remains, so the two add
  // up to the pixel exactly.
  const ScatterSource whole = p;
  ScatterSource near = whole;
  far = whole;
  for (std::size_t c = 0; c < 3; ++c) {
    near.rgb[c] = d.excess ? static_cast<float>(std::min<double>(whole.rgb[c], d.alpha * d.near.rgb[c]))
                           : static_cast<float>(std::max(0.0, whole.rgb[c] - (1.0 - d.alpha) * d.far.rgb[c]));
    far.rgb[c] = whole.rgb[c] - near.rgb[c];
  }
  near.coverage = static_cast<float>(d.alpha);
  far.coverage = static_cast<float>(1.0 - d.alpha);
  place_on(near, whole, d.near, camera);
  place_on(far, whole, d.far, camera);
  p = near;
}

}  // namespace

void split_mixed_pixels(ScatterSources& sources, int width, int height, const Camera& camera, int threads,
                        BokehStatistics& stats) {
  const std::size_t pixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  // The pixels' blurs packed, and per pixel whether it is next to a depth step and whether its
  // neighbourhood spans one. Only the pixels that span one are decided (a few per cent of a
  // frame); after each pass the flags are brought up to date around the pixels it moved.
  // (The blurs written in full by the threads, not zeroed first on one.)
  const std::unique_ptr<double[]> coc_store(new double[pixels]);
  const std::span<double> coc(coc_store.get(), pixels);
  LargeVector<std::uint8_t> next_to_step(pixels), spans(pixels);
  // Per row, where its spanning pixels start among the frame's (entry y; the count in the last).
  std::vector<std::uint32_t> row_begin(static_cast<std::size_t>(height) + 1, 0);
#pragma omp parallel for num_threads(threads) schedule(static)
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * width + x;
      coc[i] = sources[i].coc_px;
    }
  }
#pragma omp parallel for num_threads(threads) schedule(static)
  for (int y = 0; y < height; ++y) {
    const std::size_t row = static_cast<std::size_t>(y) * width;
    for (const int x : {0, width - 1}) set_step_flags_at(coc.data(), width, height, x, y, next_to_step, spans);
    // Inside the first and last columns, the columns beside are the frame's own.
    const double* up = coc.data() + (y > 0 ? row - width : row);
    const double* mid = coc.data() + row;
    const double* down = coc.data() + (y + 1 < height ? row + width : row);
    std::uint8_t* step = next_to_step.data() + row;
    std::uint8_t* span = spans.data() + row;
    for (int x = 1; x + 1 < width; ++x) set_step_flags(up, mid, down, x - 1, x, x + 1, step[x], span[x]);
    std::uint32_t count = 0;
    for (int x = 0; x < width; ++x) count += span[x];
    row_begin[static_cast<std::size_t>(y) + 1] = count;
  }
  for (std::size_t y = 0; y < static_cast<std::size_t>(height); ++y) row_begin[y + 1] += row_begin[y];
  // Each pass decides from the sources as they were at its start, so decisions do not depend on
  // the order of the pixels. A pixel's decision reads its 5 x 5 neighbourhood and their step flags
  // (one more ring): one whose 7 x 7 neighbourhood no pass has moved a pixel of since the previous
  // pass keeps that pass's decision instead of deciding again (bench/blender's fence scene focused
  // on its wall at 6 m decides 40 186 pixels, then 2 207, 601 and 188 again: this stage took 34 ms
  // and now 19, medians of 9). Per row, every spanning pixel's decision by column. Those that change
  // something are applied after the pass: its moves in row order, the last pass's splits and moves
  // row by row in parallel.
  // The first pass decides every spanning pixel: its decisions and its rows' lists lie in two
  // frame-wide arrays, each row's at row_begin (made once, filled by the threads: as a vector per
  // row, 800 blocks of the heap were allocated by the threads at once, the allocator's lock
  // contended). Later passes decide a few pixels of a few rows again: those decisions are appended
  // to their row's own pool (`later`), and a changed row's list is made in one of the row's two
  // stores, the one its previous list is not in. Lists name decisions by index: below kLater in the
  // first pass's array, from kLater in the row's pool (a decision kept from the previous pass is not
  // copied: 112 bytes each, the fence's 40 thousand of them in each of three passes).
  // A list entry: a spanning pixel's column, its decision and that decision's kind (read by every
  // pass's bookkeeping: from the decisions, 104 bytes apart, they were a cache miss each).
  struct Decided {
    int x;
    std::uint32_t at;
    Decision::Kind kind;
  };
  constexpr std::uint32_t kLater = 1u << 31;
  const std::size_t spanning = row_begin.back();
  WriteFirstArray<Decision> first_pool(spanning);
  WriteFirstArray<Decided> first_lists(spanning);
  const std::span<Decision> first_decisions = first_pool.first(spanning, threads);
  const std::span<Decided> first_entries = first_lists.first(spanning, threads);
  std::vector<std::vector<Decision>> later(static_cast<std::size_t>(height));
  const auto decision_at = [&](std::size_t y, std::uint32_t at) -> const Decision& {
    return at < kLater ? first_decisions[at] : later[y][at - kLater];
  };
  struct RowList {
    const Decided* data = nullptr;
    std::size_t size = 0;
    int store = -1;  // where it lies: -1 the first pass's array, 0 or 1 the row's stores
    std::span<const Decided> entries() const { return {data, size}; }
  };
  std::vector<RowList> decided(static_cast<std::size_t>(height)), previous(decided.size());
  std::array<std::vector<std::vector<Decided>>, 2> stores{std::vector<std::vector<Decided>>(decided.size()),
                                                          std::vector<std::vector<Decided>>(decided.size())};
  LargeVector<std::uint8_t> unchanged(pixels, 0);  // since the previous pass
  std::vector<std::size_t> moved;
  // Per row, whether a pixel within 3 rows moved in the previous pass (all rows at first): a row
  // where none did keeps its whole list, as deciding it again would (its pixels' neighbourhoods and
  // flags are as they were). The fence at 6 m has 40 thousand decisions in its first pass and about
  // 150 moves: its later passes looked at every one of them.
  std::vector<std::uint8_t> row_changed(static_cast<std::size_t>(height), 1);
  // Per row, its splits (entry y + 1), made prefix sums in the last pass: where its far parts go.
  std::vector<std::size_t> row_splits(static_cast<std::size_t>(height) + 1, 0);
  for (int pass = 0; pass <= kMovePasses; ++pass) {
    const bool last = pass == kMovePasses;
    std::size_t moves_decided = 0;
    decided.swap(previous);
#pragma omp parallel for num_threads(threads) schedule(dynamic, 16) reduction(+ : moves_decided)
    for (int y = 0; y < height; ++y) {
      const auto u = static_cast<std::size_t>(y);
      RowList& row = decided[u];
      const RowList& before = previous[u];
      std::size_t splits = 0;
      const auto count_kinds = [&](std::span<const Decided> entries) {
        for (const Decided& e : entries) {
          moves_decided += e.kind == Decision::Kind::Move ? 1 : 0;
          splits += e.kind == Decision::Kind::Split ? 1 : 0;
        }
      };
      if (!row_changed[u]) {
        row = before;
        count_kinds(row.entries());
        row_splits[u + 1] = splits;
        continue;
      }
      const std::size_t row_start = u * static_cast<std::size_t>(width);
      if (pass == 0) {
        std::uint32_t at = row_begin[u];
        for (int x = 0; x < width; ++x) {
          if (!spans[row_start + x]) continue;  // decide() would keep it
          first_decisions[at] = decide(sources, coc.data(), next_to_step, width, height, x, y);
          first_entries[at] = {x, at, first_decisions[at].kind};
          ++at;
        }
        row = {first_entries.data() + row_begin[u], row_begin[u + 1] - row_begin[u], -1};
        count_kinds(row.entries());
        row_splits[u + 1] = splits;
        continue;
      }
      const int store = before.store == 0 ? 1 : 0;
      std::vector<Decided>& list = stores[static_cast<std::size_t>(store)][u];
      list.clear();
      const std::span<const Decided> old = before.entries();
      std::size_t k = 0;  // the previous pass's decision at or after column x
      for (int x = 0; x < width; ++x) {
        if (!spans[row_start + x]) continue;  // decide() would keep it
        while (k < old.size() && old[k].x < x) ++k;
        // (A pixel whose neighbourhood is unchanged spanned a step then too: its spans flag did not change.)
        if (unchanged[row_start + x] && k < old.size() && old[k].x == x) {
          list.push_back(old[k]);
        } else {
          later[u].push_back(decide(sources, coc.data(), next_to_step, width, height, x, y));
          list.push_back({x, kLater + static_cast<std::uint32_t>(later[u].size() - 1), later[u].back().kind});
        }
      }
      row = {list.data(), list.size(), store};
      count_kinds(row.entries());
      row_splits[u + 1] = splits;
    }
    if (last) {
      // The splits, row by row in parallel (each reads and writes only its own pixel): the far parts
      // appended in row order, each row's after the rows before it.
      for (std::size_t y = 0; y < static_cast<std::size_t>(height); ++y) row_splits[y + 1] += row_splits[y];
      const std::size_t first_far = sources.size();
      fault_in(sources, first_far + row_splits.back(), threads);
      sources.resize(first_far + row_splits.back());
      std::size_t splits = 0, moves = 0;
#pragma omp parallel for num_threads(threads) schedule(dynamic, 16) reduction(+ : splits, moves)
      for (int y = 0; y < height; ++y) {
        std::size_t far = first_far + row_splits[static_cast<std::size_t>(y)];
        for (const Decided& e : decided[static_cast<std::size_t>(y)].entries()) {
          if (e.kind == Decision::Kind::Keep) continue;
          const Decision& d = decision_at(static_cast<std::size_t>(y), e.at);
          ScatterSource& p = sources[static_cast<std::size_t>(y) * width + e.x];
          if (d.kind == Decision::Kind::Move) {
            move(p, d, camera);
            ++moves;
          } else if (d.kind == Decision::Kind::Split) {
            split(p, d, camera, sources[far++]);
            ++splits;
          }
        }
      }
      stats.split_edge_pixels += splits;
      stats.redepthed_edge_pixels += moves;
      break;
    }
    // The moves of this pass (a few), in row order.
    moved.clear();
    for (int y = 0; y < height; ++y) {
      for (const Decided& e : decided[static_cast<std::size_t>(y)].entries()) {
        if (e.kind != Decision::Kind::Move) continue;
        const Decision& d = decision_at(static_cast<std::size_t>(y), e.at);
        const std::size_t i = static_cast<std::size_t>(y) * width + e.x;
        move(sources[i], d, camera);
        ++stats.redepthed_edge_pixels;
        moved.push_back(i);
      }
    }
    for (const std::size_t i : moved) coc[i] = sources[i].coc_px;
    std::fill(unchanged.begin(), unchanged.end(), std::uint8_t{1});
    std::fill(row_changed.begin(), row_changed.end(), std::uint8_t{0});
    // A moved pixel's blur enters its 4-neighbours' step flags and its 3 x 3 neighbours' spans, and
    // its colour and depth the decisions of its 7 x 7 neighbours.
    for (const std::size_t i : moved) {
      const int x = static_cast<int>(i % static_cast<std::size_t>(width)), y = static_cast<int>(i / static_cast<std::size_t>(width));
      for (int qy = std::max(0, y - 1); qy <= std::min(height - 1, y + 1); ++qy) {
        for (int qx = std::max(0, x - 1); qx <= std::min(width - 1, x + 1); ++qx) {
          set_step_flags_at(coc.data(), width, height, qx, qy, next_to_step, spans);
        }
      }
      for (int qy = std::max(0, y - 3); qy <= std::min(height - 1, y + 3); ++qy) {
        std::uint8_t* r = unchanged.data() + static_cast<std::size_t>(qy) * width;
        std::fill(r + std::max(0, x - 3), r + std::min(width, x + 4), std::uint8_t{0});
        row_changed[static_cast<std::size_t>(qy)] = 1;
      }
    }
    if (moves_decided == 0) pass = kMovePasses - 1;  // nothing moved: go to the split
  }
}

}  // namespace lensmith::render_detail
