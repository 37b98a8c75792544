#include "footprint.h"

#include <algorithm>
#include <cmath>
#include <span>
#include <utility>

#include "lensmith/core/units.h"

namespace lensmith::render_detail {

namespace {

// A model is treated as affine over a footprint when no probe ray departs from the affine map
// through three of them by more than this (px).
constexpr double kAffineTolerancePx = 0.25;
// Meshes add this share of their size to the tent's margin around the probed footprint (footprint.h)
// for the parts between probe rays.
constexpr double kMeshMarginFraction = 0.25;
// Rings of a polar mesh per pixel of footprint size: models that clip at real clear apertures
// (exact, poly) need rings fine enough for a vignetted beam's edge (at least 4, one per 6 px);
// the others one ring per 16 px carries the radial light distribution.
constexpr double kMinClippingRings = 4.0;
constexpr double kPxPerClippingRing = 6.0;
constexpr double kPxPerRing = 16.0;
// Adjacent rings of a mapped pupil mesh whose light densities differ by less than this share of the
// largest are deposited as one (a 2 % step in a large disc is below what a picture shows).
constexpr double kRingMergeTolerance = 0.02;
// Share of the chromatic tolerance over which a footprint's light is cross-faded from n - 1 to n
// wavelength groups (FootprintScatter::plan): the points there deposit both splits.
constexpr double kGroupBlend = 0.25;
// Stamps (footprint_stamps.h) are made for scales up to half the full-resolution grid's largest
// footprint plus this (px): a footprint's planned size is its probe's extent, which for an outline
// with no vertex at the probe's directions is a little less than twice its scale.
constexpr double kStampMarginPx = 2.0;
// A footprint is drawn from a stamp where its centre lies within this of its pixel's centre and its
// map from the pupil has no shear beyond it (px): a thin lens's are zero to rounding.
constexpr double kStampPlacementPx = 1e-4;
// A mapped ring that turns back in y by at most this (px) is made y-monotone (untangle_ring): the
// same quarter pixel under which the planner calls aberrations invisible (kAffineTolerancePx).
constexpr double kUntangleTolerancePx = 0.25;
// A mapped ring may reach this far (px) beyond the next ring out and still count as nested (float
// rounding of points a few hundred px from the origin is 1e-5 px). Any more lets crossing rings
// through: a white wall at 2.6 m through the Biotar at f/1.44 focused at 1.5 m came out between
// 0.91 and 1.12 with 0.05 px plus 1 % of the ring's size allowed, between 0.97 and 1.04 with this;
// the README job's picture is the same bit for bit either way.
constexpr double kNestingTolerancePx = 1e-3;
// Ring deposits of footprints up to this size (px) keep the light centroid of the triangles between
// their mapped points, and from kEdgeKeptPx their outermost ring's edge (deposit_nested_rings).
constexpr double kCentroidKeptPx = 4.0;
constexpr double kEdgeKeptPx = 8.0;
// Reusing a mapped shape along a row (FootprintScatter::plan_range): pixels probed at least every
// kShapeStride; those between draw the first's shape where every probe ray of both ends lies within
// kShapeTolerancePx of where the other's puts it (relative to their chief rays: a sixteenth of a pixel,
// below the quarter-pixel sub-rows a footprint's own polygons are scanned at), and where the depth
// varies along the run, their passing shares agree to kShapePassingTolerance (of the whole beam).
constexpr std::size_t kShapeStride = 8;
constexpr double kShapeTolerancePx = 1.0 / 16.0;
constexpr float kShapePassingTolerance = 0.004f;
// Light images (FootprintScatter::make_light_image). Cells of 0.5 px (of a grid cell at a coarse
// level), halved down to 0.125 while
// the footprint spans fewer than kLightImageCellsAcross of them: interpolating the samples blurs by
// about a cell, which against the output's 1 px tent showed on small footprints (tests/render's
// three-depth frame through the double Gauss against per-pixel rays: 41.2 dB at 0.5 px, 47.6 at
// 0.25, 50.7 at 0.125). At most kMaxLightImageCells along a side (a larger footprint keeps its
// mesh). Footprints under kDenseLightImagePx wide are kept as points (LightImage::dense says why).
constexpr double kMaxLightImageCellPx = 0.5;
constexpr double kMinLightImageCellPx = 0.125;
constexpr double kLightImageCellsAcross = 64.0;
constexpr int kMaxLightImageCells = 512;
constexpr double kDenseLightImagePx = 6.0;
// A dense image whose samples over a turned grid of pixels sum to 1 within this is drawn as sampled,
// else normalised (LightImage::normalise).
constexpr double kLatticeRipple = 1e-3;
// Depth steps of the images per step of the table's nodes (1 px of blur): a footprint takes the
// nearest image, whose size is then within 1/8 px of its own. Cross-fading the two images around it
// at the nodes' own step softened its edge (the depth-staircase scene against the ground truth,
// 320 x 180: 37.17 dB cross-faded at 1 px steps, 37.43 nearest at 1/4 px).
constexpr int kLightImageDepthSteps = 4;
// A thread's cache of light images (FootprintScratch::light_images): 2^14 slots, 384 KiB; with 2^10
// two threads spent 10 % of an exact 1080p render in the shared lock behind it and the table's.
constexpr int kLightImageCacheBits = 14;
// Grid cells of an aperture-picture mesh per pixel of footprint size.
constexpr double kPxPerGridCell = 1.5;
// Pupil points: the centre (the chief ray), and the centre with the two axes' unit points (an affine
// model's map); the unit value a footprint's shape is recorded at (FootprintShape).
constexpr std::array<PupilPoint, 1> kCentre{{{0.0, 0.0}}};
constexpr std::array<PupilPoint, 3> kBasis{{{0.0, 0.0}, {1.0, 0.0}, {0.0, 1.0}}};
constexpr std::array<float, 4> kUnit{1.0f, 1.0f, 1.0f, 1.0f};
// Footprint heights (grid cells, with margins) from which half and a quarter of the sub-rows are used
// for its own polygons (footprint_subrows).
constexpr float kMediumFootprintPx = 10.0f;
constexpr float kTallFootprintPx = 34.0f;

std::array<float, 4> group_value(const ScatterSource& s, const SpectralGroup& g, float share, const FootprintPlan& p, bool vignetting);

// Whether the pupil's centre (the chief ray) passes every disc: the passing region, an intersection
// of convex sets around it, is then star-shaped about it.
bool centre_passes(const std::vector<PupilDisc>& discs) {
  for (const PupilDisc& d : discs) {
    if (d.x * d.x + d.y * d.y >= d.radius * d.radius) return false;
  }
  return true;
}

// For each vertex direction u of an outline (from the centre), how far along u the discs'
// intersection reaches, in units of the vertex's own distance: min over the discs of the root s > 0
// of |s u - c| = rho. The centre must pass every disc. Disc by disc over all vertices, so that the
// inner loop vectorises.
// Built for AVX2+FMA too (four square roots at a time) and chosen at load time, like
// SplatBuffer::add_polygon: it measured 15 % of a paraxial 1080p render.
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
__attribute__((target_clones("arch=x86-64-v3", "default")))
#endif
void disc_reach(const PupilMeshTable::Directions& u, const std::vector<PupilDisc>& discs, std::vector<double>& reach) {
  const std::size_t n = u.ux.size();
  reach.assign(n, kInfinity);
  const double* ux = u.ux.data();
  const double* uy = u.uy.data();
  double* r = reach.data();
  for (const PupilDisc& d : discs) {
    const double cx = d.x, cy = d.y, c = d.x * d.x + d.y * d.y - d.radius * d.radius;
    for (std::size_t j = 0; j < n; ++j) {
      const double b = ux[j] * cx + uy[j] * cy;
      r[j] = std::min(r[j], b + std::sqrt(b * b - c));
    }
  }
  for (std::size_t j = 0; j < n; ++j) r[j] *= u.inverse_length[j];
}

// The outline scaled by `scale`, less what lies beyond the discs' reach along each vertex direction:
// with the centre inside every disc, the passing part of a star-shaped outline is star-shaped too,
// and its radius along each direction is the smaller of the two.
void reach_clip(const std::vector<PupilPoint>& outline, double scale, const std::vector<double>& reach, std::vector<PupilPoint>& out) {
  out.resize(outline.size());
  for (std::size_t j = 0; j < outline.size(); ++j) {
    const double f = std::min(scale, reach[j]);
    out[j] = {outline[j].x * f, outline[j].y * f};
  }
}

}  // namespace

double FootprintScatter::disc_passing_share(const std::vector<PupilDisc>& discs, int own_step, FootprintScratch& scratch) const {
  // Measured on an outline of at least kShareSectorStep's vertices: a coarse one would misjudge how
  // much of the circle a disc cuts off (an octagon by up to 10 %). With the chief ray inside every
  // disc the cut is radial (cheap); otherwise the polygon is clipped disc by disc.
  const int share_step = std::max(own_step, PupilMeshTable::kShareSectorStep);
  const std::vector<PupilPoint>& share_outline = meshes_.dense_outline(share_step);
  const PupilMeshTable::Directions& u = meshes_.dense_directions(share_step);
  if (centre_passes(discs)) {
    // The outline cut radially: its area from the scale factors along each direction.
    disc_reach(u, discs, scratch.reach);
    const std::size_t n = scratch.reach.size();
    double area = 0.0;
    for (std::size_t j = 0, k = n - 1; j < n; k = j++) {
      area += std::min(1.0, scratch.reach[k]) * std::min(1.0, scratch.reach[j]) * u.half_cross[k];
    }
    return area / u.area;
  }
  clip_pupil_polygon(share_outline, discs, scratch.clipped, scratch.clip_work);
  return scratch.clipped.size() < 3 ? 0.0 : pupil_polygon_area(scratch.clipped) / u.area;
}

namespace {

// A ring's topmost and bottommost vertices (the first of each where several are at that height).
std::pair<std::size_t, std::size_t> ring_ends(std::span<const Point2f> ring) {
  std::size_t top = 0, bottom = 0;
  for (std::size_t i = 1; i < ring.size(); ++i) {
    if (ring[i].y < ring[top].y) top = i;
    if (ring[i].y > ring[bottom].y) bottom = i;
  }
  return {top, bottom};
}

// Whether a ring that rises and falls once in y (two chains from its topmost to its bottommost
// vertex) is simple: its two chains must not cross. One that does is a figure eight (a near-focus
// beam with coma and astigmatism maps a pupil ring so), whose signed area, the difference of its
// two lobes, can be near zero: spread over that area its light would become large positive and
// negative densities. Each chain vertex strictly between the ends is compared with the other chain
// at its height; both walks are monotone in y, so O(vertices).
// `ends`: ring_ends(ring).
bool monotone_ring_is_simple(std::span<const Point2f> ring, std::pair<std::size_t, std::size_t> ends) {
  const std::size_t n = ring.size();
  const auto [top, bottom] = ends;
  const double y_top = ring[top].y, y_bottom = ring[bottom].y;
  auto next = [n](std::size_t i, bool forward) { return forward ? (i + 1 == n ? 0 : i + 1) : (i == 0 ? n - 1 : i - 1); };
  int side = 0;  // the sign of (this chain's x - the other's) seen so far
  for (const bool forward : {true, false}) {
    // `other` walks the opposite chain, staying on the edge that spans the current height.
    std::size_t other = top;
    for (std::size_t i = next(top, forward); i != bottom; i = next(i, forward)) {
      const double y = ring[i].y;
      if (!(y > y_top && y < y_bottom)) continue;
      while (static_cast<double>(ring[next(other, !forward)].y) < y) other = next(other, !forward);
      const Point2f& a = ring[other];
      const Point2f& b = ring[next(other, !forward)];
      const double t = b.y > a.y ? (y - a.y) / (static_cast<double>(b.y) - a.y) : 0.0;
      const double dx = ring[i].x - (a.x + t * (static_cast<double>(b.x) - a.x));
      const int s = (dx > 0.0) - (dx < 0.0);
      // Measured from the forward chain: the backward chain's differences count with their sign flipped.
      const int from_forward = forward ? s : -s;
      if (from_forward == 0) continue;
      if (side == 0) side = from_forward;
      if (from_forward != side) return false;
    }
  }
  return true;
}

// One side of a y-monotone ring: its vertices from the topmost to the bottommost, walking forward
// (increasing index) or backward. `x_range(y)` gives the chain's x at height y, queried at
// non-decreasing heights (a cursor walks the chain once): both ends of a horizontal run at that
// height, the single crossing elsewhere.
class RingChain {
 public:
  RingChain(std::span<const Point2f> ring, std::size_t top, std::size_t bottom, bool forward)
      : ring_(ring), top_(top), bottom_(bottom), forward_(forward), at_(top) {}
  std::size_t next(std::size_t i) const {
    const std::size_t n = ring_.size();
    return forward_ ? (i + 1 == n ? 0 : i + 1) : (i == 0 ? n - 1 : i - 1);
  }
  std::size_t top() const { return top_; }
  std::size_t bottom() const { return bottom_; }
  const Point2f& operator[](std::size_t i) const { return ring_[i]; }
  void rewind() { at_ = top_; }
  std::pair<double, double> x_range(double y) {
    while (at_ != bottom_ && static_cast<double>(ring_[next(at_)].y) < y) at_ = next(at_);
    const Point2f& a = ring_[at_];
    if (at_ == bottom_) return {a.x, a.x};
    std::size_t b = next(at_);
    if (static_cast<double>(ring_[b].y) > y) {
      if (static_cast<double>(a.y) >= y) return {a.x, a.x};
      const double t = (y - a.y) / (static_cast<double>(ring_[b].y) - a.y);
      const double x = a.x + t * (static_cast<double>(ring_[b].x) - a.x);
      return {x, x};
    }
    // A run of vertices at exactly this height (from `a` where it is at it too).
    double lo = ring_[b].x, hi = lo;
    if (static_cast<double>(a.y) == y) lo = std::min(lo, static_cast<double>(a.x)), hi = std::max(hi, static_cast<double>(a.x));
    while (b != bottom_ && static_cast<double>(ring_[next(b)].y) == y) {
      b = next(b);
      lo = std::min(lo, static_cast<double>(ring_[b].x));
      hi = std::max(hi, static_cast<double>(ring_[b].x));
    }
    return {lo, hi};
  }

 private:
  std::span<const Point2f> ring_;
  std::size_t top_, bottom_;
  bool forward_;
  std::size_t at_;
};

// Whether chain `left` lies nowhere more than `tolerance` (px) to the right of chain `right` over
// the heights both span. Both are piecewise linear in y, so their difference is largest at a vertex
// of one of them: each chain's vertices are compared with the other chain at their heights, the
// other's horizontal runs counted in the comparison's favour.
bool chain_left_of(RingChain& left, RingChain& right, double tolerance) {
  const double y_from = std::max(left[left.top()].y, right[right.top()].y);
  const double y_to = std::min(left[left.bottom()].y, right[right.bottom()].y);
  left.rewind();
  right.rewind();
  for (std::size_t i = left.top();; i = left.next(i)) {
    const double y = left[i].y;
    if (y >= y_from && y <= y_to && left[i].x > right.x_range(y).second + tolerance) return false;
    if (i == left.bottom()) break;
  }
  left.rewind();
  for (std::size_t i = right.top();; i = right.next(i)) {
    const double y = right[i].y;
    if (y >= y_from && y <= y_to && left.x_range(y).first > right[i].x + tolerance) return false;
    if (i == right.bottom()) break;
  }
  return true;
}

// Whether y-monotone simple ring `inner` lies within ring `outer`, but for `tolerance` (px): within
// its span of heights, and at every height between its left and right chains. Two rings of the same
// orientation whose areas grow can still cross (near a caustic, a larger ring mapped off to one
// side): their differences, deposited as ring polygons, would then be negative densities, dark and
// bright crescents where a uniform wall is seen through the Biotar wide open in colour.
// `inner_ends` and `outer_ends`: ring_ends of each.
bool ring_within(std::span<const Point2f> inner, std::pair<std::size_t, std::size_t> inner_ends, std::span<const Point2f> outer,
                 std::pair<std::size_t, std::size_t> outer_ends, double orientation, double tolerance) {
  const auto [in_top, in_bottom] = inner_ends;
  const auto [out_top, out_bottom] = outer_ends;
  if (inner[in_top].y < outer[out_top].y - tolerance || inner[in_bottom].y > outer[out_bottom].y + tolerance) return false;
  // Walking forward from the top, a ring of positive shoelace orientation (y pointing down) goes
  // down its right side.
  const bool forward_is_right = orientation > 0.0;
  RingChain in_left(inner, in_top, in_bottom, !forward_is_right), in_right(inner, in_top, in_bottom, forward_is_right);
  RingChain out_left(outer, out_top, out_bottom, !forward_is_right), out_right(outer, out_top, out_bottom, forward_is_right);
  return chain_left_of(out_left, in_left, tolerance) && chain_left_of(in_right, out_right, tolerance);
}

// A mapped ring whose y turns back by at most kUntangleTolerancePx along its way from its topmost to
// its bottommost vertex, made y-monotone by raising each such vertex to the lowest y its chain has
// reached (it moves by no more than that): the fitted Seidel model maps a pupil ring clipped to a
// cat's eye with a small loop near each cusp (0.05-0.25 px in a 4-11 px in-focus footprint through
// bench/bokeh_bench's double Gauss at f/2), which sent 13 % of its footprints to 18 triangles each
// instead of one ring polygon. A ring that turns back further (a crescent) is left as it is.
void untangle_ring(std::span<Point2f> ring) {
  const std::size_t n = ring.size();
  if (n < 3) return;
  const auto [top, bottom] = ring_ends(ring);
  auto next = [n](std::size_t i, bool forward) { return forward ? (i + 1 == n ? 0 : i + 1) : (i == 0 ? n - 1 : i - 1); };
  float worst = 0.0f;
  for (const bool forward : {true, false}) {
    float reached = ring[top].y;
    for (std::size_t i = next(top, forward); i != bottom; i = next(i, forward)) {
      reached = std::max(reached, ring[i].y);
      worst = std::max(worst, reached - ring[i].y);
    }
  }
  if (!(worst > 0.0f) || worst > static_cast<float>(kUntangleTolerancePx)) return;
  for (const bool forward : {true, false}) {
    float reached = ring[top].y;
    for (std::size_t i = next(top, forward); i != bottom; i = next(i, forward)) {
      reached = std::max(reached, ring[i].y);
      ring[i].y = reached;
    }
  }
}

// The mapped ring polygons (ring k is points [ring_range(k).first, ring_range(k).second)) copied to
// scratch.ring_points, untangled (untangle_ring), as scratch.ring_spans: the triangles keep the
// mapped points as they are.
template <typename RingEnd>
void untangled_ring_spans(const std::vector<Point2f>& points, int rings, RingEnd&& ring_range, FootprintScratch& scratch) {
  scratch.ring_points.assign(points.begin(), points.end());
  scratch.ring_spans.clear();
  for (int k = 1; k <= rings; ++k) {
    const auto [begin, end] = ring_range(k);
    const std::span<Point2f> ring(scratch.ring_points.data() + begin, end - begin);
    untangle_ring(ring);
    scratch.ring_spans.emplace_back(ring.data(), ring.size());
  }
}

// Nested ring polygons of any vertex counts (rings[k - 1], mapped to the output) with the pupil
// areas they enclose (pupil_areas[k], pupil_areas[0] = 0) and their rays' mean radiometric weights
// (ring_weights[k], [0] the centre ray's): annulus k carries the light of its pupil area over
// `full_pupil_area` (so what first-order vignetting cuts off is missing) and the coverage of its
// pupil area over the ring set's (an opaque point, however vignetted), spread evenly over its mapped
// area. Rings are merged where the densities differ by less than kRingMergeTolerance. Returns false,
// depositing nothing, where the mapped rings are not nested or one crosses itself (a fold or
// caustic).
// Whether mapped ring polygons nest, each y-monotone and simple (what deposit_nested_rings needs);
// their enclosed areas into `areas` (areas[0] = 0).
bool rings_nest(const std::vector<std::span<const Point2f>>& rings, std::vector<double>& areas, bool shapes_checked = false) {
  const int count = static_cast<int>(rings.size());
  areas.assign(static_cast<std::size_t>(count) + 1, 0.0);
  double orientation = 0.0;
  std::pair<std::size_t, std::size_t> inner_ends{0, 0};  // ring k - 1's, for the nesting check
  for (int k = 1; k <= count; ++k) {
    const std::span<const Point2f> ring = rings[static_cast<std::size_t>(k - 1)];
    const std::size_t n = ring.size();
    double twice = 0.0;
    for (std::size_t j = 0, i = n - 1; j < n; i = j++) {
      twice += static_cast<double>(ring[i].x) * ring[j].y - static_cast<double>(ring[j].x) * ring[i].y;
    }
    if (k == 1) orientation = twice < 0.0 ? -1.0 : 1.0;
    // Only y-monotone rings (one rise and one fall of y around them). A mapped ring that turns back
    // in y (a strongly aberrated or clipped beam, a crescent: a 35 mm lens's frame corners) goes to
    // the triangles although SplatBuffer fills it exactly: spread evenly over a crescent, the light
    // leaves from the wrong place (its thin horns get as much as its middle). Tried: the README main
    // job's vertical mortar lines kinked by a pixel where footprints turned into crescents, and it
    // moved 0.3 dB away from the exact model, for 13 % of its time.
    if (!shapes_checked) {
      int turns = 0;
      double last_dy = 0.0;
      for (std::size_t j = 0; j <= n; ++j) {
        const std::size_t a = j == n ? 0 : j, b = a + 1 == n ? 0 : a + 1;
        const double dy = static_cast<double>(ring[b].y) - ring[a].y;
        if (dy == 0.0) continue;
        if (last_dy != 0.0 && (dy > 0.0) != (last_dy > 0.0)) ++turns;
        last_dy = dy;
      }
      const std::pair<std::size_t, std::size_t> ends = ring_ends(ring);
      if (turns > 2 || !monotone_ring_is_simple(ring, ends)) return false;
      if (k > 1 && !ring_within(rings[static_cast<std::size_t>(k - 2)], inner_ends, ring, ends, orientation, kNestingTolerancePx)) return false;
      inner_ends = ends;
    }
    const double area = 0.5 * twice * orientation;
    if (!(area > areas[static_cast<std::size_t>(k) - 1] + 1e-3 * std::max(area, 1e-9))) return false;
    areas[static_cast<std::size_t>(k)] = area;
  }
  return true;
}

// The triangles between a footprint's pupil rings: a fan from the centre (point 0), then two per
// cell between rings; rings have `n` vertices each, ring k's from ring_begin(k). Calls
// triangle(a, b, c, pupil_area) for each, in that order.
template <typename Pupil, typename RingBegin, typename Triangle>
void for_each_ring_triangle(const Pupil& pupil, int rings, std::size_t n, RingBegin&& ring_begin, Triangle&& triangle) {
  auto visit = [&](std::size_t a, std::size_t b, std::size_t c) {
    triangle(a, b, c,
             0.5 * std::abs((pupil[b].x - pupil[a].x) * (pupil[c].y - pupil[a].y) - (pupil[c].x - pupil[a].x) * (pupil[b].y - pupil[a].y)));
  };
  for (int k = 1; k <= rings; ++k) {
    const std::size_t outer = ring_begin(k);
    for (std::size_t j = 0; j < n; ++j) {
      const std::size_t j1 = j + 1 == n ? 0 : j + 1;
      if (k == 1) {
        visit(0, outer + j, outer + j1);
        continue;
      }
      const std::size_t inner = ring_begin(k - 1);
      visit(inner + j, outer + j, outer + j1);
      visit(inner + j, outer + j1, inner + j1);
    }
  }
}

// The centroid (px) of the light of the triangles between a footprint's mapped rings
// (for_each_ring_triangle; what deposit_clipped_rings would deposit): each carries its pupil area
// (times its rays' mean radiometric weight when `weighted`) at its mapped corners' mean. False where
// no triangle has pupil area.
template <typename Pupil, typename RingBegin>
bool fan_light_centroid(const Pupil& pupil, const std::vector<Point2f>& points, const std::vector<SensorHit>& hits, int rings,
                        std::size_t n, RingBegin&& ring_begin, bool weighted, double& cx, double& cy) {
  double sx = 0.0, sy = 0.0, total = 0.0;
  for_each_ring_triangle(pupil, rings, n, ring_begin, [&](std::size_t a, std::size_t b, std::size_t c, double area) {
    const double w = weighted ? area * (hits[a].weight + hits[b].weight + hits[c].weight) : area;
    sx += w * (static_cast<double>(points[a].x) + points[b].x + points[c].x);
    sy += w * (static_cast<double>(points[a].y) + points[b].y + points[c].y);
    total += w;
  });
  if (!(total > 0.0)) return false;
  cx = sx / (3.0 * total);
  cy = sy / (3.0 * total);
  return std::isfinite(cx) && std::isfinite(cy);
}

// Centroid of a simple polygon (px), by the shoelace formula; false for one without area.
bool polygon_centroid(std::span<const Point2f> ring, double& cx, double& cy) {
  double twice = 0.0, sx = 0.0, sy = 0.0;
  const double x0 = ring[0].x, y0 = ring[0].y;  // about its first vertex, for rounding
  for (std::size_t j = 0; j < ring.size(); ++j) {
    const Point2f& a = ring[j];
    const Point2f& b = ring[j + 1 == ring.size() ? 0 : j + 1];
    const double ax = a.x - x0, ay = a.y - y0, bx = b.x - x0, by = b.y - y0;
    const double cross = ax * by - bx * ay;
    twice += cross;
    sx += (ax + bx) * cross;
    sy += (ay + by) * cross;
  }
  if (!(std::abs(twice) > 0.0)) return false;
  cx = x0 + sx / (3.0 * twice);
  cy = y0 + sy / (3.0 * twice);
  return true;
}

// `light_centroid(cx, cy)` gives the centroid of the light of the triangles between the same mapped
// points (fan_light_centroid), or false.
template <typename LightCentroid>
bool deposit_nested_rings(const std::vector<std::span<const Point2f>>& rings, const std::vector<double>& pupil_areas,
                          const std::vector<double>& ring_weights, double full_pupil_area, const std::array<float, 4>& value,
                          bool weighted, LightCentroid&& light_centroid, FootprintShape& out, int subrows, bool shapes_checked,
                          FootprintScratch& scratch) {
  std::vector<double>& areas = scratch.areas;
  if (!rings_nest(rings, areas, shapes_checked)) return false;
  const int count = static_cast<int>(rings.size());
  const double pupil_total = pupil_areas[static_cast<std::size_t>(count)];
  auto pupil = [&](int k) { return pupil_areas[static_cast<std::size_t>(k)] - pupil_areas[static_cast<std::size_t>(k) - 1]; };
  auto area = [&](int k) { return areas[static_cast<std::size_t>(k)] - areas[static_cast<std::size_t>(k) - 1]; };
  auto light = [&](int k) {
    const double weight = weighted ? 0.5 * (ring_weights[static_cast<std::size_t>(k) - 1] + ring_weights[static_cast<std::size_t>(k)]) : 1.0;
    return pupil(k) / (weighted ? full_pupil_area : pupil_total) * weight / area(k);
  };
  auto coverage = [&](int k) { return pupil(k) / pupil_total / area(k); };
  double max_light = 0.0, max_coverage = 0.0;
  for (int k = 1; k <= count; ++k) {
    max_light = std::max(max_light, std::abs(light(k)));
    max_coverage = std::max(max_coverage, coverage(k));
  }
  // The ring polygons to deposit and their light and coverage, outermost first.
  std::vector<FootprintScratch::RingDeposit>& deposits = scratch.ring_deposits;
  deposits.clear();
  int outer = count;
  double group_light = light(count) * area(count), group_coverage = coverage(count) * area(count);
  double next_light = 0.0, next_coverage = 0.0;
  for (int k = count - 1; k >= 0; --k) {
    const double group_area = areas[static_cast<std::size_t>(outer)] - areas[static_cast<std::size_t>(k)];
    const double dl = group_light / group_area, dc = group_coverage / group_area;
    if (k > 0 && std::abs(light(k) - dl) <= kRingMergeTolerance * max_light &&
        std::abs(coverage(k) - dc) <= kRingMergeTolerance * max_coverage) {
      group_light += light(k) * area(k);
      group_coverage += coverage(k) * area(k);
      continue;
    }
    deposits.push_back({outer, areas[static_cast<std::size_t>(outer)] * (dl - next_light),
                        areas[static_cast<std::size_t>(outer)] * (dc - next_coverage)});
    next_light = dl;
    next_coverage = dc;
    if (k > 0) {
      outer = k;
      group_light = light(k) * area(k);
      group_coverage = coverage(k) * area(k);
    }
  }
  // Spread evenly over each annulus, light varying around a ring (coma's flare) is averaged, and the
  // light's centroid moves towards the rings' centres: at comatic highlights near focus through the
  // Canon 35 mm wide open by 0.2-0.3 px. A small footprint's rings are moved by the difference to the
  // centroid the triangles between the same mapped points give, so that the deposit keeps it. Only
  // where the footprint is small enough that its light's centroid, not its edge, is what shows: a
  // large defocused disc's edge is its outermost ring's, where the model maps it, and moved with the
  // centroid of a comatic light distribution, the edges moved away from the exact tracer's
  // (pbrt-dgauss-50mm at f/2 on the bundled scene: 41.81 -> 39.85 dB). Fully below kCentroidKeptPx,
  // not at all from kEdgeKeptPx, blended in between (no seam).
  float x_min = rings.back()[0].x, x_max = x_min, y_min = rings.back()[0].y, y_max = y_min;
  for (const Point2f& q : rings.back()) {
    x_min = std::min(x_min, q.x);
    x_max = std::max(x_max, q.x);
    y_min = std::min(y_min, q.y);
    y_max = std::max(y_max, q.y);
  }
  const double size = std::max(x_max - x_min, y_max - y_min);
  const double keep = std::clamp((kEdgeKeptPx - size) / (kEdgeKeptPx - kCentroidKeptPx), 0.0, 1.0);
  double dx = 0.0, dy = 0.0, tx = 0.0, ty = 0.0;
  if (keep > 0.0 && light_centroid(tx, ty)) {
    double sx = 0.0, sy = 0.0, total = 0.0;
    bool ok = true;
    for (const FootprintScratch::RingDeposit& d : deposits) {
      double cx = 0.0, cy = 0.0;
      ok = ok && polygon_centroid(rings[static_cast<std::size_t>(d.ring) - 1], cx, cy);
      sx += d.light * cx;
      sy += d.light * cy;
      total += d.light;
    }
    if (ok && total > 0.0) {
      dx = keep * (tx - sx / total);
      dy = keep * (ty - sy / total);
      if (!(std::isfinite(dx) && std::isfinite(dy))) dx = dy = 0.0;
    }
  }
  const auto fx = static_cast<float>(dx), fy = static_cast<float>(dy);
  for (const FootprintScratch::RingDeposit& d : deposits) {
    std::span<const Point2f> ring = rings[static_cast<std::size_t>(d.ring) - 1];
    if (fx != 0.0f || fy != 0.0f) {
      scratch.moved.resize(ring.size());
      for (std::size_t j = 0; j < ring.size(); ++j) scratch.moved[j] = {ring[j].x + fx, ring[j].y + fy};
      ring = scratch.moved;
    }
    const auto f = static_cast<float>(d.light);
    const auto c = static_cast<float>(d.coverage);
    out.add(ring, {value[0] * f, value[1] * f, value[2] * f, value[3] * c}, subrows);
  }
  return true;
}

// A polar mesh mapped without folds deposits as nested rings (deposit_nested_rings): annulus k
// carries its share of the pupil, (2k - 1) / R^2, spread evenly over its mapped area. As the
// scatter is linear, annulus k is ring polygon k at density d_k minus ring polygon k-1 at d_k, so
// ring polygon k is deposited once with area * (d_k - d_(k+1)): R polygons at O(height) each
// instead of 2 R S small triangles. The radial light distribution (spherical aberration's bright
// or dark rims) is kept; light varying around a ring (coma's flare) is averaged over each annulus.
// Returns false, depositing nothing, when a ray is lost or the rings are not nested (a fold or
// caustic): the caller then uses the triangles.
// The mesh's ring polygons of mapped `points` as spans in scratch.ring_spans, and their pupil areas
// and mean weights; false where a ray is lost.
bool mesh_ring_spans(const PupilMesh& mesh, const std::vector<SensorHit>& hits, const std::vector<Point2f>& points,
                     FootprintScratch& scratch) {
  for (const SensorHit& h : hits) {
    if (!h.ok) return false;
  }
  const int rings = mesh.rings;
  const auto sectors = static_cast<std::size_t>(mesh.sectors);
  auto ring_range = [sectors](int k) {
    const std::size_t begin = 1 + static_cast<std::size_t>(k - 1) * sectors;
    return std::pair{begin, begin + sectors};
  };
  untangled_ring_spans(points, rings, ring_range, scratch);
  scratch.pupil_areas.assign(1, 0.0);
  scratch.ring_weights.assign(1, hits[0].weight);
  for (int k = 1; k <= rings; ++k) {
    const std::size_t begin = ring_range(k).first;
    scratch.pupil_areas.push_back(static_cast<double>(k) * k / (static_cast<double>(rings) * rings));
    double sum = 0.0;
    for (std::size_t i = begin; i < begin + sectors; ++i) sum += hits[i].weight;
    scratch.ring_weights.push_back(sum / static_cast<double>(sectors));
  }
  return true;
}

bool deposit_ring_polygons(const PupilMesh& mesh, const std::vector<SensorHit>& hits, const std::vector<Point2f>& points,
                           const std::array<float, 4>& value, bool weighted, FootprintShape& out, int subrows, bool shapes_checked,
                           FootprintScratch& scratch) {
  if (!mesh_ring_spans(mesh, hits, points, scratch)) return false;
  const auto sectors = static_cast<std::size_t>(mesh.sectors);
  auto centroid = [&](double& cx, double& cy) {
    return fan_light_centroid(mesh.points, points, hits, mesh.rings, sectors,
                              [sectors](int k) { return 1 + static_cast<std::size_t>(k - 1) * sectors; }, weighted, cx, cy);
  };
  return deposit_nested_rings(scratch.ring_spans, scratch.pupil_areas, scratch.ring_weights, 1.0, value, weighted, centroid,
                              out, subrows, shapes_checked, scratch);
}

}  // namespace

bool FootprintScatter::clip_rings(const FootprintPlan& p, FootprintScratch& scratch) const {
  const PupilMesh& mesh = meshes_.mesh(p.mesh);
  const std::vector<PupilPoint>& outline = meshes_.dense_outline(PupilMeshTable::sector_step_of_mesh(p.mesh));
  const int rings = mesh.rings;
  // The rings of the pupil mesh (the outline scaled by k / R) less what the discs cut off, with the
  // centre first; each ring's vertices follow one another in scratch.ring_pupil.
  std::vector<PupilPoint>& pupil = scratch.ring_pupil;
  pupil.assign(1, PupilPoint{0.0, 0.0});
  scratch.ring_offsets.assign(1, 1);
  scratch.pupil_areas.assign(1, 0.0);
  // Rings must nest around the centre: a centre ray that is cut off (the beam's pupil off the axis)
  // leaves it to the triangles. Otherwise ring k reaches the smaller of k / R and the discs' reach
  // along each vertex direction.
  if (!centre_passes(scratch.discs)) return false;
  disc_reach(meshes_.dense_directions(PupilMeshTable::sector_step_of_mesh(p.mesh)), scratch.discs, scratch.reach);
  // The rings span what passes: where the discs cut every direction short of the rim (a lens opened
  // beyond its clear apertures), ring R is the passing region's outline and the others scale to
  // its largest reach, so that no two rings clip to the same polygon (which would read as a fold).
  double widest = 0.0;
  for (double r : scratch.reach) widest = std::max(widest, r);
  const double span = std::min(1.0, widest);
  for (int k = 1; k <= rings; ++k) {
    reach_clip(outline, span * k / rings, scratch.reach, scratch.clipped);
    pupil.insert(pupil.end(), scratch.clipped.begin(), scratch.clipped.end());
    scratch.ring_offsets.push_back(pupil.size());
    scratch.pupil_areas.push_back(pupil_polygon_area(scratch.clipped));
  }
  return true;
}

void FootprintScatter::map_set(const ScenePoint& point, double wavelength_nm, int set, std::span<const PupilPoint> pupil,
                               std::span<SensorHit> hits, FootprintScratch& scratch) const {
  if (table_) {
    table_->map(point, wavelength_nm, set, pupil, hits, scratch.table_cache);
  } else {
    model_.map(point, wavelength_nm, pupil, hits);
  }
}

void FootprintScatter::map_cached(const ScenePoint& point, double wavelength_nm, int set, int mesh, std::span<const PupilPoint> pupil,
                                  std::vector<SensorHit>& hits, FootprintScratch& scratch, bool keep) const {
  for (std::size_t i = 0; i < scratch.cached_count; ++i) {
    const FootprintScratch::CachedMap& c = scratch.cached_maps[i];
    if (c.set == set && c.wavelength_nm == wavelength_nm && c.hits.size() == pupil.size()) {
      hits.assign(c.hits.begin(), c.hits.end());
      return;
    }
  }
  hits.resize(pupil.size());
  if (set == 0) {
    map_set(point, wavelength_nm, mesh, pupil, hits, scratch);
  } else {
    model_.map_passing(point, wavelength_nm, pupil, hits);
  }
  if (!keep) return;
  if (scratch.cached_count == scratch.cached_maps.size()) scratch.cached_maps.emplace_back();
  FootprintScratch::CachedMap& c = scratch.cached_maps[scratch.cached_count++];
  c.wavelength_nm = wavelength_nm;
  c.set = set;
  c.hits.assign(hits.begin(), hits.end());
}

void FootprintScatter::map_clipped_rings(const ScenePoint& point, double wavelength_nm, const FootprintPlan& p,
                                         FootprintScratch& scratch, bool keep) const {
  const int rings = meshes_.mesh(p.mesh).rings;
  const std::vector<PupilPoint>& pupil = scratch.ring_pupil;
  std::vector<SensorHit>& hits = scratch.hits;
  map_cached(point, wavelength_nm, 1, -1, pupil, hits, scratch, keep);
  std::vector<Point2f>& points = scratch.points;
  points.resize(pupil.size());
  for (std::size_t i = 0; i < pupil.size(); ++i) {
    const PixelPoint q = camera_.output_pixel(hits[i].x_mm, hits[i].y_mm);
    points[i] = {static_cast<float>(q.x), static_cast<float>(q.y)};
  }
  auto ring_range = [&scratch](int k) {
    return std::pair{scratch.ring_offsets[static_cast<std::size_t>(k) - 1], scratch.ring_offsets[static_cast<std::size_t>(k)]};
  };
  untangled_ring_spans(points, rings, ring_range, scratch);
  scratch.ring_weights.assign(1, hits[0].weight);
  for (int k = 1; k <= rings; ++k) {
    const auto [begin, end] = ring_range(k);
    double sum = 0.0;
    for (std::size_t i = begin; i < end; ++i) sum += hits[i].weight;
    scratch.ring_weights.push_back(sum / static_cast<double>(end - begin));
  }
}

void FootprintScatter::deposit_clipped_rings(const ScenePoint& point, double wavelength_nm, const FootprintPlan& p, double passing,
                                             bool allow_rings, bool shapes_checked, const std::array<float, 4>& value,
                                             FootprintShape& out, int ring_subrows, FootprintScratch& scratch,
                                             std::size_t& triangles) const {
  const int rings = meshes_.mesh(p.mesh).rings;
  const std::vector<PupilPoint>& outline = meshes_.dense_outline(PupilMeshTable::sector_step_of_mesh(p.mesh));
  const std::vector<PupilPoint>& pupil = scratch.ring_pupil;
  map_clipped_rings(point, wavelength_nm, p, scratch);
  const std::vector<SensorHit>& hits = scratch.hits;
  const std::vector<Point2f>& points = scratch.points;
  // The light of the whole aperture in the rings' units, such that what they enclose passes the
  // dense outline's share: a coarse outline's chords cut a cat's eye's cusps by a few per cent
  // more than the iris's, and where neighbouring points' outlines switched from 16 to 24 vertices
  // a uniform defocused sky showed a line.
  const double full_pupil_area = scratch.pupil_areas.back() / passing;
  auto ring_begin = [&scratch](int k) { return scratch.ring_offsets[static_cast<std::size_t>(k) - 1]; };
  auto centroid = [&](double& cx, double& cy) {
    return fan_light_centroid(pupil, points, hits, rings, outline.size(), ring_begin, options_.vignetting, cx, cy);
  };
  if (allow_rings && deposit_nested_rings(scratch.ring_spans, scratch.pupil_areas, scratch.ring_weights, full_pupil_area,
                                          value, options_.vignetting, centroid, out, ring_subrows, shapes_checked, scratch)) {
    return;
  }
  // The same clipped rings as triangles (for_each_ring_triangle; every ring has the outline's vertex
  // count). Each carries its own pupil area's light and
  // coverage, so that the beam keeps its clipped shape: the mesh's triangles, clipped in place by
  // interpolated clearances, would spread a coarse mesh's edge cells over their unclipped images,
  // and where neighbouring sources switch between the two the sky showed seams.
  const double pupil_total = scratch.pupil_areas.back();
  if (!(pupil_total > 0.0)) return;
  const double light_area = options_.vignetting ? full_pupil_area : pupil_total;
  for_each_ring_triangle(pupil, rings, outline.size(), ring_begin, [&](std::size_t a, std::size_t b, std::size_t c, double area) {
    if (!(area > 0.0)) return;
    const double weight = options_.vignetting ? (hits[a].weight + hits[b].weight + hits[c].weight) / 3.0 : 1.0;
    const auto f = static_cast<float>(area / light_area * weight);
    const auto cover = static_cast<float>(area / pupil_total);
    const std::array<Point2f, 3> corners{points[a], points[b], points[c]};
    out.add(corners, {value[0] * f, value[1] * f, value[2] * f, value[3] * cover}, 0);
    ++triangles;
  });
}

std::array<float, 4> FootprintScatter::lit(const std::array<float, 4>& value, double weight) const {
  if (!options_.vignetting) return value;
  const auto w = static_cast<float>(weight);
  return {value[0] * w, value[1] * w, value[2] * w, value[3]};
}

FootprintScatter::FootprintScatter(const RayModel& model, const Aperture& aperture, const SpectralGroups& groups,
                                   const PupilMeshTable& meshes, const ImageAreaTable& areas, const IlluminationTable& illumination,
                                   const BokehOptions& options)
    : model_(model), camera_(model.camera()), aperture_(aperture), groups_(groups), meshes_(meshes), options_(options),
      stamps_(meshes, 0.5 * kHalfResolutionPx + kStampMarginPx), areas_(areas), illumination_(illumination), images_(kLightImageCacheBits) {
  if (options.interpolated_rays && MappedPupilTable::applies(model, aperture)) table_ = std::make_unique<MappedPupilTable>(model);
  {
    const PixelPoint o = camera_.output_pixel(0.0, 0.0), ex = camera_.output_pixel(1.0, 0.0), ey = camera_.output_pixel(0.0, 1.0);
    px_per_mm_ = {ex.x - o.x, ey.x - o.x, ex.y - o.y, ey.y - o.y};
  }
  probe_[0] = {0.0, 0.0};
  for (int k = 0; k < 8; ++k) {
    const double a = kPi / 2.0 + 2.0 * kPi * k / 8.0;
    const double r = aperture_.kind() == Aperture::Kind::Mask ? 1.0 : aperture_.edge_radius(a);
    probe_[static_cast<std::size_t>(k) + 1] = {r * std::cos(a), r * std::sin(a)};
    probe_directions_.ux.push_back(std::cos(a));
    probe_directions_.uy.push_back(std::sin(a));
    probe_directions_.inverse_length.push_back(1.0 / r);
  }
}

void FootprintScatter::forget_light_images() const { images_.clear(); }

// The footprint of `node` (a point on the table's x axis) as the mesh path would draw it: its mesh's
// cells recorded as record_mesh records them, deposited into a buffer of cells (a fraction of a
// pixel) around its chief ray, and kept per unit of light, as samples filtered by the output's tent
// (dense) or as the cells' light (points).
LightImage FootprintScatter::make_light_image(int mesh, const ScenePoint& node, double wavelength_nm, int level,
                                              FootprintScratch& scratch) const {
  LightImage image;
  FootprintPlan q;
  q.mesh = mesh;
  scratch.discs.clear();
  scratch.cached_count = 0;
  scratch.shape.clear();
  std::size_t triangles = 0;
  record_mesh(node, wavelength_nm, q, false, false, options_.splat.subrows, scratch, triangles);
  const FootprintShape& shape = scratch.shape;
  if (shape.mesh_sets.empty() || shape.mesh_sets.back().cell_count == 0) return image;
  std::array<SensorHit, 1> chief{};
  map_set(node, wavelength_nm, MappedPupilTable::kCentreSet, kCentre, chief, scratch);
  if (!(chief[0].ok || chief[0].unclipped)) return image;
  const PixelPoint c = camera_.output_pixel(chief[0].x_mm, chief[0].y_mm);
  const FootprintShape::MeshSet& set = shape.mesh_sets.back();
  const std::span<const MeshCell> cells(shape.mesh_cells.data() + set.cell_begin, set.cell_count);
  double x_min = kInfinity, x_max = -kInfinity, y_min = kInfinity, y_max = -kInfinity;
  for (const MeshCell& cell : cells) {
    for (std::uint32_t k = 0; k < cell.corners; ++k) {
      const Point2f& v = shape.points[cell.corner[k]];
      x_min = std::min(x_min, v.x - c.x);
      x_max = std::max(x_max, v.x - c.x);
      y_min = std::min(y_min, v.y - c.y);
      y_max = std::max(y_max, v.y - c.y);
    }
  }
  // Cells of a power of two of a pixel (the filter below), finer for smaller footprints; the chief
  // ray on a cell's centre (a point-like footprint's light stays where it lands); a margin for the
  // output's tent (1 px beyond the mesh, for a dense image) or the cells' own (one cell).
  const double extent = std::max(x_max - x_min, y_max - y_min);
  image.extent_px = extent;
  level = std::min(level, grid_level(extent));
  image.level = level;
  const double grid_cell = 1 << level;
  double cell = kMaxLightImageCellPx * grid_cell;
  while (cell > kMinLightImageCellPx * grid_cell && extent < kLightImageCellsAcross * cell) cell *= 0.5;
  image.cell_px = static_cast<float>(cell);
  image.dense = level > 0 || extent >= kDenseLightImagePx;
  const double margin = image.dense ? 2.0 * grid_cell : 2.0 * cell;
  const double ox = -cell * (std::ceil((margin - x_min) / cell) + 0.5), oy = -cell * (std::ceil((margin - y_min) / cell) + 0.5);
  const int nx = static_cast<int>(std::ceil((x_max + margin - ox) / cell)) + 1;
  const int ny = static_cast<int>(std::ceil((y_max + margin - oy) / cell)) + 1;
  if (!(nx >= 2 && ny >= 2 && nx <= kMaxLightImageCells && ny <= kMaxLightImageCells)) return image;
  std::vector<Point2f> local(shape.points.size());
  for (std::size_t i = 0; i < local.size(); ++i) {
    local[i] = {static_cast<float>((shape.points[i].x - c.x - ox) / cell), static_cast<float>((shape.points[i].y - c.y - oy) / cell)};
  }
  SplatOptions o;
  o.subrows = options_.splat.subrows;
  SplatBuffer buffer(nx, 0, ny, o);
  buffer.add_mesh(local, std::span(shape.mesh_edges).subspan(set.edge_begin, set.edge_count), cells, kUnit);
  std::vector<float> rgba(static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny) * 4, 0.0f);
  buffer.resolve_into(rgba.data());
  const auto w = static_cast<std::size_t>(nx);
  const auto h = static_cast<std::size_t>(ny);
  double total = 0.0;
  for (std::size_t i = 0; i < w * h; ++i) total += rgba[i * 4];
  if (!(total > 0.0)) return image;
  image.origin_x = static_cast<float>(ox + 0.5 * cell);
  image.origin_y = static_cast<float>(oy + 0.5 * cell);
  if (!image.dense) {
    for (std::size_t y = 0; y < h; ++y) {
      for (std::size_t x = 0; x < w; ++x) {
        const double e = rgba[(y * w + x) * 4] / total;
        if (e > 0.0) {
          image.points.push_back({static_cast<float>(image.origin_x + static_cast<double>(x) * cell),
                                  static_cast<float>(image.origin_y + static_cast<double>(y) * cell), static_cast<float>(e)});
        }
      }
    }
    image.ok = true;
    return image;
  }
  // Each cell holds the light of a tent one cell wide around it; the output pixels' tent (the grid
  // cells' at a coarse level) is that tent convolved, along each axis, with the triangle of weights
  // (n - |k|) / n^2 at cell steps k (n cells a pixel or grid cell), exactly: a box of 1 px is n boxes
  // of one cell. Weighted (n - |k|) / n: the light an output pixel (grid cell) centred on the cell
  // would receive.
  const int n = static_cast<int>(std::lround(grid_cell / cell));
  // The triangle as two boxes of n cells, one ending at the cell and one starting there (running
  // sums: O(cells) whatever n), scaled by 1/n.
  std::vector<double> line(std::max(w, h) + 2 * static_cast<std::size_t>(n), 0.0), boxed(line.size(), 0.0);
  auto triangle = [n, &line, &boxed](auto&& get, auto&& put, std::size_t count) {
    std::fill(line.begin(), line.end(), 0.0);
    for (std::size_t i = 0; i < count; ++i) line[i + static_cast<std::size_t>(n)] = get(i);
    const std::size_t m = count + 2 * static_cast<std::size_t>(n);
    double run = 0.0;
    for (std::size_t i = 0; i < m; ++i) {  // boxed[i] = line[i - n + 1] + ... + line[i]
      run += line[i] - (i >= static_cast<std::size_t>(n) ? line[i - static_cast<std::size_t>(n)] : 0.0);
      boxed[i] = run;
    }
    run = 0.0;
    for (std::size_t i = m; i-- > 0;) {  // out[i] = boxed[i] + ... + boxed[i + n - 1]
      run += boxed[i] - (i + static_cast<std::size_t>(n) < m ? boxed[i + static_cast<std::size_t>(n)] : 0.0);
      if (i >= static_cast<std::size_t>(n) && i < count + static_cast<std::size_t>(n)) put(i - static_cast<std::size_t>(n), run / n);
    }
  };
  std::vector<double> along(w * h, 0.0), both(w * h, 0.0);
  for (std::size_t y = 0; y < h; ++y) {
    triangle([&](std::size_t x) { return static_cast<double>(rgba[(y * w + x) * 4]); }, [&](std::size_t x, double v) { along[y * w + x] = v; }, w);
  }
  for (std::size_t x = 0; x < w; ++x) {
    triangle([&](std::size_t y) { return along[y * w + x]; }, [&](std::size_t y, double v) { both[y * w + x] = v; }, h);
  }
  // Cropped to the samples with light and a border of zeros (which bilinear interpolation needs at
  // the edge of what it draws).
  std::size_t x0 = w, x1 = 0, y0 = h, y1 = 0;
  for (std::size_t y = 0; y < h; ++y) {
    for (std::size_t x = 0; x < w; ++x) {
      if (!(both[y * w + x] > 0.0)) continue;
      x0 = std::min(x0, x);
      x1 = std::max(x1, x);
      y0 = std::min(y0, y);
      y1 = std::max(y1, y);
    }
  }
  x0 = x0 > 0 ? x0 - 1 : 0;
  y0 = y0 > 0 ? y0 - 1 : 0;
  x1 = std::min(w - 1, x1 + 1);
  y1 = std::min(h - 1, y1 + 1);
  const std::size_t cw = x1 - x0 + 1, ch = y1 - y0 + 1;
  image.samples.assign(cw * ch, 0.0f);
  for (std::size_t y = 0; y < ch; ++y) {
    for (std::size_t x = 0; x < cw; ++x) image.samples[y * cw + x] = static_cast<float>(both[(y + y0) * w + x + x0] / total);
  }
  image.nx = static_cast<int>(cw);
  image.ny = static_cast<int>(ch);
  // The samples with light bounded along the diagonals too (the corners of a disc's square are
  // empty), widened by 2 (a point interpolated from them lies within a cell of one along each axis).
  double sum_lo = kInfinity, sum_hi = -kInfinity, difference_lo = kInfinity, difference_hi = -kInfinity;
  for (std::size_t y = 0; y < ch; ++y) {
    for (std::size_t x = 0; x < cw; ++x) {
      if (!(image.samples[y * cw + x] > 0.0f)) continue;
      const auto a = static_cast<double>(x), b = static_cast<double>(y);
      sum_lo = std::min(sum_lo, a + b);
      sum_hi = std::max(sum_hi, a + b);
      difference_lo = std::min(difference_lo, a - b);
      difference_hi = std::max(difference_hi, a - b);
    }
  }
  image.diagonals = {static_cast<float>(sum_lo - 2.0), static_cast<float>(sum_hi + 2.0), static_cast<float>(difference_lo - 2.0),
                     static_cast<float>(difference_hi + 2.0)};
  // Its samples' sum over grids of cells turned by 0, 22.5 and 45 deg and moved by four sub-cell
  // offsets: a smooth footprint's is 1 within 1e-4 whatever the turn, and it is drawn as sampled; a
  // sharp core's is not (a point's, turned by 45 deg, 1.17-1.34), and it is drawn normalised, which
  // costs sampling it whole in every band it reaches.
  double ripple = 0.0;
  for (const double angle : {0.0, kPi / 8.0, kPi / 4.0}) {
    const double ca = std::cos(angle), sa = std::sin(angle);
    for (const auto& [ox_g, oy_g] : {std::pair{0.0, 0.0}, std::pair{0.5, 0.0}, std::pair{0.5, 0.5}, std::pair{0.25, 0.75}}) {
      double lattice = 0.0;
      const double reach = 0.5 * std::hypot(static_cast<double>(cw), static_cast<double>(ch)) * cell / grid_cell + 2.0;
      const double cx = image.origin_x + 0.5 * static_cast<double>(cw - 1) * cell, cy = image.origin_y + 0.5 * static_cast<double>(ch - 1) * cell;
      for (int gy = -static_cast<int>(reach); gy <= static_cast<int>(reach); ++gy) {
        for (int gx = -static_cast<int>(reach); gx <= static_cast<int>(reach); ++gx) {
          const double qx = (gx + ox_g) * grid_cell, qy = (gy + oy_g) * grid_cell;  // from the image's centre, px
          const double u = ((ca * qx + sa * qy + cx) - image.origin_x) / cell, v = ((-sa * qx + ca * qy + cy) - image.origin_y) / cell;
          if (u < 0.0 || v < 0.0 || u > static_cast<double>(cw - 1) || v > static_cast<double>(ch - 1)) continue;
          const auto iu = std::min(static_cast<std::size_t>(u), cw - 2), iv = std::min(static_cast<std::size_t>(v), ch - 2);
          const double fu = u - static_cast<double>(iu), fv = v - static_cast<double>(iv);
          const float* at = image.samples.data() + iv * cw + iu;
          lattice += (1.0 - fv) * (at[0] + fu * (at[1] - at[0])) + fv * (at[cw] + fu * (at[cw + 1] - at[cw]));
        }
      }
      ripple = std::max(ripple, std::abs(lattice - 1.0));
    }
  }
  image.normalise = ripple > kLatticeRipple;
  image.origin_x += static_cast<float>(static_cast<double>(x0) * cell);
  image.origin_y += static_cast<float>(static_cast<double>(y0) * cell);
  image.ok = true;
  return image;
}

std::uint64_t FootprintScatter::key_of(int mesh, std::int64_t field_index, std::int64_t depth_step, int level) {
  // mesh < 2^14 with the level (< 4), field index < 2^20, depth step within +-2^27 (as the table's own keys).
  return ((static_cast<std::uint64_t>(mesh) * 4 + static_cast<std::uint64_t>(level)) << 48) | (static_cast<std::uint64_t>(field_index) << 28) |
         static_cast<std::uint64_t>(depth_step + (std::int64_t{1} << 27));
}

const LightImage& FootprintScatter::light_image(int mesh, std::int64_t field_index, std::int64_t depth_step, double wavelength_nm,
                                                int level, FootprintScratch& scratch) const {
  const auto make = [&] {
    if (!scratch.image_scratch) scratch.image_scratch = std::make_unique<FootprintScratch>();
    const ScenePoint at = table_->point_at(static_cast<double>(field_index), static_cast<double>(depth_step) / kLightImageDepthSteps);
    return make_light_image(mesh, at, wavelength_nm, level, *scratch.image_scratch);
  };
  // Made at a finer level than asked (its passing beam is smaller than its probe said): the same
  // image serves that level's key too, which the footprints drawn at it look up.
  const auto also_key = [&](const LightImage& made) {
    return made.level != level ? std::optional<std::uint64_t>(key_of(mesh, field_index, depth_step, made.level)) : std::nullopt;
  };
  return images_.get(key_of(mesh, field_index, depth_step, level), wavelength_nm, scratch.light_images, make, also_key);
}

FootprintScatter::ImagePlace FootprintScatter::image_place(const ScenePoint& point) const {
  const MappedPupilTable::Place q = table_->place(point);
  return {q.field_index, static_cast<std::int64_t>(std::floor(q.depth_index * kLightImageDepthSteps + 0.5)), q.cos_azimuth, q.sin_azimuth};
}

bool FootprintScatter::deposit_light_images(const ScatterSource& s, const FootprintPlan& p, SplatBuffer& buffer,
                                            FootprintScratch& scratch) const {
  const ScenePoint point = scene_point(s);
  const ImagePlace n = image_place(point);
  // Output px turned by the azimuth: M R(phi) M^-1 (M = px_per_mm_); an image is sampled through
  // its inverse, M R(-phi) M^-1.
  const double m00 = px_per_mm_[0], m01 = px_per_mm_[1], m10 = px_per_mm_[2], m11 = px_per_mm_[3];
  const double det = m00 * m11 - m01 * m10;
  const double i00 = m11 / det, i01 = -m01 / det, i10 = -m10 / det, i11 = m00 / det;
  const double c = n.cos_azimuth, sn = n.sin_azimuth;
  // R(-phi) M^-1
  const double r00 = c * i00 + sn * i10, r01 = c * i01 + sn * i11, r10 = -sn * i00 + c * i10, r11 = -sn * i01 + c * i11;
  const std::array<float, 4> to_image{static_cast<float>(m00 * r00 + m01 * r10), static_cast<float>(m00 * r01 + m01 * r11),
                                      static_cast<float>(m10 * r00 + m11 * r10), static_cast<float>(m10 * r01 + m11 * r11)};
  const PupilMesh& fine = meshes_.mesh(PupilMeshTable::light_mesh());
  scratch.image_draws.clear();
  auto add_group = [&](const SpectralGroup& g, float share) {
    const LightImage& image = light_image(p.mesh, n.field_index, n.depth_step, g.wavelength_nm, p.level, scratch);
    if (!image.ok) return false;
    std::array<SensorHit, 1> chief{};
    map_set(point, g.wavelength_nm, MappedPupilTable::kCentreSet, kCentre, chief, scratch);
    if (!(chief[0].ok || chief[0].unclipped)) return false;
    const PixelPoint at = camera_.output_pixel(chief[0].x_mm, chief[0].y_mm);
    const Point2f anchor{static_cast<float>(at.x), static_cast<float>(at.y)};
    const std::array<float, 4> value = group_value(s, g, share, p, options_.vignetting);
    const double light = options_.vignetting ? table_->passing_light(point, g.wavelength_nm, fine, scratch.table_cache) : 1.0;
    const auto lit = static_cast<float>(light);
    scratch.image_draws.push_back({&image, anchor, {value[0] * lit, value[1] * lit, value[2] * lit, value[3]}});
    return true;
  };
  for (const SpectralGroup& g : groups_.split(p.groups)) {
    if (!add_group(g, p.blend)) return false;
  }
  if (p.blend < 1.0f) {
    for (const SpectralGroup& g : groups_.split(p.groups - 1)) {
      if (!add_group(g, 1.0f - p.blend)) return false;
    }
  }
  // Image offsets to output offsets: M R(phi) M^-1, to_image's inverse.
  const float t_det = to_image[0] * to_image[3] - to_image[1] * to_image[2];
  const std::array<float, 4> from_image{to_image[3] / t_det, -to_image[1] / t_det, -to_image[2] / t_det, to_image[0] / t_det};
  for (const FootprintScratch::ImageDraw& d : scratch.image_draws) {
    const LightImage& im = *d.image;
    if (im.dense) {
      buffer.add_image(im.samples, im.nx, im.ny, im.origin_x, im.origin_y, im.cell_px, to_image, d.anchor, d.value, im.diagonals, im.normalise);
      continue;
    }
    buffer.add_points(im.points, from_image, d.anchor, d.value);
  }
  return true;
}

ScenePoint FootprintScatter::scene_point(const ScatterSource& s) const {
  const Tangents t = camera_.frame().tangents_at(source_centre(s));
  return {t.x, t.y, s.inverse_depth_per_mm};
}

float FootprintScatter::plan_light(const ScenePoint& point, const FootprintPlan& p) const {
  const float factor = illumination_.factor(point);
  // Widened discs: the light at the share the table's nodes measured (interpolated), not at this
  // footprint's own (IlluminationTable::widened_share says why).
  if (const double share = illumination_.widened_share(point); p.discs && share > 0.0 && p.passing > 0.0f) {
    return static_cast<float>(factor * share / p.passing);
  }
  return factor;
}

void FootprintScatter::clip_discs(const ScenePoint& point, std::vector<PupilDisc>& discs) const {
  model_.clip_discs(point, discs);
  illumination_.widen(point, discs);
}

FootprintPlan FootprintScatter::plan(const ScatterSource& s, FootprintScratch& scratch, FootprintProbe* probe_out) const {
  std::vector<PupilPoint>& pupil = scratch.pupil;
  std::vector<SensorHit>& hits = scratch.hits;
  const PixelPoint centre = source_centre(s);
  const ScenePoint point = scene_point(s);
  FootprintPlan p;
  const bool affine = model_.affine_in_pupil() && aperture_.is_uniform_convex();
  // Probe: the pupil centre and its edge (8 points) at the extreme wavelengths and the reference.
  pupil.assign(probe_.begin(), probe_.end());
  hits.resize(pupil.size());
  const std::array<double, 3> lambdas{camera_.reference_wavelength_nm(), groups_.lowest_nm(), groups_.highest_nm()};
  // Copied to *probe_out for plan_range where asked. On the stack (a thin-lens process took 4 %
  // longer with it in the scratch space). `px` is read only where `ok` (not value-initialised:
  // zeroing its 432 bytes was a tenth of a thin-lens plan's time).
  FootprintProbe probe;
  auto& px = probe.px;
  auto& ok = probe.ok;  // where the ray lands is known (it passes, or would)
  double x_min = kInfinity, x_max = -kInfinity, y_min = kInfinity, y_max = -kInfinity;
  // Without dispersion (a thin lens, or colour off) one wavelength tells all.
  const std::size_t wavelengths = camera_.is_thin_lens() || !options_.spectral ? 1 : 3;
  probe.wavelengths = wavelengths;
  // Where the model describes its clipping as pupil discs, those that cut the aperture say that the
  // beam is clipped, and the probe maps without clipping (cheaper).
  clip_discs(point, scratch.discs);
  bool any_clipped = !scratch.discs.empty();
  // The probe's edge points pulled in to the discs' edge where they cut it (star-shaped about the
  // centre when the centre passes): the footprint's extent and its colour spread are the passing
  // beam's, not the iris's (a lens opened beyond its clear apertures would otherwise plan meshes and
  // spectral groups for light that never gets through).
  if (any_clipped && centre_passes(scratch.discs)) {
    disc_reach(probe_directions_, scratch.discs, scratch.reach);
    for (std::size_t i = 1; i < pupil.size(); ++i) {
      const double f = std::min(1.0, scratch.reach[i - 1]);
      pupil[i] = {pupil[i].x * f, pupil[i].y * f};
    }
  }
  for (std::size_t l = 0; l < wavelengths; ++l) {
    if (affine) {
      // An affine model (which clips by discs only) maps the probe through three rays.
      std::array<SensorHit, 3> basis;
      model_.map_passing(point, lambdas[l], kBasis, basis);
      if (l == 0) {
        const PixelPoint o = camera_.output_pixel(basis[0].x_mm, basis[0].y_mm);
        const PixelPoint ex = camera_.output_pixel(basis[1].x_mm, basis[1].y_mm);
        const PixelPoint ey = camera_.output_pixel(basis[2].x_mm, basis[2].y_mm);
        p.affine_px = {static_cast<float>(o.x),        static_cast<float>(o.y),        static_cast<float>(ex.x - o.x),
                       static_cast<float>(ex.y - o.y), static_cast<float>(ey.x - o.x), static_cast<float>(ey.y - o.y)};
        p.centre_weight = static_cast<float>(basis[0].weight);
        p.mapped = basis[0].ok;
      }
      // The probe's landings from the three rays' (output pixels are affine in sensor mm), with
      // the centre ray's fate: an affine model clips by discs only, which the probe ignores.
      const PixelPoint o = camera_.output_pixel(basis[0].x_mm, basis[0].y_mm);
      const PixelPoint ex = camera_.output_pixel(basis[1].x_mm, basis[1].y_mm);
      const PixelPoint ey = camera_.output_pixel(basis[2].x_mm, basis[2].y_mm);
      const double axx = ex.x - o.x, axy = ex.y - o.y, ayx = ey.x - o.x, ayy = ey.y - o.y;
      const bool lands = basis[0].ok || basis[0].unclipped;
      any_clipped = any_clipped || !basis[0].ok;
      if (l == 0 && basis[0].ok) probe.chief_passes = true;
      for (std::size_t i = 0; i < 9; ++i) {
        ok[l][i] = lands;
        if (!lands) continue;
        px[l][i] = {o.x + axx * pupil[i].x + ayx * pupil[i].y, o.y + axy * pupil[i].x + ayy * pupil[i].y};
        x_min = std::min(x_min, px[l][i].x);
        x_max = std::max(x_max, px[l][i].x);
        y_min = std::min(y_min, px[l][i].y);
        y_max = std::max(y_max, px[l][i].y);
      }
      continue;
    }
    if (scratch.discs.empty()) {
      map_set(point, lambdas[l], MappedPupilTable::kProbeSet, pupil, hits, scratch);
    } else {
      model_.map_passing(point, lambdas[l], pupil, hits);
    }
    if (l == 0 && hits[0].ok) {
      p.centre_weight = static_cast<float>(hits[0].weight);
      probe.chief_passes = true;
    }
    for (std::size_t i = 0; i < 9; ++i) {
      ok[l][i] = hits[i].ok || hits[i].unclipped;
      any_clipped = any_clipped || !hits[i].ok;
      if (!ok[l][i]) continue;
      const PixelPoint q = camera_.output_pixel(hits[i].x_mm, hits[i].y_mm);
      px[l][i] = {q.x, q.y};
      x_min = std::min(x_min, px[l][i].x);
      x_max = std::max(x_max, px[l][i].x);
      y_min = std::min(y_min, px[l][i].y);
      y_max = std::max(y_max, px[l][i].y);
    }
  }
  if (probe.chief_passes && !affine) {  // (an affine plan has them from its three rays)
    p.affine_px[0] = static_cast<float>(px[0][0].x);
    p.affine_px[1] = static_cast<float>(px[0][0].y);
  }
  if (!(y_min <= y_max)) {
    // No probe ray got through (the exact model, fully vignetted): plan a small mesh around the
    // pixel so the rays that do pass are still found.
    x_min = x_max = centre.x;
    y_min = y_max = centre.y;
  }
  // Nearly affine? Fit the reference-wavelength probe by the affine map through its centre and
  // two edge points; if no probe point departs from it by more than a quarter pixel, the
  // aberrations are invisible in this footprint and the single polygon is exact enough.
  bool near_affine = affine;
  if (!affine && aperture_.is_uniform_convex() && std::all_of(ok[0].begin(), ok[0].end(), [](bool b) { return b; })) {
    // Pupil points 1 and 3 are (r1, 90 deg) and (r3, 180 deg): solve for the map's columns.
    const double r1 = pupil[1].y, r3 = -pupil[3].x;
    const double ax = (px[0][3].x - px[0][0].x) / -r3, ay = (px[0][3].y - px[0][0].y) / -r3;
    const double bx = (px[0][1].x - px[0][0].x) / r1, by = (px[0][1].y - px[0][0].y) / r1;
    double worst = 0.0;  // squared
    for (std::size_t i = 0; i < 9; ++i) {
      const double dx = px[0][i].x - (px[0][0].x + ax * pupil[i].x + bx * pupil[i].y);
      const double dy = px[0][i].y - (px[0][0].y + ay * pupil[i].x + by * pupil[i].y);
      worst = std::max(worst, dx * dx + dy * dy);
    }
    near_affine = worst < kAffineTolerancePx * kAffineTolerancePx;
  }
  // A clipped beam is one polygon only where the model describes its clipping as pupil discs.
  if (any_clipped && scratch.discs.empty()) near_affine = false;
  double spread = 0.0;  // squared, then px
  for (std::size_t i = 0; i < 9; ++i) {
    if (!ok[1][i] || !ok[2][i]) continue;
    const double dx = px[1][i].x - px[2][i].x, dy = px[1][i].y - px[2][i].y;
    spread = std::max(spread, dx * dx + dy * dy);
  }
  spread = std::sqrt(spread);
  const double size = std::max(x_max - x_min, y_max - y_min);
  // Coverage has no colour: one group carries it. A point whose colour spread just crossed into one
  // more group than its neighbour's is split both ways, its light cross-faded between the two over
  // kGroupBlend of the tolerance: each split places its colours at its groups' wavelengths, and a
  // hard switch moved them by a fraction of a pixel between neighbouring points, which a uniform
  // sky showed as coloured lines of up to 5 % along the switch.
  const double groups_needed = spread / options_.chromatic_tolerance_px;
  p.groups = s.coverage_only ? 1 : std::clamp(static_cast<int>(std::ceil(groups_needed)), 1, groups_.max_count());
  if (p.groups > 1 && groups_needed < p.groups) {
    p.blend = static_cast<float>(std::min(1.0, (groups_needed - (p.groups - 1)) / kGroupBlend));
  }
  p.level = grid_level(size);
  const double cell_px = 1 << p.level;
  const double margin = kTentMarginPx * cell_px + (near_affine ? 0.0 : kMeshMarginFraction * size);
  p.y_min = static_cast<float>(y_min - margin);
  p.y_max = static_cast<float>(y_max + margin);
  // The outline need only follow the circle to 0.1 of a cell.
  const int sector_step = PupilMeshTable::sector_step(size / cell_px);
  // A point stands for the whole beam where it all passes or where the discs say what share does.
  const bool all_pass = !any_clipped || !scratch.discs.empty();
  if (size < kPointFootprintPx && all_pass) {
    p.outline = FootprintPlan::kPoint;
  } else if (near_affine) {
    p.outline = sector_step;
  } else if (aperture_.kind() == Aperture::Kind::Mask) {
    p.mesh = PupilMeshTable::grid_mesh(size / kPxPerGridCell);
  } else {
    // Models that clip rays one by one (exact, poly) need rings fine enough for a vignetted beam's
    // edge; where the model's clipping is pupil discs the rings themselves are clipped.
    const bool clips = (any_clipped && scratch.discs.empty()) || model_.kind() == RayModelKind::Exact ||
                       model_.kind() == RayModelKind::Poly;
    // On a coarse grid a ring may span more pixels (as many cells as at full resolution at 2 x 2, half
    // as many at 4 x 4): the grid smooths the radial profile by a cell anyway.
    const double rings = clips ? std::max(kMinClippingRings, size / kPxPerClippingRing) : size / (kPxPerRing * std::max(1.0, 0.5 * cell_px));
    p.mesh = PupilMeshTable::polar_mesh(rings, sector_step);
  }
  p.discs = !scratch.discs.empty();
  if (table_ && options_.light_images && p.mesh >= 0 && !p.discs) {
    // Drawn from light images, at the grid level of the beam's passing part (not of its probe, whose
    // stopped rays may land far out: an in-focus point's passing beam a few pixels across).
    const ImagePlace n = image_place(point);
    const double wavelength_nm = groups_.split(p.groups)[0].wavelength_nm;
    const LightImage& image = light_image(p.mesh, n.field_index, n.depth_step, wavelength_nm, p.level, scratch);
    if (image.ok) {
      p.images = true;
      p.level = image.level;
    }
  }
  if (p.discs && aperture_.is_uniform_convex()) {
    const int own_step = p.mesh >= 0 ? PupilMeshTable::sector_step_of_mesh(p.mesh) : p.outline;
    p.passing = static_cast<float>(disc_passing_share(scratch.discs, own_step, scratch));
  }
  p.area = areas_.at(centre.x, centre.y, s.inverse_depth_per_mm);
  p.light = plan_light(point, p);
  if (probe_out != nullptr) *probe_out = probe;
  return p;
}

namespace {

// A run of plan_range: whole pixels (not the parts of a split edge pixel) of one row, one after the
// other, from a column that is a multiple of kShapeStride (or where one is cut off) to the next.
bool whole_pixel(const ScatterSource& s) { return s.offset_x_px == 0.0f && s.offset_y_px == 0.0f; }

bool joins_run(std::span<const ScatterSource> sources, std::size_t i) {
  const ScatterSource& p = sources[i - 1];
  const ScatterSource& q = sources[i];
  return q.y == p.y && q.x == p.x + 1 && q.coverage_only == p.coverage_only && whole_pixel(p) && whole_pixel(q);
}

// Whether source i begins a run (true past the end).
bool starts_run(std::span<const ScatterSource> sources, std::size_t i) {
  constexpr auto stride = static_cast<int>(kShapeStride);
  return i == 0 || i >= sources.size() || ((sources[i].x % stride) + stride) % stride == 0 || !joins_run(sources, i);
}

}  // namespace

void plan_range_starts(std::span<const ScatterSource> sources, std::size_t target, std::vector<std::size_t>& starts) {
  starts.clear();
  for (std::size_t i = 0; i < sources.size(); i += target) {
    // Where no run continues across (a row's first pixel, a gap): a range that ended at a run's
    // kShapeStride column cut the run short of the column it would have shared with the next
    // (plan_range), so a split edge pixel far away, appended before and shifting every range,
    // changed how the pixels before a range's end were planned.
    while (i < sources.size() && i > 0 && joins_run(sources, i)) ++i;
    if (i < sources.size()) starts.push_back(i);
  }
  starts.push_back(sources.size());
}

bool FootprintScatter::shares_shape(std::span<const ScatterSource> sources, std::span<const FootprintPlan> plans, std::size_t a,
                                    std::size_t b, const FootprintProbe& pa, const FootprintProbe& pb) const {
  const FootprintPlan& A = plans[a];
  const FootprintPlan& B = plans[b];
  // The same kind of deposit: a mesh (the single polygon and the point are cheap already), the same
  // mesh, grid and wavelength-group splits, some of the beam passing in both.
  if (A.mesh < 0 || A.mesh != B.mesh || A.level != B.level || A.groups != B.groups || (A.blend < 1.0f) != (B.blend < 1.0f) ||
      A.discs != B.discs || !(A.passing > 0.0f && B.passing > 0.0f)) {
    return false;
  }
  if (!pa.chief_passes || !pb.chief_passes || pa.wavelengths != pb.wavelengths) return false;
  // The sources between lie at depths between theirs, so that their shapes lie between a's and b's
  // (a footprint changes monotonically with depth over so short a run); at one depth all along, the
  // passing share is interpolated to second order, else a's and b's must agree.
  const double da = sources[a].inverse_depth_per_mm, db = sources[b].inverse_depth_per_mm;
  const double lo = std::min(da, db), hi = std::max(da, db);
  bool one_depth = da == db;
  for (std::size_t m = a + 1; m < b; ++m) {
    const double d = sources[m].inverse_depth_per_mm;
    if (!(d >= lo && d <= hi)) return false;
    one_depth = one_depth && d == da;
  }
  if (!one_depth && std::abs(A.passing - B.passing) > kShapePassingTolerance) return false;
  // Every probe ray, at every probed wavelength, where a's and b's chief rays put it, within the
  // tolerance of each other.
  const double tolerance2 = kShapeTolerancePx * kShapeTolerancePx;
  for (std::size_t l = 0; l < pa.wavelengths; ++l) {
    for (std::size_t i = 0; i < 9; ++i) {
      if (pa.ok[l][i] != pb.ok[l][i]) return false;
      if (!pa.ok[l][i]) continue;
      const double dx = (pb.px[l][i].x - pb.px[0][0].x) - (pa.px[l][i].x - pa.px[0][0].x);
      const double dy = (pb.px[l][i].y - pb.px[0][0].y) - (pa.px[l][i].y - pa.px[0][0].y);
      if (dx * dx + dy * dy > tolerance2) return false;
    }
  }
  return true;
}

bool FootprintScatter::follow(const ScatterSource& s, const FootprintPlan& a, const FootprintPlan& b, double along,
                              std::int32_t a_index, FootprintPlan& out) const {
  // Its own chief ray (exact: distortion and lateral colour move a footprint by up to 1/16 px per
  // pixel along a row), a's shape, the rest interpolated between a and b.
  const ScenePoint point = scene_point(s);
  std::array<SensorHit, 1> hit;
  if (a.discs) {
    model_.map_passing(point, camera_.reference_wavelength_nm(), kCentre, hit);
  } else {
    model_.map(point, camera_.reference_wavelength_nm(), kCentre, hit);
  }
  if (!hit[0].ok) return false;
  const PixelPoint c = camera_.output_pixel(hit[0].x_mm, hit[0].y_mm);
  out = a;
  out.affine_px[0] = static_cast<float>(c.x);
  out.affine_px[1] = static_cast<float>(c.y);
  out.centre_weight = static_cast<float>(hit[0].weight);
  const float dy = out.affine_px[1] - a.affine_px[1];
  out.y_min = a.y_min + dy;
  out.y_max = a.y_max + dy;
  const auto f = static_cast<float>(along);
  const PixelPoint centre = source_centre(s);
  out.area = areas_.at(centre.x, centre.y, s.inverse_depth_per_mm);
  out.blend = a.blend + f * (b.blend - a.blend);
  out.passing = a.passing + f * (b.passing - a.passing);
  out.light = plan_light(point, out);
  out.shape_source = a_index;
  return true;
}

void FootprintScatter::plan_range(std::span<const ScatterSource> sources, std::span<FootprintPlan> plans, std::size_t begin,
                                  std::size_t end, FootprintScratch& scratch) const {
  // Models that clip by pupil discs alone (paraxial, Seidel): the exact and poly models clip ray by
  // ray, and a beam's clipped edge can move faster along a row than their probe shows. An affine
  // model through a uniform convex aperture has no mesh footprints to share.
  const bool meshes = !(model_.affine_in_pupil() && aperture_.is_uniform_convex());
  const bool reuse = options_.reuse_shapes && meshes &&
                     (model_.kind() == RayModelKind::Paraxial || model_.kind() == RayModelKind::Seidel);
  if (!reuse && model_.kind() == RayModelKind::Thin) {
    // A thin lens images every point at one depth alike, moved with it: its chief ray goes through
    // the lens's centre, undeviated, to where the pinhole puts the point, and the aperture's image
    // about it depends on the depth alone (no weights, no clear apertures, no distortion). So a
    // source at the inverse depth of one planned before it in the range takes that plan moved by the
    // difference of their pixels' centres (walls, the sky and a level ground's rows hold many equal
    // depths); the street scene's thin-lens process planned in 25 ms of CPU before.
    std::size_t planned = end;
    for (std::size_t i = begin; i < end; ++i) {
      const ScatterSource& s = sources[i];
      if (planned != end && sources[planned].inverse_depth_per_mm == s.inverse_depth_per_mm &&
          sources[planned].coverage_only == s.coverage_only) {
        plans[i] = moved_plan(plans[planned], sources[planned], s);
        // A thin model of a real lens: the real lens's brightness where this one lands.
        if (!illumination_.empty()) plans[i].light = plan_light(scene_point(s), plans[i]);
      } else {
        plans[i] = plan(s, scratch);
        planned = i;
      }
    }
    return;
  }
  if (!reuse) {
    for (std::size_t i = begin; i < end; ++i) plans[i] = plan(sources[i], scratch);
    return;
  }
  std::vector<FootprintProbe>& probes = scratch.range_probes;
  probes.resize(end - begin);
  auto full = [&](std::size_t i) { plans[i] = plan(sources[i], scratch, &probes[i - begin]); };
  // Between planned a and b: all follow a where they may, else the middle is planned and each half
  // tried in turn.
  auto fill = [&](auto& self, std::size_t a, std::size_t b) -> void {
    if (b - a < 2) return;
    if (shares_shape(sources, plans, a, b, probes[a - begin], probes[b - begin])) {
      for (std::size_t m = a + 1; m < b; ++m) {
        const double along = static_cast<double>(m - a) / static_cast<double>(b - a);
        if (!follow(sources[m], plans[a], plans[b], along, static_cast<std::int32_t>(a), plans[m])) full(m);
      }
      return;
    }
    const std::size_t mid = a + (b - a) / 2;
    full(mid);
    self(self, a, mid);
    self(self, mid, b);
  };
  if (begin >= end) return;
  full(begin);
  std::size_t i = begin;
  while (i < end) {
    std::size_t last = i;
    // To the next column that is a multiple of kShapeStride, so that which pixels are probed depends
    // on where they are, not on where the frame or the range begins.
    while (last + 1 < end && joins_run(sources, last + 1)) {
      if (starts_run(sources, ++last)) break;
    }
    if (last == i) {
      if (++i < end) full(i);
      continue;
    }
    full(last);
    fill(fill, i, last);
    i = last;
  }
}

FootprintPlan moved_plan(const FootprintPlan& p, const ScatterSource& from, const ScatterSource& to) {
  const PixelPoint a = source_centre(from), b = source_centre(to);
  const auto dx = static_cast<float>(b.x - a.x), dy = static_cast<float>(b.y - a.y);
  FootprintPlan q = p;
  q.affine_px[0] += dx;
  q.affine_px[1] += dy;
  q.y_min += dy;
  q.y_max += dy;
  return q;
}

int footprint_subrows(const FootprintPlan& p, int buffer_subrows) {
  const float height = (p.y_max - p.y_min) / static_cast<float>(1 << p.level);
  const int divisor = height < kMediumFootprintPx ? 1 : height < kTallFootprintPx ? 2 : 4;
  return std::max(1, buffer_subrows / divisor);
}

void FootprintShape::clear() {
  valid = false;
  points.clear();
  polygons.clear();
  group_end.clear();
  group_triangles.clear();
  mesh_cells.clear();
  mesh_edges.clear();
  mesh_sets.clear();
}

void FootprintShape::add(std::span<const Point2f> vertices, const std::array<float, 4>& unit_value, int subrows) {
  polygons.push_back({static_cast<std::uint32_t>(points.size()), static_cast<std::uint32_t>(vertices.size()), unit_value[0],
                      unit_value[3], subrows});
  points.insert(points.end(), vertices.begin(), vertices.end());
}

namespace {

// A wavelength group's share of a source's light (RGB, times the plan's FootprintPlan::light) and
// coverage (alpha, times the output area its pixel's image covers, FootprintPlan::area, with
// vignetting on).
std::array<float, 4> group_value(const ScatterSource& s, const SpectralGroup& g, float share, const FootprintPlan& p, bool vignetting) {
  std::array<float, 4> value{};
  const float light = share * p.light;
  for (std::size_t c = 0; c < 3; ++c) value[c] = light * (g.m[c][0] * s.rgb[0] + g.m[c][1] * s.rgb[1] + g.m[c][2] * s.rgb[2]);
  value[3] = share * g.alpha * s.coverage * (vignetting ? p.area : 1.0f);
  return value;
}

}  // namespace

void FootprintScatter::map_shape(const ScatterSource& s, const FootprintPlan& p, int buffer_subrows, FootprintScratch& scratch) const {
  const int own_subrows = footprint_subrows(p, buffer_subrows);
  std::vector<SensorHit>& hits = scratch.hits;
  std::vector<Point2f>& points = scratch.points;
  const ScenePoint point = scene_point(s);
  const double passing = p.passing;
  if (p.discs) {
    clip_discs(point, scratch.discs);
  } else {
    scratch.discs.clear();
  }
  // A polar mesh of a model that clips by discs: its rings clipped once for every wavelength.
  const PupilMesh& mesh = meshes_.mesh(p.mesh);
  const bool rings_clipped = !scratch.discs.empty() && mesh.sectors > 0 && aperture_.is_uniform_convex() && clip_rings(p, scratch);
  // Rings or triangles: decided once for all the footprint's wavelengths. Each group's light and
  // coverage go down in its own shape, and a pixel's colour is their sum over its coverage: where
  // the rings nested at some wavelengths and not at others (a mapped ring turning back in y, which
  // depends on the beam's direction), neighbouring sources tiled differently per wavelength, and a
  // uniform defocused wall through the Canon 35 mm showed star-shaped coloured lines of up to 36 %.
  bool allow_rings = true;
  scratch.cached_count = 0;
  const bool several = p.groups > 1 || p.blend < 1.0f;
  if (several) {
    auto nest_at = [&](double wavelength_nm) {
      if (rings_clipped) {
        map_clipped_rings(point, wavelength_nm, p, scratch, true);
      } else {
        if (mesh.sectors <= 0) return false;
        map_cached(point, wavelength_nm, 0, p.mesh, mesh.points, hits, scratch, true);
        points.resize(mesh.points.size());
        for (std::size_t i = 0; i < mesh.points.size(); ++i) {
          const PixelPoint q = camera_.output_pixel(hits[i].x_mm, hits[i].y_mm);
          points[i] = {static_cast<float>(q.x), static_cast<float>(q.y)};
        }
        if (!mesh_ring_spans(mesh, hits, points, scratch)) return false;
      }
      return rings_nest(scratch.ring_spans, scratch.areas);
    };
    for (const SpectralGroup& g : groups_.split(p.groups)) allow_rings = allow_rings && nest_at(g.wavelength_nm);
    if (p.blend < 1.0f) {
      for (const SpectralGroup& g : groups_.split(p.groups - 1)) allow_rings = allow_rings && nest_at(g.wavelength_nm);
    }
  }
  // Every group's rings found y-monotone and simple above: the deposits below map the same rays
  // (scratch.cached_maps) and need only their areas.
  const bool rings_checked = several && allow_rings;
  FootprintShape& shape = scratch.shape;
  shape.clear();
  // One wavelength group's polygons, per unit of its value.
  auto record_group = [&](const SpectralGroup& g) {
    std::size_t triangles = 0;
    const std::size_t sets = shape.mesh_sets.size();
    if (rings_clipped) {
      deposit_clipped_rings(point, g.wavelength_nm, p, passing, allow_rings, rings_checked, kUnit, shape, own_subrows, scratch,
                            triangles);
    } else {
      record_mesh(point, g.wavelength_nm, p, allow_rings, rings_checked, own_subrows, scratch, triangles);
    }
    if (shape.mesh_sets.size() == sets) shape.mesh_sets.emplace_back();
    shape.group_end.push_back(shape.polygons.size());
    shape.group_triangles.push_back(triangles);
  };
  for (const SpectralGroup& g : groups_.split(p.groups)) record_group(g);
  if (p.blend < 1.0f) {
    for (const SpectralGroup& g : groups_.split(p.groups - 1)) record_group(g);
  }
  shape.valid = true;
  shape.chief_px = {p.affine_px[0], p.affine_px[1]};
  shape.light_scale = static_cast<double>(p.centre_weight) * passing;
}

void FootprintScatter::record_mesh(const ScenePoint& point, double wavelength_nm, const FootprintPlan& p, bool allow_rings,
                                   bool rings_checked, int own_subrows, FootprintScratch& scratch, std::size_t& triangles) const {
  std::vector<SensorHit>& hits = scratch.hits;
  std::vector<Point2f>& points = scratch.points;
  FootprintShape& shape = scratch.shape;
  const PupilMesh& mesh = meshes_.mesh(p.mesh);
  map_cached(point, wavelength_nm, 0, p.mesh, mesh.points, hits, scratch, false);
  if (!scratch.discs.empty() && illumination_.widened_share(point) > 0.0) {
    // The discs as planned, widened where the real lens passes more (IlluminationTable::widen), not
    // the model's own, which RayModel::map applies.
    for (std::size_t i = 0; i < mesh.points.size(); ++i) {
      const double c = disc_clearance(mesh.points[i], scratch.discs);
      hits[i].clearance = c;
      hits[i].ok = c >= 0.0;
      hits[i].unclipped = true;
    }
  }
  points.resize(mesh.points.size());
  for (std::size_t i = 0; i < mesh.points.size(); ++i) {
    if (!hits[i].unclipped && !hits[i].ok) continue;
    const PixelPoint q = camera_.output_pixel(hits[i].x_mm, hits[i].y_mm);
    points[i] = {static_cast<float>(q.x), static_cast<float>(q.y)};
  }
  if (mesh.sectors > 0 && allow_rings &&
      deposit_ring_polygons(mesh, hits, points, kUnit, options_.vignetting, shape, own_subrows, rings_checked, scratch)) {
    return;
  }
  // A triangle whose corners a clear aperture partly stops (exact, poly) passes the part of its
  // area where the linear interpolation of their clearances is >= 0, in place: the beam's edge
  // falls inside it, to first order.
  auto triangle_passing = [&hits](const PupilTriangle& tri) {
    const SensorHit& a = hits[static_cast<std::size_t>(tri.a)];
    const SensorHit& b = hits[static_cast<std::size_t>(tri.b)];
    const SensorHit& c = hits[static_cast<std::size_t>(tri.c)];
    if (!(a.ok || a.unclipped) || !(b.ok || b.unclipped) || !(c.ok || c.unclipped)) return 0.0;
    return passing_share(a.clearance, b.clearance, c.clearance);
  };
  // Colour carries the transmitted fraction and the rays' radiometric weights (vignetting darkens);
  // coverage is normalised over the light that passes, so a vignetted point is still an opaque
  // surface. Without vignetting the colour is normalised the same way.
  // The share of the pupil that passes, and (interpolated rays) the light it carries at the rays'
  // weights, for the table's finer measure below.
  const bool finer_light = table_ && options_.vignetting;
  double passed = 0.0, coarse = 0.0;
  std::vector<double>& fractions = scratch.fractions;
  fractions.resize(mesh.triangles.size());
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const PupilTriangle& tri = mesh.triangles[t];
    const double fraction = triangle_passing(tri);
    fractions[t] = fraction;
    passed += tri.weight * fraction;
    if (finer_light && fraction > 0.0) coarse += tri.weight * fraction * (hits[tri.a].weight + hits[tri.b].weight + hits[tri.c].weight) / 3.0;
  }
  if (!(passed > 0.0)) return;
  // Where the model describes its clipping as discs, the light that passes is known exactly (the
  // outline less the discs); the triangles' linear interpolation only distributes it.
  const double exact_share = !scratch.discs.empty() && aperture_.is_uniform_convex() ? static_cast<double>(p.passing) : passed;
  double unlit = options_.vignetting ? exact_share / passed : 1.0 / passed;
  if (finer_light) {
    // Interpolated rays (exact, poly): the light that passes from the table's finer mesh, this
    // mesh's triangles only distributing it (MappedPupilTable::passing_light says why).
    const PupilMesh& fine = meshes_.mesh(PupilMeshTable::light_mesh());
    if (coarse > 0.0) unlit = table_->passing_light(point, wavelength_nm, fine, scratch.table_cache) / coarse;
  }
  // The triangles, whole or cut, go down together (SplatBuffer::add_mesh): the same deposit as one by
  // one, with one entry per shared edge and sub-row instead of two, and no polygon set up per
  // triangle (a quarter of an exact render's time, perf). A cut edge's crossing of the clearance's
  // 0 is one point for both its triangles, so that they share its passing part.
  const PupilMeshTable::Edges& topology = meshes_.edges(p.mesh);
  scratch.edge_slot.assign(topology.ends.size(), FootprintScratch::kNoSlot);
  scratch.clip_slot.assign(topology.ends.size(), FootprintScratch::kNoSlot);
  const auto point_base = static_cast<std::uint32_t>(shape.points.size());
  shape.points.insert(shape.points.end(), points.begin(), points.end());
  FootprintShape::MeshSet set;
  set.cell_begin = static_cast<std::uint32_t>(shape.mesh_cells.size());
  set.edge_begin = static_cast<std::uint32_t>(shape.mesh_edges.size());
  auto new_edge = [&](std::uint32_t from, std::uint32_t to) {
    shape.mesh_edges.push_back({from, to});
    return static_cast<std::uint32_t>(shape.mesh_edges.size() - 1 - set.edge_begin);
  };
  // Where edge e's interpolated clearance crosses 0, from its first end to its second.
  auto clip_point = [&](std::uint32_t e) {
    std::uint32_t& slot = scratch.clip_slot[e];
    if (slot == FootprintScratch::kNoSlot) {
      const std::size_t u = topology.ends[e][0], v = topology.ends[e][1];
      const double cu = hits[u].clearance, cv = hits[v].clearance;
      const auto along = static_cast<float>(cu / (cu - cv));
      const Point2f& pu = points[u];
      const Point2f& pv = points[v];
      slot = static_cast<std::uint32_t>(shape.points.size());
      shape.points.push_back({pu.x + along * (pv.x - pu.x), pu.y + along * (pv.y - pu.y)});
    }
    return slot;
  };
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const PupilTriangle& tri = mesh.triangles[t];
    const double fraction = fractions[t];
    if (fraction == 0.0) continue;
    const double ray_weight = options_.vignetting ? (hits[tri.a].weight + hits[tri.b].weight + hits[tri.c].weight) / 3.0 : 1.0;
    MeshCell cell;
    cell.light = static_cast<float>(tri.weight * fraction * ray_weight * unlit);
    cell.coverage = static_cast<float>(tri.weight * fraction / passed);
    const std::array<std::uint32_t, 3> corner{static_cast<std::uint32_t>(tri.a), static_cast<std::uint32_t>(tri.b),
                                              static_cast<std::uint32_t>(tri.c)};
    const bool whole = fraction >= 1.0;
    // Its passing part only where it is cut, where the interpolated clearance is >= 0, mapped by
    // interpolating the corners' landing points (first order): spread over the whole triangle's
    // image, the stopped corners' unclipped landings drew a faint skirt around a vignetted point's
    // bokeh (a highlight of radiance 200 showed it as a disc twice too wide, docs/bokeh.md
    // "Brightness"). Walked a -> b -> c: each passing corner, then the crossing of each edge whose
    // ends pass and stop; `kind` of each vertex: its corner k, or 3 + the edge k it cuts.
    std::array<std::uint32_t, MeshCell::kMaxCorners> kind{};
    cell.corners = 0;
    for (std::uint32_t k = 0; k < 3; ++k) {
      const std::uint32_t next = (k + 1) % 3;
      const bool passes = whole || hits[corner[k]].clearance >= 0.0;
      const bool next_passes = whole || hits[corner[next]].clearance >= 0.0;
      if (passes) {
        cell.corner[cell.corners] = point_base + corner[k];
        kind[cell.corners++] = k;
      }
      if (passes != next_passes && cell.corners < MeshCell::kMaxCorners) {
        cell.corner[cell.corners] = clip_point(topology.of_triangle[t][k]);
        kind[cell.corners++] = 3 + k;
      }
    }
    if (cell.corners < 3) continue;
    for (std::uint32_t j = 0; j < cell.corners; ++j) {
      const std::uint32_t from = kind[j], to = kind[(j + 1) % cell.corners];
      if (from < 3 && to < 3) {
        // Along a whole edge of the triangle.
        const std::uint32_t e = topology.of_triangle[t][from];
        std::uint32_t& slot = scratch.edge_slot[e];
        if (slot == FootprintScratch::kNoSlot) slot = new_edge(point_base + topology.ends[e][0], point_base + topology.ends[e][1]);
        cell.edge[j] = slot;
        cell.direction[j] = topology.direction[t][from];
      } else if (from >= 3 && to >= 3) {
        // The cut across the triangle: its own.
        cell.edge[j] = new_edge(cell.corner[j], cell.corner[(j + 1) % cell.corners]);
        cell.direction[j] = 1;
      } else {
        // The passing part of a cut edge, kept from its passing corner to its crossing.
        const std::uint32_t k = from < 3 ? from : from - 3;
        const std::uint32_t e = topology.of_triangle[t][k];
        std::uint32_t& slot = scratch.edge_slot[e];
        const std::uint32_t passing_corner = from < 3 ? cell.corner[j] : cell.corner[(j + 1) % cell.corners];
        if (slot == FootprintScratch::kNoSlot) slot = new_edge(passing_corner, clip_point(e));
        cell.edge[j] = slot;
        cell.direction[j] = from < 3 ? std::int8_t{1} : std::int8_t{-1};
      }
    }
    shape.mesh_cells.push_back(cell);
    ++triangles;
  }
  set.cell_count = static_cast<std::uint32_t>(shape.mesh_cells.size() - set.cell_begin);
  set.edge_count = static_cast<std::uint32_t>(shape.mesh_edges.size() - set.edge_begin);
  shape.mesh_sets.push_back(set);
}

void FootprintScatter::draw_shape(const ScatterSource& s, const FootprintPlan& p, SplatBuffer& buffer, FootprintScratch& scratch,
                                  std::size_t& triangles) const {
  const FootprintShape& shape = scratch.shape;
  // A neighbour's shape carries its light: scaled by this source's chief-ray weight and passing
  // share against the neighbour's (both change slowly along a row; 1 for the source's own shape).
  double scale = 1.0;
  if (options_.vignetting && shape.light_scale > 0.0) scale = static_cast<double>(p.centre_weight) * p.passing / shape.light_scale;
  const float dx = p.affine_px[0] - shape.chief_px[0], dy = p.affine_px[1] - shape.chief_px[1];
  std::size_t group = 0;
  auto draw_group = [&](const SpectralGroup& g, float share) {
    std::array<float, 4> value = group_value(s, g, share, p, options_.vignetting);
    if (scale != 1.0) {
      for (std::size_t c = 0; c < 3; ++c) value[c] = static_cast<float>(value[c] * scale);
    }
    const FootprintShape::MeshSet& set = shape.mesh_sets[group];
    if (set.cell_count > 0) {
      buffer.add_mesh(shape.points, std::span(shape.mesh_edges).subspan(set.edge_begin, set.edge_count),
                      std::span(shape.mesh_cells).subspan(set.cell_begin, set.cell_count), value, {dx, dy});
    }
    const std::size_t begin = group == 0 ? 0 : shape.group_end[group - 1];
    for (std::size_t k = begin; k < shape.group_end[group]; ++k) {
      const FootprintShape::Polygon& q = shape.polygons[k];
      std::span<const Point2f> vertices(shape.points.data() + q.begin, q.count);
      if (dx != 0.0f || dy != 0.0f) {
        scratch.moved.resize(q.count);
        for (std::size_t j = 0; j < q.count; ++j) scratch.moved[j] = {vertices[j].x + dx, vertices[j].y + dy};
        vertices = scratch.moved;
      }
      buffer.add_polygon(vertices, {value[0] * q.light, value[1] * q.light, value[2] * q.light, value[3] * q.coverage}, q.subrows);
    }
    triangles += shape.group_triangles[group];
    ++group;
  };
  for (const SpectralGroup& g : groups_.split(p.groups)) draw_group(g, p.blend);
  if (p.blend < 1.0f) {
    for (const SpectralGroup& g : groups_.split(p.groups - 1)) draw_group(g, 1.0f - p.blend);
  }
}

bool FootprintScatter::deposit_planned_point(const ScatterSource& s, const FootprintPlan& p, SplatBuffer& buffer) const {
  if (p.outline != FootprintPlan::kPoint || !p.mapped || p.groups != 1 || p.blend != 1.0f || p.images || p.mesh >= 0 ||
      !(p.passing > 0.0f)) {
    return false;
  }
  std::array<float, 4> v = lit(group_value(s, groups_.split(1).front(), p.blend, p, options_.vignetting), p.centre_weight);
  const float light = options_.vignetting ? p.passing : 1.0f;
  for (std::size_t k = 0; k < 3; ++k) v[k] *= light;
  buffer.add_point({p.affine_px[0], p.affine_px[1]}, v);
  return true;
}

void FootprintScatter::deposit(const ScatterSource& s, const FootprintPlan& p, std::size_t index, SplatBuffer& buffer,
                               FootprintScratch& scratch, std::size_t& triangles, std::size_t& reused) const {
  // First-order vignetting (the model's pupil discs, the same at every wavelength): the share of the
  // aperture that passes was planned; the point path needs nothing more, the single polygon the
  // outline less what the discs cut off.
  const double passing = p.passing;
  // Where the model's discs stop the whole beam (or leave too thin a sliver to draw), the point is
  // still an opaque surface that sends no light: it darkens its pixel as a vignetted corner does,
  // instead of leaving a hole that the fill paints with its neighbours' colour (a retrofocus's frame
  // corners came out at 0.28 of the centre through the paraxial model where the ground truth has 0.05).
  auto stopped = [&] {
    if (!p.discs || !options_.vignetting) return;
    // Only where the model's field is not folded back onto the frame's middle (a black point there
    // would darken what the model does draw).
    if (!illumination_.unfolded(scene_point(s))) return;
    const Point2f at{p.affine_px[0], p.affine_px[1]};
    for (const SpectralGroup& g : groups_.split(p.groups)) {
      const std::array<float, 4> value = group_value(s, g, 1.0f, p, true);
      if (value[3] > 0.0f) buffer.add_point(at, {0.0f, 0.0f, 0.0f, value[3]});
    }
  };
  if (!(passing > 0.0)) {
    stopped();
    return;
  }
  if (p.images && deposit_light_images(s, p, buffer, scratch)) {
    return;
  }
  if (p.mesh >= 0) {
    // A mesh footprint is mapped into its shape, or drawn from its neighbour's (plan_range).
    const std::int64_t key = p.shape_source >= 0 ? p.shape_source : static_cast<std::int64_t>(index);
    const std::size_t deposits = static_cast<std::size_t>(p.groups + (p.blend < 1.0f ? p.groups - 1 : 0));
    const FootprintShape& shape = scratch.shape;
    if (shape.valid && shape.key == key && shape.group_end.size() == deposits) {
      ++reused;
    } else {
      map_shape(s, p, buffer.options().subrows, scratch);
      scratch.shape.key = key;
    }
    draw_shape(s, p, buffer, scratch, triangles);
    return;
  }
  const int own_subrows = footprint_subrows(p, buffer.options().subrows);
  std::vector<SensorHit>& hits = scratch.hits;
  std::vector<Point2f>& points = scratch.points;
  // A single group's rays are the plan's, at the reference wavelength: the scene point is needed only
  // to map others and to clip by discs.
  const bool planned = p.mapped && p.groups == 1 && p.blend == 1.0f;
  const ScenePoint point = planned && !p.discs ? ScenePoint{} : scene_point(s);
  if (p.discs && p.outline != FootprintPlan::kPoint) {
    clip_discs(point, scratch.discs);
  } else {
    scratch.discs.clear();
  }
  const std::vector<PupilPoint>* outline = p.outline >= 0 ? &meshes_.outline(p.outline) : nullptr;
  if (!scratch.discs.empty() && aperture_.is_uniform_convex() && p.outline >= 0) {
    // The outline less what the discs cut off: with the chief ray inside every disc the cut is
    // radial (cheap); otherwise the polygon is clipped disc by disc.
    const std::vector<PupilPoint>& own = meshes_.dense_outline(p.outline);
    if (centre_passes(scratch.discs)) {
      disc_reach(meshes_.dense_directions(p.outline), scratch.discs, scratch.reach);
      reach_clip(own, 1.0, scratch.reach, scratch.clipped);
    } else {
      clip_pupil_polygon(own, scratch.discs, scratch.clipped, scratch.clip_work);
    }
    if (scratch.clipped.size() < 3) {
      stopped();
      return;
    }
    outline = &scratch.clipped;
  }
  // One wavelength group's share of the light.
  auto deposit_group = [&](const SpectralGroup& g, float share) {
    const std::array<float, 4> value = group_value(s, g, share, p, options_.vignetting);
    if (p.outline == FootprintPlan::kPoint) {
      PixelPoint c{p.affine_px[0], p.affine_px[1]};
      double centre_weight = p.centre_weight;
      if (!planned) {
        hits.resize(1);
        // With discs the passing share is known (a cat's eye may leave the chief ray out).
        if (!p.discs) {
          map_set(point, g.wavelength_nm, MappedPupilTable::kCentreSet, kCentre, std::span<SensorHit>(hits.data(), 1), scratch);
        } else {
          model_.map_passing(point, g.wavelength_nm, kCentre, std::span<SensorHit>(hits.data(), 1));
        }
        if (!hits[0].ok) return;
        c = camera_.output_pixel(hits[0].x_mm, hits[0].y_mm);
        centre_weight = hits[0].weight;
      }
      std::array<float, 4> v = lit(value, centre_weight);
      const auto light = static_cast<float>(options_.vignetting ? passing : 1.0);
      for (std::size_t k = 0; k < 3; ++k) v[k] *= light;
      buffer.add_point({static_cast<float>(c.x), static_cast<float>(c.y)}, v);
      return;
    }
    // Affine model, uniform convex aperture: the outline, less what first-order vignetting cuts
    // off, mapped by the affine map of three rays; it keeps the share of the light that passes.
    PixelPoint o, ex, ey;
    double centre_weight = p.centre_weight;
    if (planned) {
      o = {p.affine_px[0], p.affine_px[1]};
      ex = {o.x + p.affine_px[2], o.y + p.affine_px[3]};
      ey = {o.x + p.affine_px[4], o.y + p.affine_px[5]};
    } else {
      hits.resize(3);
      if (table_) {
        map_set(point, g.wavelength_nm, MappedPupilTable::kBasisSet, kBasis, std::span<SensorHit>(hits.data(), 3), scratch);
      } else {
        model_.map_passing(point, g.wavelength_nm, kBasis, std::span<SensorHit>(hits.data(), 3));
      }
      o = camera_.output_pixel(hits[0].x_mm, hits[0].y_mm);
      ex = camera_.output_pixel(hits[1].x_mm, hits[1].y_mm);
      ey = camera_.output_pixel(hits[2].x_mm, hits[2].y_mm);
      centre_weight = hits[0].weight;
    }
    std::array<float, 4> v = lit(value, centre_weight);
    const auto light = static_cast<float>(options_.vignetting ? passing : 1.0);
    for (std::size_t c = 0; c < 3; ++c) v[c] *= light;
    if (p.level == 0 && outline == &meshes_.outline(p.outline)) {
      // The outline scaled about the pixel's centre (no discs cut it): a stamp.
      const double ax = std::floor(o.x), ay = std::floor(o.y);
      const double off = std::abs(o.x - ax - 0.5) + std::abs(o.y - ay - 0.5) + std::abs(ex.y - o.y) + std::abs(ey.x - o.x);
      if (off <= kStampPlacementPx && std::abs(ax) < 1e6 && std::abs(ay) < 1e6) {
        if (const DifferenceStamp* stamp = stamps_.find(ex.x - o.x, ey.y - o.y)) {
          buffer.add_stamp(*stamp, static_cast<int>(ax), static_cast<int>(ay), v);
          return;
        }
      }
    }
    points.resize(outline->size());
    for (std::size_t i = 0; i < outline->size(); ++i) {
      const PupilPoint& q = (*outline)[i];
      points[i] = {static_cast<float>(o.x + (ex.x - o.x) * q.x + (ey.x - o.x) * q.y),
                   static_cast<float>(o.y + (ex.y - o.y) * q.x + (ey.y - o.y) * q.y)};
    }
    buffer.add_polygon(points, v, own_subrows);
  };
  for (const SpectralGroup& g : groups_.split(p.groups)) deposit_group(g, p.blend);
  if (p.blend < 1.0f) {
    for (const SpectralGroup& g : groups_.split(p.groups - 1)) deposit_group(g, 1.0f - p.blend);
  }
}

}  // namespace lensmith::render_detail
