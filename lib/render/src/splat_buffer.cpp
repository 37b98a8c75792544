// SplatBuffer: polygons scan-converted into sub-row spans whose tent-filtered x profile is written as
// first differences (at most 3 entries per span end) and integrated by one prefix sum per row at
// resolve time; Kosloff, Tao & Barsky's constant-time rectangle spreading generalised to polygons.
#include "lensmith/render/splat_buffer.h"

#include <algorithm>
#if defined(__x86_64__)
#include <immintrin.h>
#endif
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>

#include "lensmith/core/errors.h"
#include "lensmith/core/units.h"
#include "lensmith/render/image.h"

namespace lensmith {

namespace {

constexpr int kChannels = 4;
constexpr int kMaxSubrows = 16;
constexpr int kMaxDownsample = 8;
// Below this rasterised area (px^2) a polygon is a point: the rounding of its span ends at 4K
// coordinates (~1e-12 px), divided by A, would exceed 1e-4 of its value.
constexpr double kPointArea = 1e-9;

// floor and ceil without a libm call (baseline x86-64 has no rounding instruction); values beyond
// 2^52 are integers already.
inline double fast_floor(double v) {
  if (!(std::abs(v) < 4.5e15)) return v;
  const auto t = static_cast<double>(static_cast<std::int64_t>(v));
  return t > v ? t - 1.0 : t;
}
inline double fast_ceil(double v) { return -fast_floor(-v); }

// t limited to [-2, width + 2], where every visible pixel already sees h_t = 1 or 0; NaN goes low.
inline double clamp_end(double t, double width) {
  return t > width + 2.0 ? width + 2.0 : (t >= -2.0 ? t : -2.0);
}

// First differences of one span end's tent profile at entries first .. first + 2. A span end t
// contributes h_t(i) = 1 - Phi(t - (i + 0.5)) to pixel i, Phi the integral of the unit tent: h_t is
// 0 up to k = floor(t - 1.5) and 1 from k + 3, and its differences at k+1..k+3 are the quadratic
// B-spline weights of f = t - 1.5 - k. t must be clamped (clamp_end).
struct EndWeights {
  int first;
  double q[3];
};
inline EndWeights end_weights(double t) {
  const double u = t - 1.5;
  int k = static_cast<int>(u);
  if (k > u) --k;
  const double f = u - k;
  EndWeights e;
  e.first = k + 1;
  e.q[0] = 0.5 * (1.0 - f) * (1.0 - f);
  e.q[2] = 0.5 * f * f;
  e.q[1] = 1.0 - e.q[0] - e.q[2];
  return e;
}

// e[c] += w * v[c] for the four channels, written so that GCC makes it one 256-bit operation.
inline void add_scaled(double* e, double w, const double v[kChannels]) {
  const double e0 = e[0] + w * v[0];
  const double e1 = e[1] + w * v[1];
  const double e2 = e[2] + w * v[2];
  const double e3 = e[3] + w * v[3];
  e[0] = e0;
  e[1] = e1;
  e[2] = e2;
  e[3] = e3;
}

// Adds q[j] * coef[c] to entry first + j, channel c. Entries left of 0 fold into entry 0 (the
// prefix sums of visible pixels stay right); entries at width and beyond are dropped.
inline void add_weights(double* row, int width, int first, const double q[3], const double coef[kChannels]) {
  if (first >= 0 && first + 2 < width) {
    double* e = row + static_cast<std::ptrdiff_t>(first) * kChannels;
    for (int j = 0; j < 3; ++j, e += kChannels) add_scaled(e, q[j], coef);
    return;
  }
  for (int j = 0; j < 3; ++j) {
    const int i = first + j;
    if (i >= width) break;
    double* e = row + static_cast<std::ptrdiff_t>(std::max(i, 0)) * kChannels;
    for (int c = 0; c < kChannels; ++c) e[c] += q[j] * coef[c];
  }
}

inline bool finite_value(const std::array<float, 4>& value) {
  return std::isfinite(value[0]) && std::isfinite(value[1]) && std::isfinite(value[2]) && std::isfinite(value[3]);
}

// Per sub-row count s (1..kMaxSubrows) and sub-row m in [0, s): the upper of the two pixel rows its
// tent reaches relative to the pixel row it lies in (-1 or 0), and the tent weight of the lower row
// (the upper row gets 1 - weight).
struct SubrowTent {
  int upper_offset[kMaxSubrows + 1][kMaxSubrows];
  double lower_weight[kMaxSubrows + 1][kMaxSubrows];
};
// Made at compile time: read per sub-row of every polygon, it needs no guard of a lazy static.
constexpr SubrowTent make_subrow_tent() {
  SubrowTent t{};
  for (int s = 1; s <= kMaxSubrows; ++s) {
    for (int m = 0; m < s; ++m) {
      // Sub-row centre relative to its pixel row's centre, in (-0.5, 0.5).
      const double offset = (m + 0.5) / s - 0.5;
      const int upper = offset < 0.0 ? -1 : 0;
      t.upper_offset[s][m] = upper;
      t.lower_weight[s][m] = offset - upper;
    }
  }
  return t;
}
constexpr SubrowTent kSubrowTent = make_subrow_tent();

// floor(a / b) for b > 0.
inline std::int64_t floor_div(std::int64_t a, std::int64_t b) {
  const std::int64_t q = a / b;
  return (a % b != 0 && a < 0) ? q - 1 : q;
}

}  // namespace

std::string Point2f::to_string() const {
  std::ostringstream os;
  os << '(' << x << ", " << y << ')';
  return os.str();
}

double polygon_area(std::span<const Point2f> vertices) {
  const std::size_t n = vertices.size();
  if (n < 3) return 0.0;
  double twice = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const Point2f& p = vertices[i];
    const Point2f& q = vertices[(i + 1) % n];
    twice += static_cast<double>(p.x) * q.y - static_cast<double>(q.x) * p.y;
  }
  return 0.5 * std::abs(twice);
}

void SplatOptions::validate() const {
  if (downsample < 1 || downsample > kMaxDownsample) {
    throw OptionsError("SplatOptions::downsample = " + std::to_string(downsample) + ": must lie in [1, " +
                       std::to_string(kMaxDownsample) + "]");
  }
  if (subrows < 1 || subrows > kMaxSubrows) {
    throw OptionsError("SplatOptions::subrows = " + std::to_string(subrows) + ": must lie in [1, " +
                       std::to_string(kMaxSubrows) + "]");
  }
}

std::string SplatOptions::to_string() const {
  return "SplatOptions(subrows " + std::to_string(subrows) + (downsample > 1 ? ", downsample " + std::to_string(downsample) : "") + ")";
}

SplatBuffer::SplatBuffer(int width_px, int row_begin, int row_end, const SplatOptions& options)
    : width_(width_px), options_(options) {
  options_.validate();
  if (width_px < 1) {
    throw OptionsError("SplatBuffer: width " + std::to_string(width_px) + " px: need width >= 1");
  }
  reset(row_begin, row_end);
}

void SplatBuffer::reset(int row_begin, int row_end) {
  if (row_begin < 0 || row_end < row_begin) {
    throw OptionsError("SplatBuffer: width " + std::to_string(width_) + " px, rows [" + std::to_string(row_begin) +
                       ", " + std::to_string(row_end) + "): need width >= 1 and 0 <= row_begin <= row_end");
  }
  // Every entry 0 once the rows written are, zeroed in the layout of the band that wrote them.
  zero_dirty_rows();
  row_begin_ = row_begin;
  row_end_ = row_end;
  // The grid: 1 / downsample of the output's resolution, one cell more on each side than the
  // output's band needs so that the bilinear upsampling of every band row has both neighbours.
  const int k = options_.downsample;
  scale_ = 1.0 / k;
  x_offset_ = k > 1 ? 1.0 : 0.0;
  grid_width_ = k > 1 ? (width_ + k - 1) / k + 2 : width_;
  grid_row_begin_ = k > 1 ? static_cast<int>(fast_floor((row_begin + 0.5) * scale_ - 0.5)) : row_begin;
  grid_row_end_ = k > 1 ? static_cast<int>(fast_floor((row_end - 0.5) * scale_ - 0.5)) + 2 : row_end;
  if (row_end == row_begin) grid_row_end_ = grid_row_begin_;
  // resize keeps the capacity: a buffer reused band after band allocates (and faults in) once.
  const std::size_t size = static_cast<std::size_t>(grid_width_) * static_cast<std::size_t>(grid_row_end_ - grid_row_begin_) * kChannels;
  diff_.resize(size, 0.0);
  if (!dense_.empty()) dense_.resize(size, 0.0f);
  dense_used_ = false;
  skipped_ = 0;
}

void SplatBuffer::zero_dirty_rows() {
  if (dirty_first_ <= dirty_last_) {
    const std::size_t row_size = static_cast<std::size_t>(grid_width_) * kChannels;
    const std::size_t begin = static_cast<std::size_t>(dirty_first_ - grid_row_begin_) * row_size;
    const std::size_t end = static_cast<std::size_t>(dirty_last_ + 1 - grid_row_begin_) * row_size;
    std::fill(diff_.begin() + static_cast<std::ptrdiff_t>(std::min(begin, diff_.size())),
              diff_.begin() + static_cast<std::ptrdiff_t>(std::min(end, diff_.size())), 0.0);
    std::fill(dense_.begin() + static_cast<std::ptrdiff_t>(std::min(begin, dense_.size())),
              dense_.begin() + static_cast<std::ptrdiff_t>(std::min(end, dense_.size())), 0.0f);
  }
  dirty_first_ = std::numeric_limits<int>::max();
  dirty_last_ = std::numeric_limits<int>::min();
}

void SplatBuffer::touch_cells(double top, double bottom) {
  if (!(top <= bottom)) return;  // nothing finite
  // A sub-row's tent reaches the pixel row above or below its own; two rows of margin, and the
  // y range clamped to the band before it becomes an int.
  const double lowest = grid_row_begin_ - 4.0, highest = grid_row_end_ + 4.0;
  const int first = static_cast<int>(std::floor(std::clamp(top, lowest, highest))) - 2;
  const int last = static_cast<int>(std::floor(std::clamp(bottom, lowest, highest))) + 2;
  touch(std::max(first, grid_row_begin_), std::min(last, grid_row_end_ - 1));
}

void SplatBuffer::clear() {
  zero_dirty_rows();
  dense_used_ = false;
  skipped_ = 0;
}

void SplatBuffer::add_point(Point2f p, const std::array<float, 4>& value) {
  if (!std::isfinite(p.x) || !std::isfinite(p.y) || !finite_value(value)) {
    ++skipped_;
    return;
  }
  deposit_point(p.x, p.y, value);
}

void SplatBuffer::deposit_point(double x_out_px, double y_out_px, const std::array<float, 4>& value) {
  deposit_grid_point(x_out_px * scale_ + x_offset_, y_out_px * scale_, value);
}

void SplatBuffer::deposit_grid_point(double x_px, double y_px, const std::array<float, 4>& value) {
  // Only rows whose centres lie within 1 of y receive anything; this also keeps floor() in int range.
  if (!(y_px > grid_row_begin_ - 0.5 && y_px < grid_row_end_ + 0.5)) return;
  const double x = clamp_end(x_px, grid_width_);
  // Bilinear weights: pixel i0 gets 1 - fx, i0 + 1 gets fx; as differences at i0 .. i0 + 2.
  const double i0 = fast_floor(x - 0.5);
  const double fx = x - 0.5 - i0;
  const double q[3] = {1.0 - fx, 2.0 * fx - 1.0, -fx};
  const double j0 = fast_floor(y_px - 0.5);
  const double fy = y_px - 0.5 - j0;
  const int rows[2] = {static_cast<int>(j0), static_cast<int>(j0) + 1};
  const double row_weight[2] = {1.0 - fy, fy};
  for (int r = 0; r < 2; ++r) {
    if (rows[r] < grid_row_begin_ || rows[r] >= grid_row_end_) continue;
    touch(rows[r], rows[r]);
    double coef[kChannels];
    for (int c = 0; c < kChannels; ++c) coef[c] = row_weight[r] * value[static_cast<std::size_t>(c)];
    add_weights(diff_.data() + static_cast<std::size_t>(rows[r] - grid_row_begin_) * grid_width_ * kChannels, grid_width_,
                static_cast<int>(i0), q, coef);
  }
}

void SplatBuffer::add_triangle(Point2f a, Point2f b, Point2f c, const std::array<float, 4>& value) {
  const Point2f v[3] = {a, b, c};
  add_polygon(v, value);
}

bool SplatBuffer::build_chains(std::span<const Point2f> vertices, int subrows) {
  const std::size_t n = vertices.size();
  std::size_t top = 0;
  std::size_t bottom = 0;
  for (std::size_t i = 1; i < n; ++i) {
    if (vertices[i].y < vertices[top].y) top = i;
    if (vertices[i].y > vertices[bottom].y) bottom = i;
  }
  const double s = subrows;
  bool monotone = true;
  auto build = [&](std::vector<ChainVertex>& chain, bool forward) {
    chain.clear();
    double first = -std::numeric_limits<double>::infinity();
    double last_y = -std::numeric_limits<double>::infinity();
    for (std::size_t i = top;; i = forward ? (i + 1 == n ? 0 : i + 1) : (i == 0 ? n - 1 : i - 1)) {
      const double x = vertices[i].x;
      const double y = vertices[i].y;
      monotone = monotone && y >= last_y;
      last_y = y;
      // Sub-row centre (k + 0.5) / S >= y  <=>  k >= y S - 0.5.
      first = std::max(first, fast_ceil(y * s - 0.5));
      chain.push_back({x, y, first, 0.0});
      if (i == bottom) break;
    }
    // An edge that covers sub-rows rises strictly in y (its first sub-rows differ), so dy > 0.
    for (std::size_t k = 0; k + 1 < chain.size(); ++k) {
      ChainVertex& p = chain[k];
      const ChainVertex& q = chain[k + 1];
      if (q.first_subrow > p.first_subrow) p.slope = (q.x - p.x) / (q.y - p.y);
    }
  };
  build(forward_chain_, true);
  build(backward_chain_, false);
  return monotone;
}

// The pixel rows of the band that sub-row class m of pixel row `pixel_row` reaches with its tent (the
// row above or below and its own), each as its first differences and its tent weight: add(row, weight).
template <class Add>
inline __attribute__((always_inline)) void SplatBuffer::tent_rows(int pixel_row, int subrows, int m, Add&& add) {
  const int upper = pixel_row + kSubrowTent.upper_offset[subrows][m];
  const double lower_weight = kSubrowTent.lower_weight[subrows][m];
  for (int r = 0; r < 2; ++r) {
    const int row = upper + r;
    const double row_weight = r == 0 ? 1.0 - lower_weight : lower_weight;
    // One sub-row per pixel row samples the row's centre, which the tent gives wholly to it.
    if (row < grid_row_begin_ || row >= grid_row_end_ || row_weight == 0.0) continue;
    add(diff_.data() + static_cast<std::size_t>(row - grid_row_begin_) * grid_width_ * kChannels, row_weight);
  }
}

// One sub-row's span from x_enter (+) to x_leave (-), its tent-filtered x profile as first
// differences into the two pixel rows the sub-row's tent reaches (sub-row class m of pixel row
// `pixel_row`); `unit` is the deposit per unit span length.
inline __attribute__((always_inline)) void SplatBuffer::deposit_span(int pixel_row, int subrows, int m, double x_enter,
                                                                      double x_leave, const double unit[4]) {
  const double w = grid_width_;
  const EndWeights a = end_weights(clamp_end(x_enter, w));
  const EndWeights b = end_weights(clamp_end(x_leave, w));
  const double minus_qb[3] = {-b.q[0], -b.q[1], -b.q[2]};
  tent_rows(pixel_row, subrows, m, [&](double* row_diff, double row_weight) {
    double coef[kChannels];
    for (int c = 0; c < kChannels; ++c) coef[c] = row_weight * unit[c];
    add_weights(row_diff, grid_width_, a.first, a.q, coef);
    add_weights(row_diff, grid_width_, b.first, minus_qb, coef);
  });
}

inline __attribute__((always_inline)) void SplatBuffer::deposit_end(int pixel_row, int subrows, int m, double x, const double coef[4]) {
  const EndWeights e = end_weights(clamp_end(x, grid_width_));
  tent_rows(pixel_row, subrows, m, [&](double* row_diff, double row_weight) {
    double weighted[kChannels];
    for (int c = 0; c < kChannels; ++c) weighted[c] = row_weight * coef[c];
    add_weights(row_diff, grid_width_, e.first, e.q, weighted);
  });
}

// Function multi-versioning as add_polygon (below).
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
__attribute__((target_clones("arch=x86-64-v3", "default")))
#endif
void SplatBuffer::add_mesh(std::span<const Point2f> vertices, std::span<const std::array<std::uint32_t, 2>> edges,
                           std::span<const MeshCell> cells, const std::array<float, 4>& value, Point2f offset, int mesh_subrows) {
  if (mesh_subrows < 0 || mesh_subrows > kMaxSubrows) {
    throw OptionsError("SplatBuffer::add_mesh: " + std::to_string(mesh_subrows) + " sub-rows: must lie in [1, " +
                       std::to_string(kMaxSubrows) + "], or 0 for the buffer's own");
  }
  const auto out_of_range = [&](std::size_t index, std::size_t size, const char* what) {
    return OptionsError("SplatBuffer::add_mesh: " + std::string(what) + " " + std::to_string(index) + " of " + std::to_string(size));
  };
  const int subrows = mesh_subrows > 0 ? mesh_subrows : options_.subrows;
  const double s = subrows;
  if (!finite_value(value) || !std::isfinite(offset.x) || !std::isfinite(offset.y)) {
    skipped_ += cells.size();
    return;
  }
  const auto cell_x = [&](float x_px) { return (static_cast<double>(x_px) + offset.x) * scale_ + x_offset_; };
  const auto cell_y = [&](float y_px) { return (static_cast<double>(y_px) + offset.y) * scale_; };
  // Each edge's sub-rows by the rule of the chains (a sub-row centre c with y_upper <= c < y_lower),
  // and its x summed over them (count * x at the mean sub-row's y), of which a cell's rasterised area
  // is the signed sum over its edges: what add_polygon's spans would sum to.
  edge_runs_.resize(edges.size());
  double mesh_top = std::numeric_limits<double>::infinity(), mesh_bottom = -mesh_top;  // of its finite edges, cells
  for (std::size_t i = 0; i < edges.size(); ++i) {
    const auto [from, to] = edges[i];
    if (from >= vertices.size() || to >= vertices.size()) throw out_of_range(std::max(from, to), vertices.size(), "an edge names vertex");
    const double px = cell_x(vertices[from].x), py = cell_y(vertices[from].y);
    const double qx = cell_x(vertices[to].x), qy = cell_y(vertices[to].y);
    EdgeRun& r = edge_runs_[i];
    r.light = 0.0;
    r.coverage = 0.0;
    const bool up = qy < py;
    r.up = up ? 1.0 : -1.0;
    r.x = up ? qx : px;
    r.y = up ? qy : py;
    const double lower_x = up ? px : qx, lower_y = up ? py : qy;
    if (std::isfinite(r.y) && std::isfinite(lower_y)) {
      mesh_top = std::min(mesh_top, r.y);
      mesh_bottom = std::max(mesh_bottom, lower_y);
    }
    r.first = fast_ceil(r.y * s - 0.5);
    r.last = fast_ceil(lower_y * s - 0.5);
    if (!(r.first < r.last)) {
      // Horizontal, between two sub-rows, or not finite (then so is every area it enters).
      r.last = r.first;
      r.slope = 0.0;
      const bool finite = std::isfinite(px) && std::isfinite(py) && std::isfinite(qx) && std::isfinite(qy);
      r.x_sum = finite ? 0.0 : std::numeric_limits<double>::quiet_NaN();
      continue;
    }
    r.slope = (lower_x - r.x) / (lower_y - r.y);
    r.x_sum = (r.last - r.first) * (r.x + r.slope * ((r.first + r.last) / (2.0 * s) - r.y));
  }
  touch_cells(mesh_top, mesh_bottom);
  // Each cell's density steps onto its edges: walked upwards, an edge has a positively oriented
  // cell's inside on its +x side, so the cell's indicator steps by direction * up there, and a
  // sub-row's integral of the steps is -sum step * x.
  for (const MeshCell& t : cells) {
    if (t.corners < 3 || t.corners > MeshCell::kMaxCorners) {
      throw OptionsError("SplatBuffer::add_mesh: a cell of " + std::to_string(t.corners) + " corners: must have 3 or 4");
    }
    double signed_area = 0.0;
    for (std::size_t k = 0; k < t.corners; ++k) {
      if (t.edge[k] >= edges.size()) throw out_of_range(t.edge[k], edges.size(), "a cell names edge");
      if (t.corner[k] >= vertices.size()) throw out_of_range(t.corner[k], vertices.size(), "a cell names vertex");
      const EdgeRun& r = edge_runs_[t.edge[k]];
      signed_area -= t.direction[k] * r.up * r.x_sum;
    }
    signed_area /= s;
    if (!std::isfinite(signed_area) || !std::isfinite(t.light) || !std::isfinite(t.coverage)) {
      ++skipped_;
      continue;
    }
    if (std::abs(signed_area) < kPointArea) {
      double cx = 0.0, cy = 0.0;
      for (std::size_t k = 0; k < t.corners; ++k) {
        cx += cell_x(vertices[t.corner[k]].x);
        cy += cell_y(vertices[t.corner[k]].y);
      }
      const double n = t.corners;
      deposit_grid_point(cx / n, cy / n, {value[0] * t.light, value[1] * t.light, value[2] * t.light, value[3] * t.coverage});
      continue;
    }
    const double light = t.light / signed_area, coverage = t.coverage / signed_area;
    for (std::size_t k = 0; k < t.corners; ++k) {
      EdgeRun& r = edge_runs_[t.edge[k]];
      r.light += t.direction[k] * light;
      r.coverage += t.direction[k] * coverage;
    }
  }
  // One span end per edge and sub-row, carrying the difference of the densities either side.
  const double lo = fast_ceil((grid_row_begin_ - 0.5) * s - 0.5);
  const double hi = fast_ceil((grid_row_end_ + 0.5) * s - 0.5);
  const double inv_s = 1.0 / s;
  for (const EdgeRun& r : edge_runs_) {
    if (r.light == 0.0 && r.coverage == 0.0) continue;
    const double from = std::max(r.first, lo), to = std::min(r.last, hi);
    if (!(from < to)) continue;
    const double l = r.up * r.light * inv_s, c = r.up * r.coverage * inv_s;
    const double coef[kChannels] = {l * value[0], l * value[1], l * value[2], c * value[3]};
    const auto s_lo = static_cast<std::int64_t>(from);
    const auto s_hi = static_cast<std::int64_t>(to);
    std::int64_t pixel_row = floor_div(s_lo, subrows);
    auto m = static_cast<int>(s_lo - pixel_row * subrows);
    for (std::int64_t sub = s_lo; sub < s_hi; ++sub) {
      const double y = (static_cast<double>(sub) + 0.5) * inv_s;
      deposit_end(static_cast<int>(pixel_row), subrows, m, r.x + r.slope * (y - r.y), coef);
      if (++m == subrows) {
        m = 0;
        ++pixel_row;
      }
    }
  }
}

void SplatBuffer::add_general_polygon(std::span<const Point2f> vertices, int subrows, double cx, double cy,
                                      const std::array<float, 4>& value) {
  // Edges as sub-row ranges, by the rule of the chains: an edge covers the sub-row centres c with
  // y_upper <= c < y_lower, so each sub-row crosses an even number of edges.
  const double s = subrows;
  edges_.clear();
  const std::size_t n = vertices.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Point2f& p = vertices[i];
    const Point2f& q = vertices[i + 1 == n ? 0 : i + 1];
    if (p.y == q.y) continue;
    const Point2f& up = p.y < q.y ? p : q;
    const Point2f& down = p.y < q.y ? q : p;
    const double first = fast_ceil(up.y * s - 0.5), last = fast_ceil(down.y * s - 0.5);
    if (!(first < last)) continue;
    edges_.push_back({first, last, up.x, up.y, (static_cast<double>(down.x) - up.x) / (static_cast<double>(down.y) - up.y)});
  }
  std::sort(edges_.begin(), edges_.end(), [](const Edge& a, const Edge& b) { return a.first < b.first; });
  // Spans by even-odd pairs of the crossings of each sub-row, sorted along x.
  spans_.clear();
  double span_length = 0.0;  // summed over every sub-row, px
  std::size_t next = 0;
  std::vector<std::size_t>& active = active_edges_;
  active.clear();
  double bottom = -std::numeric_limits<double>::infinity();
  for (const Edge& e : edges_) bottom = std::max(bottom, e.last);
  for (double sub = edges_.empty() ? 0.0 : edges_.front().first; sub < bottom; sub += 1.0) {
    while (next < edges_.size() && edges_[next].first <= sub) active.push_back(next++);
    std::erase_if(active, [&](std::size_t k) { return edges_[k].last <= sub; });
    const double y = (sub + 0.5) / s;
    crossings_.clear();
    for (std::size_t k : active) crossings_.push_back(edges_[k].x + edges_[k].slope * (y - edges_[k].y));
    std::sort(crossings_.begin(), crossings_.end());
    for (std::size_t j = 0; j + 1 < crossings_.size(); j += 2) {
      spans_.push_back({sub, crossings_[j], crossings_[j + 1]});
      span_length += crossings_[j + 1] - crossings_[j];
    }
  }
  const double area = span_length / s;
  if (!std::isfinite(area)) {
    ++skipped_;
    return;
  }
  if (area < kPointArea) {
    deposit_grid_point(cx, cy, value);
    return;
  }
  const double lo = fast_ceil((grid_row_begin_ - 0.5) * s - 0.5);
  const double hi = fast_ceil((grid_row_end_ + 0.5) * s - 0.5);
  double unit[kChannels];
  for (int c = 0; c < kChannels; ++c) unit[c] = value[static_cast<std::size_t>(c)] / (area * s);
  for (const SubrowSpan& span : spans_) {
    if (span.subrow < lo || span.subrow >= hi) continue;
    const auto sub = static_cast<std::int64_t>(span.subrow);
    const std::int64_t pixel_row = floor_div(sub, subrows);
    deposit_span(static_cast<int>(pixel_row), subrows, static_cast<int>(sub - pixel_row * subrows), span.x_enter, span.x_leave, unit);
  }
}

// With GCC on x86-64, built twice, for AVX2+FMA (x86-64-v3) and for the baseline, and chosen at
// load time (function multi-versioning): its four-channel double updates become one 256-bit
// operation each (the thin-lens render of bench/blender's scene: 0.72 s -> 0.59 s on one core).
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
__attribute__((target_clones("arch=x86-64-v3", "default")))
#endif
void SplatBuffer::add_polygon(std::span<const Point2f> output_vertices, const std::array<float, 4>& value, int polygon_subrows) {
  if (polygon_subrows < 0 || polygon_subrows > kMaxSubrows) {
    throw OptionsError("SplatBuffer::add_polygon: " + std::to_string(polygon_subrows) + " sub-rows: must lie in [1, " +
                       std::to_string(kMaxSubrows) + "], or 0 for the buffer's own");
  }
  const int subrows = polygon_subrows > 0 ? polygon_subrows : options_.subrows;
  std::span<const Point2f> vertices = output_vertices;
  if (options_.downsample > 1) {
    // To grid cells; float keeps 1e-6 of a cell's size at 4K / k.
    scaled_.resize(output_vertices.size());
    const auto scale = static_cast<float>(scale_), offset = static_cast<float>(x_offset_);
    for (std::size_t i = 0; i < output_vertices.size(); ++i) {
      scaled_[i] = {output_vertices[i].x * scale + offset, output_vertices[i].y * scale};
    }
    vertices = scaled_;
  }
  const std::size_t n = vertices.size();
  bool finite = n > 0 && finite_value(value);
  double cx = 0.0;
  double cy = 0.0;
  for (const Point2f& p : vertices) {
    finite = finite && std::isfinite(p.x) && std::isfinite(p.y);
    cx += p.x;
    cy += p.y;
  }
  if (!finite) {
    ++skipped_;
    return;
  }
  cx /= static_cast<double>(n);
  cy /= static_cast<double>(n);
  if (n < 3) {
    deposit_grid_point(cx, cy, value);
    return;
  }
  {
    // The rows its sub-rows' tents may reach (marked once here, not span by span: Seidel's mesh
    // footprints at 1080p took 15 % longer marked in the spans' loop).
    double top = vertices[0].y, bottom = top;
    for (const Point2f& p : vertices) {
      top = std::min(top, static_cast<double>(p.y));
      bottom = std::max(bottom, static_cast<double>(p.y));
    }
    touch_cells(top, bottom);
  }
  if (!build_chains(vertices, subrows)) {
    // Not y-monotone: two chains would smear it between them.
    add_general_polygon(vertices, subrows, cx, cy, value);
    return;
  }

  // Rasterised area in closed form, O(vertices): an edge is linear in y over its sub-rows, so the sum
  // of its x over them is count * x(mean sub-row y). The scan below assigns sub-rows to edges by the
  // same first_subrow bounds, so what it deposits sums to this area up to rounding.
  const double s = subrows;
  auto chain_x_sum = [s](const std::vector<ChainVertex>& chain) {
    double sum = 0.0;
    for (std::size_t k = 0; k + 1 < chain.size(); ++k) {
      const ChainVertex& p = chain[k];
      const double count = chain[k + 1].first_subrow - p.first_subrow;
      const double mean_y = (p.first_subrow + chain[k + 1].first_subrow) / (2.0 * s);
      if (count > 0.0) sum += count * (p.x + p.slope * (mean_y - p.y));
    }
    return sum;
  };
  // Spans run from the forward chain (enter, +) to the backward chain (leave, -); for the other
  // winding both the spans and the area change sign, so the deposit does not.
  const double area = (chain_x_sum(backward_chain_) - chain_x_sum(forward_chain_)) / s;
  if (!std::isfinite(area)) {
    ++skipped_;
    return;
  }
  if (std::abs(area) < kPointArea) {
    deposit_grid_point(cx, cy, value);
    return;
  }

  // Sub-rows that reach a band row: centres within 1 of a band row's centre, (row_begin - 0.5,
  // row_end + 0.5) in y.
  const double subrow_top = forward_chain_.front().first_subrow;
  const double subrow_bottom = forward_chain_.back().first_subrow;  // exclusive
  const double lo = std::max(subrow_top, fast_ceil((grid_row_begin_ - 0.5) * s - 0.5));
  const double hi = std::min(subrow_bottom, fast_ceil((grid_row_end_ + 0.5) * s - 0.5));
  if (!(lo < hi)) return;

  double unit[kChannels];  // deposit per unit span length of one sub-row
  for (int c = 0; c < kChannels; ++c) unit[c] = value[static_cast<std::size_t>(c)] / (area * s);

  // Walk both chains: each edge is entered once, so the scan costs O(vertices + sub-rows).
  const ChainVertex* ef = forward_chain_.data();
  const ChainVertex* eb = backward_chain_.data();
  while (ef[1].first_subrow <= lo) ++ef;
  while (eb[1].first_subrow <= lo) ++eb;
  const auto s_lo = static_cast<std::int64_t>(lo);
  const auto s_hi = static_cast<std::int64_t>(hi);
  std::int64_t pixel_row = floor_div(s_lo, subrows);
  auto m = static_cast<int>(s_lo - pixel_row * subrows);
  const double inv_s = 1.0 / s;
  for (std::int64_t sub = s_lo; sub < s_hi; ++sub) {
    const auto sub_d = static_cast<double>(sub);
    while (ef[1].first_subrow <= sub_d) ++ef;
    while (eb[1].first_subrow <= sub_d) ++eb;
    const double y = (sub_d + 0.5) * inv_s;
    deposit_span(static_cast<int>(pixel_row), subrows, m, ef->x + ef->slope * (y - ef->y), eb->x + eb->slope * (y - eb->y), unit);
    if (++m == subrows) {
      m = 0;
      ++pixel_row;
    }
  }
}

std::string DifferenceStamp::to_string() const {
  const std::size_t rows = row_entries.empty() ? 0 : row_entries.size() - 1;
  return "DifferenceStamp(" + std::to_string(rows) + " rows, " + std::to_string(entries()) + " entries)";
}

DifferenceStamp SplatBuffer::record(std::span<const Point2f> vertices, int subrows) {
  DifferenceStamp stamp;
  float x_min = std::numeric_limits<float>::infinity(), x_max = -x_min, y_min = x_min, y_max = -x_min;
  for (const Point2f& p : vertices) {
    x_min = std::min(x_min, p.x);
    x_max = std::max(x_max, p.x);
    y_min = std::min(y_min, p.y);
    y_max = std::max(y_max, p.y);
  }
  if (vertices.empty() || !(std::isfinite(x_min) && std::isfinite(x_max) && std::isfinite(y_min) && std::isfinite(y_max))) {
    return stamp;
  }
  // A buffer around the polygon moved by whole pixels so that its tent (1.5 px from a span end)
  // never reaches the buffer's edges, where add_polygon folds or drops entries.
  constexpr int kPad = 4;
  const int shift_x = kPad - static_cast<int>(fast_floor(x_min));
  const int shift_y = kPad - static_cast<int>(fast_floor(y_min));
  const int width = static_cast<int>(fast_ceil(x_max)) + shift_x + kPad;
  const int rows = static_cast<int>(fast_ceil(y_max)) + shift_y + kPad;
  SplatOptions options;
  options.subrows = subrows;
  SplatBuffer buffer(width, 0, rows, options);
  std::vector<Point2f> moved(vertices.begin(), vertices.end());
  for (Point2f& p : moved) p = {p.x + static_cast<float>(shift_x), p.y + static_cast<float>(shift_y)};
  buffer.add_polygon(moved, {1.0f, 0.0f, 0.0f, 0.0f});
  if (buffer.skipped() > 0) return stamp;
  stamp.first_row = -shift_y;
  stamp.row_entries.push_back(0);
  for (int r = 0; r < rows; ++r) {
    const double* d = buffer.diff_.data() + static_cast<std::size_t>(r) * static_cast<std::size_t>(width) * kChannels;
    for (int x = 0; x < width; ++x) {
      const double v = d[static_cast<std::size_t>(x) * kChannels];
      if (v == 0.0) continue;
      stamp.column.push_back(x - shift_x);
      stamp.weight.push_back(v);
    }
    stamp.row_entries.push_back(static_cast<std::uint32_t>(stamp.column.size()));
  }
  return stamp;
}

#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
__attribute__((target_clones("arch=x86-64-v3", "default")))
#endif
void SplatBuffer::add_stamp(const DifferenceStamp& stamp, int anchor_x, int anchor_y, const std::array<float, 4>& value) {
  if (options_.downsample != 1) throw OptionsError("SplatBuffer::add_stamp: " + to_string() + " is not at full resolution");
  if (!finite_value(value)) {
    ++skipped_;
    return;
  }
  const int rows = static_cast<int>(stamp.row_entries.size()) - 1;
  const int r_begin = std::max(0, row_begin_ - anchor_y - stamp.first_row);
  const int r_end = std::min(rows, row_end_ - anchor_y - stamp.first_row);
  const double v[kChannels] = {value[0], value[1], value[2], value[3]};
  const std::int32_t* column = stamp.column.data();
  const double* weight = stamp.weight.data();
  if (r_begin < r_end) touch(anchor_y + stamp.first_row + r_begin, anchor_y + stamp.first_row + r_end - 1);
  for (int r = r_begin; r < r_end; ++r) {
    const int row = anchor_y + stamp.first_row + r;
    double* row_diff = diff_.data() + static_cast<std::size_t>(row - row_begin_) * static_cast<std::size_t>(width_) * kChannels;
    const std::uint32_t end = stamp.row_entries[static_cast<std::size_t>(r) + 1];
    for (std::uint32_t k = stamp.row_entries[static_cast<std::size_t>(r)]; k < end; ++k) {
      int x = anchor_x + column[k];
      if (x >= width_) continue;
      x = std::max(x, 0);
      add_scaled(row_diff + static_cast<std::size_t>(x) * kChannels, weight[k], v);
    }
  }
}

namespace {

// add_image's samples along a row: `count` pixels from image position (u0, v0) (in samples) in
// steps of (du, dv), bilinear, clamped to the image; writes up to kImageRowPadding past `count`.
constexpr std::size_t kImageRowPadding = 8;


float sample_image_row_scalar(const float* data, int nx, int ny, float u0, float v0, float du, float dv, std::size_t count, float* out) {
  float sum = 0.0f;
  const auto um = static_cast<float>(nx - 1), vm = static_cast<float>(ny - 1);
  for (std::size_t k = 0; k < count; ++k) {
    const auto t = static_cast<float>(k);
    const float u = std::min(std::max(u0 + du * t, 0.0f), um), w = std::min(std::max(v0 + dv * t, 0.0f), vm);
    const int iu = std::min(static_cast<int>(u), nx - 2), iv = std::min(static_cast<int>(w), ny - 2);
    const float fu = u - static_cast<float>(iu), fv = w - static_cast<float>(iv);
    const float* s = data + static_cast<std::ptrdiff_t>(iv) * nx + iu;
    const float top = s[0] + fu * (s[1] - s[0]), bottom = s[nx] + fu * (s[nx + 1] - s[nx]);
    out[k] = top + fv * (bottom - top);
    sum += out[k];
  }
  return sum;
}

#if defined(__GNUC__) && defined(__x86_64__)
// Eight pixels at a time with AVX2's gathers (the compiler does not vectorise the scalar loop).
__attribute__((target("avx2,fma"))) float sample_image_row_avx2(const float* data, int nx, int ny, float u0, float v0, float du, float dv,
                                                                std::size_t count, float* out) {
  __m256 sum = _mm256_setzero_ps();
  const __m256 end = _mm256_set1_ps(static_cast<float>(count));
  const __m256 zero = _mm256_setzero_ps();
  const __m256 um = _mm256_set1_ps(static_cast<float>(nx - 1)), vm = _mm256_set1_ps(static_cast<float>(ny - 1));
  const __m256i last_u = _mm256_set1_epi32(nx - 2), last_v = _mm256_set1_epi32(ny - 2), width = _mm256_set1_epi32(nx);
  const __m256 step_u = _mm256_set1_ps(du), step_v = _mm256_set1_ps(dv);
  __m256 t = _mm256_setr_ps(0.0f, 1.0f, 2.0f, 3.0f, 4.0f, 5.0f, 6.0f, 7.0f);
  const __m256 eight = _mm256_set1_ps(8.0f);
  const __m256 start_u = _mm256_set1_ps(u0), start_v = _mm256_set1_ps(v0);
  const __m256i pair_order = _mm256_setr_epi32(0, 1, 4, 5, 2, 3, 6, 7);
  // The masked form with every lane on (the plain one leaves its source undefined, which GCC 12 warns of).
  const __m256d no_pair = _mm256_setzero_pd(), all_pairs = _mm256_castsi256_pd(_mm256_set1_epi64x(-1));
  // The gathers read bytes (the pairs of floats as doubles): the pointers' type is the intrinsic's.
  const auto* top_row = reinterpret_cast<const double*>(data);
  const auto* bottom_row = reinterpret_cast<const double*>(data + nx);
  for (std::size_t k = 0; k < count; k += 8) {
    const __m256 u = _mm256_min_ps(_mm256_max_ps(_mm256_fmadd_ps(step_u, t, start_u), zero), um);
    const __m256 w = _mm256_min_ps(_mm256_max_ps(_mm256_fmadd_ps(step_v, t, start_v), zero), vm);
    const __m256i iu = _mm256_min_epi32(_mm256_cvttps_epi32(u), last_u), iv = _mm256_min_epi32(_mm256_cvttps_epi32(w), last_v);
    const __m256 fu = _mm256_sub_ps(u, _mm256_cvtepi32_ps(iu)), fv = _mm256_sub_ps(w, _mm256_cvtepi32_ps(iv));
    // Each sample's horizontal neighbours as one 8-byte element (gathers need no alignment): half the
    // elements of four float gathers. The indices go in the order (0, 1, 4, 5 | 2, 3, 6, 7), so that
    // shuffling the two halves' pairs gives the samples back in order.
    const __m256i at = _mm256_permutevar8x32_epi32(_mm256_add_epi32(_mm256_mullo_epi32(iv, width), iu), pair_order);
    const __m128i at_lo = _mm256_castsi256_si128(at), at_hi = _mm256_extracti128_si256(at, 1);
    const __m256 top_lo = _mm256_castpd_ps(_mm256_mask_i32gather_pd(no_pair, top_row, at_lo, all_pairs, 4));
    const __m256 top_hi = _mm256_castpd_ps(_mm256_mask_i32gather_pd(no_pair, top_row, at_hi, all_pairs, 4));
    const __m256 bottom_lo = _mm256_castpd_ps(_mm256_mask_i32gather_pd(no_pair, bottom_row, at_lo, all_pairs, 4));
    const __m256 bottom_hi = _mm256_castpd_ps(_mm256_mask_i32gather_pd(no_pair, bottom_row, at_hi, all_pairs, 4));
    const __m256 s00 = _mm256_shuffle_ps(top_lo, top_hi, _MM_SHUFFLE(2, 0, 2, 0)), s01 = _mm256_shuffle_ps(top_lo, top_hi, _MM_SHUFFLE(3, 1, 3, 1));
    const __m256 s10 = _mm256_shuffle_ps(bottom_lo, bottom_hi, _MM_SHUFFLE(2, 0, 2, 0)),
                 s11 = _mm256_shuffle_ps(bottom_lo, bottom_hi, _MM_SHUFFLE(3, 1, 3, 1));
    const __m256 top = _mm256_fmadd_ps(fu, _mm256_sub_ps(s01, s00), s00), bottom = _mm256_fmadd_ps(fu, _mm256_sub_ps(s11, s10), s10);
    const __m256 sample = _mm256_fmadd_ps(fv, _mm256_sub_ps(bottom, top), top);
    _mm256_storeu_ps(out + k, sample);
    sum = _mm256_add_ps(sum, _mm256_and_ps(sample, _mm256_cmp_ps(t, end, _CMP_LT_OQ)));  // the padding past count left out
    t = _mm256_add_ps(t, eight);
  }
  const __m128 half = _mm_add_ps(_mm256_castps256_ps128(sum), _mm256_extractf128_ps(sum, 1));
  const __m128 pair = _mm_add_ps(half, _mm_movehl_ps(half, half));
  return _mm_cvtss_f32(_mm_add_ss(pair, _mm_shuffle_ps(pair, pair, 1)));
}
#endif

// out[4 k + c] += samples[k] value[c] for k < count (add_image's adding of a row's samples).
static_assert(kChannels == 4, "add_scaled_samples spreads a sample over four channels");
void add_scaled_samples_scalar(const float* samples, std::size_t count, const float* value, float* out) {
  for (std::size_t k = 0; k < count; ++k) {
    for (int c = 0; c < 4; ++c) out[k * 4 + static_cast<std::size_t>(c)] += samples[k] * value[c];
  }
}

#if defined(__GNUC__) && defined(__x86_64__)
// Two samples a vector, each spread over its four channels by a permute (the compiler's version of
// the scalar loop transposes blocks of samples, with three times the shuffles).
__attribute__((target("avx2,fma"))) void add_scaled_samples_avx2(const float* samples, std::size_t count, const float* value, float* out) {
  const __m256 v = _mm256_setr_ps(value[0], value[1], value[2], value[3], value[0], value[1], value[2], value[3]);
  const __m256i spread0 = _mm256_setr_epi32(0, 0, 0, 0, 1, 1, 1, 1), spread1 = _mm256_setr_epi32(2, 2, 2, 2, 3, 3, 3, 3);
  const __m256i spread2 = _mm256_setr_epi32(4, 4, 4, 4, 5, 5, 5, 5), spread3 = _mm256_setr_epi32(6, 6, 6, 6, 7, 7, 7, 7);
  std::size_t k = 0;
  for (; k + 8 <= count; k += 8) {
    const __m256 s = _mm256_loadu_ps(samples + k);
    float* o = out + 4 * k;
    _mm256_storeu_ps(o, _mm256_fmadd_ps(_mm256_permutevar8x32_ps(s, spread0), v, _mm256_loadu_ps(o)));
    _mm256_storeu_ps(o + 8, _mm256_fmadd_ps(_mm256_permutevar8x32_ps(s, spread1), v, _mm256_loadu_ps(o + 8)));
    _mm256_storeu_ps(o + 16, _mm256_fmadd_ps(_mm256_permutevar8x32_ps(s, spread2), v, _mm256_loadu_ps(o + 16)));
    _mm256_storeu_ps(o + 24, _mm256_fmadd_ps(_mm256_permutevar8x32_ps(s, spread3), v, _mm256_loadu_ps(o + 24)));
  }
  for (; k + 2 <= count; k += 2) {
    const __m256 s = _mm256_setr_ps(samples[k], samples[k], samples[k], samples[k], samples[k + 1], samples[k + 1], samples[k + 1], samples[k + 1]);
    _mm256_storeu_ps(out + 4 * k, _mm256_fmadd_ps(s, v, _mm256_loadu_ps(out + 4 * k)));
  }
  if (k < count) add_scaled_samples_scalar(samples + k, count - k, value, out + 4 * k);
}

// Whether this processor runs the AVX2 paths above (asked once).
bool avx2_fma() {
  static const bool supported = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  return supported;
}
#endif

void add_scaled_samples(const float* samples, std::size_t count, const float* value, float* out) {
#if defined(__GNUC__) && defined(__x86_64__)
  if (avx2_fma()) return add_scaled_samples_avx2(samples, count, value, out);
#endif
  add_scaled_samples_scalar(samples, count, value, out);
}

// Returns the samples' sum.
float sample_image_row(const float* data, int nx, int ny, float u0, float v0, float du, float dv, std::size_t count, float* out) {
#if defined(__GNUC__) && defined(__x86_64__)
  if (avx2_fma()) return sample_image_row_avx2(data, nx, ny, u0, v0, du, dv, count, out);
#endif
  return sample_image_row_scalar(data, nx, ny, u0, v0, du, dv, count, out);
}

}  // namespace

void SplatBuffer::use_dense() {
  if (dense_used_) return;
  dense_.resize(diff_.size(), 0.0f);  // 0 but in the rows written (zero_dirty_rows)
  dense_used_ = true;
}

#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
__attribute__((target_clones("arch=x86-64-v3", "default")))
#endif
void SplatBuffer::add_points(std::span<const std::array<float, 3>> points, const std::array<float, 4>& from_image, Point2f anchor,
                             const std::array<float, 4>& value) {
  const bool finite_map = std::isfinite(anchor.x) && std::isfinite(anchor.y) &&
                          std::all_of(from_image.begin(), from_image.end(), [](float m) { return std::isfinite(m); });
  if (!finite_value(value) || !finite_map) {
    ++skipped_;
    return;
  }
  use_dense();
  // Bilinear weights over the 2 x 2 cells whose centres surround each point, as add_point's.
  const std::size_t row_size = static_cast<std::size_t>(grid_width_) * kChannels;
  const auto scale = static_cast<float>(scale_), offset = static_cast<float>(x_offset_);
  const float pair_value[2 * kChannels] = {value[0], value[1], value[2], value[3], value[0], value[1], value[2], value[3]};
  for (const auto& [x, y, weight] : points) {
    const float px = (anchor.x + from_image[0] * x + from_image[1] * y) * scale + offset - 0.5f;
    const float py = (anchor.y + from_image[2] * x + from_image[3] * y) * scale - 0.5f;
    if (!(py > static_cast<float>(grid_row_begin_) - 1.0f && py < static_cast<float>(grid_row_end_)) || !(px > -1.0f && px < static_cast<float>(grid_width_))) continue;
    const float x0 = std::floor(px), y0 = std::floor(py);
    const float fx = px - x0, fy = py - y0;
    const int i0 = static_cast<int>(x0), j0 = static_cast<int>(y0);
    const float wx[2] = {1.0f - fx, fx}, wy[2] = {1.0f - fy, fy};
    if (i0 >= 0 && i0 + 1 < grid_width_ && j0 >= grid_row_begin_ && j0 + 1 < grid_row_end_) {
      // All four cells in the band: each row's two cells as one run of 8 floats (a vector).
      const float pair_weight[2 * kChannels] = {wx[0], wx[0], wx[0], wx[0], wx[1], wx[1], wx[1], wx[1]};
      touch(j0, j0 + 1);
      for (int r = 0; r < 2; ++r) {
        float* e = dense_.data() + static_cast<std::size_t>(j0 + r - grid_row_begin_) * row_size + static_cast<std::size_t>(i0) * kChannels;
        const float w = weight * wy[r];
        for (int q = 0; q < 2 * kChannels; ++q) e[q] += w * pair_weight[q] * pair_value[q];
      }
      continue;
    }
    for (int r = 0; r < 2; ++r) {
      const int row = j0 + r;
      if (row < grid_row_begin_ || row >= grid_row_end_) continue;
      touch(row, row);
      float* line = dense_.data() + static_cast<std::size_t>(row - grid_row_begin_) * row_size;
      for (int k = 0; k < 2; ++k) {
        const int col = i0 + k;
        if (col < 0 || col >= grid_width_) continue;
        const float w = weight * wy[r] * wx[k];
        float* e = line + static_cast<std::size_t>(col) * kChannels;
        for (int c = 0; c < kChannels; ++c) e[c] += w * value[static_cast<std::size_t>(c)];
      }
    }
  }
}

#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
__attribute__((target_clones("arch=x86-64-v3", "default")))
#endif
void SplatBuffer::add_image(std::span<const float> samples, int nx, int ny, float origin_x, float origin_y, float cell_px,
                            const std::array<float, 4>& to_image, Point2f anchor, const std::array<float, 4>& value,
                            const std::array<float, 4>& diagonals, bool normalise) {
  if (nx < 2 || ny < 2 || samples.size() < static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny)) {
    throw OptionsError("SplatBuffer::add_image: " + std::to_string(samples.size()) + " samples for a " + std::to_string(nx) + " x " +
                       std::to_string(ny) + " image (at least 2 x 2)");
  }
  const bool finite_map = std::isfinite(origin_x) && std::isfinite(origin_y) && std::isfinite(anchor.x) && std::isfinite(anchor.y) &&
                          std::all_of(to_image.begin(), to_image.end(), [](float m) { return std::isfinite(m); });
  if (!finite_value(value) || !finite_map || !(cell_px > 0.0f)) {
    ++skipped_;
    return;
  }
  // In sample units: (u, v) = A (q - anchor) / cell - origin / cell, A = to_image.
  const double inv_cell = 1.0 / cell_px;
  const double a00 = to_image[0] * inv_cell, a01 = to_image[1] * inv_cell, a10 = to_image[2] * inv_cell, a11 = to_image[3] * inv_cell;
  const double u_at_anchor = -origin_x * inv_cell, v_at_anchor = -origin_y * inv_cell;
  // The output rectangle around the samples' parallelogram (A's inverse applied to its corners).
  const double det = a00 * a11 - a01 * a10;
  if (!(std::abs(det) > 0.0)) {
    ++skipped_;
    return;
  }
  const double um = static_cast<double>(nx - 1), vm = static_cast<double>(ny - 1);
  double x_lo = kInfinity, x_hi = -kInfinity, y_lo = kInfinity, y_hi = -kInfinity;
  for (const auto& [cu, cv] : {std::pair{0.0, 0.0}, std::pair{um, 0.0}, std::pair{0.0, vm}, std::pair{um, vm}}) {
    const double du = cu - u_at_anchor, dv = cv - v_at_anchor;
    const double qx = (a11 * du - a01 * dv) / det + anchor.x, qy = (-a10 * du + a00 * dv) / det + anchor.y;
    x_lo = std::min(x_lo, qx);
    x_hi = std::max(x_hi, qx);
    y_lo = std::min(y_lo, qy);
    y_hi = std::max(y_hi, qy);
  }
  // Grid cells (output pixels at full resolution): cell (gx, gy) is centred at output
  // ((gx + 0.5 - x_offset_) / scale_, (gy + 0.5) / scale_), one cell k = 1 / scale_ px across. Every
  // cell the image reaches is sampled, in and out of the band and the frame, so that the deposit can
  // be normalised to exactly its value: a tent turned with the image is not the cells' tent, and its
  // samples over the cells sum to 1 only on average (a point's, turned by 45 deg, to 1.17-1.34 as it
  // moves across a cell), where add_polygon deposits exactly its value.
  int row_first = static_cast<int>(std::ceil(y_lo * scale_ - 0.5));
  int row_last = static_cast<int>(std::floor(y_hi * scale_ - 0.5));
  // Nothing to draw here: the image lies wholly above or below the band (a renderer hands a band
  // every footprint its planned rows overlap, planned wide), or beside the frame.
  if (row_last < grid_row_begin_ || row_first >= grid_row_end_) return;
  if (std::floor(x_hi * scale_ + x_offset_ - 0.5) < 0.0 || std::ceil(x_lo * scale_ + x_offset_ - 0.5) > grid_width_ - 1) return;
  if (!normalise) {  // the band's rows alone
    row_first = std::max(row_first, grid_row_begin_);
    row_last = std::min(row_last, grid_row_end_ - 1);
  }
  const double k_px = 1.0 / scale_;
  const float* data = samples.data();
  // Each row's cells first, for all rows in one short loop, then the rows' samples (interleaved row
  // by row, this bookkeeping took about as long as the samples' gathers). Along a row's centre line
  // u = u0 + a00 x, v = v0 + a10 x at x = cell centre - anchor.x; its cells are those whose centres
  // fall inside [0, um] x [0, vm] and within the diagonal bounds: each bound an interval of x, or
  // along a bound's own direction (slope 0) all of the row or none of it.
  const int rows = row_last - row_first + 1;
  if (rows <= 0) return;
  image_row_cells_.resize(4 * static_cast<std::size_t>(rows));
  double* const cell_first = image_row_cells_.data();
  double* const cell_last = cell_first + rows;
  double* const row_u = cell_last + rows;
  double* const row_v = row_u + rows;
  const double x_lowest = normalise ? -kInfinity : 0.0, x_highest = normalise ? kInfinity : static_cast<double>(grid_width_ - 1);
  const double x_shift = x_offset_ - 0.5;
  const double scale = scale_, anchor_x = anchor.x, anchor_y = anchor.y;
  // The four bounds: u, v, u + v and u - v, each changing along a row at its slope.
  const double slopes[4] = {a00, a10, a00 + a10, a00 - a10};
  const double bottoms[4] = {0.0, 0.0, diagonals[0], diagonals[2]}, tops[4] = {um, vm, diagonals[1], diagonals[3]};
  double inverses[4];
  bool sloped[4];
  for (int c = 0; c < 4; ++c) {
    sloped[c] = slopes[c] != 0.0;
    inverses[c] = sloped[c] ? 1.0 / slopes[c] : 0.0;
  }
  for (int i = 0; i < rows; ++i) {
    const double dy = (row_first + i + 0.5) * k_px - anchor_y;
    const double u0 = u_at_anchor + a01 * dy, v0 = v_at_anchor + a11 * dy;
    double t_lo = -kInfinity, t_hi = kInfinity;
    const double starts[4] = {u0, v0, u0 + v0, u0 - v0};
    for (int c = 0; c < 4; ++c) {
      const double t0 = (bottoms[c] - starts[c]) * inverses[c], t1 = (tops[c] - starts[c]) * inverses[c];
      const bool outside = (starts[c] < bottoms[c]) | (starts[c] > tops[c]);
      const double lo = sloped[c] ? std::min(t0, t1) : (outside ? kInfinity : -kInfinity);
      const double hi = sloped[c] ? std::max(t0, t1) : kInfinity;
      t_lo = std::max(t_lo, lo);
      t_hi = std::min(t_hi, hi);
    }
    // An empty row (t_lo > t_hi) ends with cell_first > cell_last, and so does one whose cells all
    // lie beside the frame where only the frame's are drawn.
    const double first = std::ceil((t_lo + anchor_x) * scale + x_shift), last = std::floor((t_hi + anchor_x) * scale + x_shift);
    cell_first[i] = std::max(first, x_lowest);
    cell_last[i] = t_lo <= t_hi ? std::min(last, x_highest) : -kInfinity;
    row_u[i] = u0;
    row_v[i] = v0;
  }
  image_spans_.clear();
  std::size_t used = 0;
  double total = 0.0;
  for (int i = 0; i < rows; ++i) {
    if (!(cell_first[i] <= cell_last[i])) continue;
    const int x_first = static_cast<int>(cell_first[i]), x_last = static_cast<int>(cell_last[i]);
    // The row's samples (a loop of gathers), kept for the adding below.
    const auto count = static_cast<std::size_t>(x_last - x_first + 1);
    if (image_row_.size() < used + count + kImageRowPadding) image_row_.resize(2 * (used + count + kImageRowPadding));
    const double x0 = (x_first + 0.5 - x_offset_) * k_px - anchor_x;
    const auto fu0 = static_cast<float>(row_u[i] + a00 * x0), fv0 = static_cast<float>(row_v[i] + a10 * x0);
    total += sample_image_row(data, nx, ny, fu0, fv0, static_cast<float>(a00 * k_px), static_cast<float>(a10 * k_px), count,
                              image_row_.data() + used);
    image_spans_.push_back({row_first + i, x_first, static_cast<std::uint32_t>(used), static_cast<std::uint32_t>(count)});
    used += count;
  }
  if (!(total > 0.0)) return;
  // Then added to the band's cells in the frame (a vector of four channels each).
  const auto norm = normalise ? static_cast<float>(1.0 / total) : 1.0f;
  const float vf[kChannels] = {value[0] * norm, value[1] * norm, value[2] * norm, value[3] * norm};
  use_dense();
  for (const ImageSpan& span : image_spans_) {
    if (span.row < grid_row_begin_ || span.row >= grid_row_end_) continue;
    const int x_first = std::max(0, span.x_first);
    const int x_last = std::min(grid_width_ - 1, span.x_first + static_cast<int>(span.count) - 1);
    if (x_first > x_last) continue;
    touch(span.row, span.row);
    const float* row_samples = image_row_.data() + span.offset + (x_first - span.x_first);
    float* out = dense_.data() + (static_cast<std::size_t>(span.row - grid_row_begin_) * static_cast<std::size_t>(grid_width_) +
                                  static_cast<std::size_t>(x_first)) * kChannels;
    const auto count = static_cast<std::size_t>(x_last - x_first + 1);
    add_scaled_samples(row_samples, count, vf, out);
  }
}

void SplatBuffer::resolve_into(float* rgba_full_image) const {
  resolve_rows_into(rgba_full_image + static_cast<std::size_t>(row_begin_) * static_cast<std::size_t>(width_) * kChannels);
}

std::pair<int, int> SplatBuffer::touched_rows() const {
  if (dirty_first_ > dirty_last_) return {row_begin_, row_begin_};
  if (options_.downsample == 1) return {std::max(row_begin_, dirty_first_), std::min(row_end_, dirty_last_ + 1)};
  // Output row y interpolates between cell rows g0 and g0 + 1 (resolve_rows_into): those rows whose
  // pair meets the dirty rows, a run (g0 grows with y).
  int first = row_end_, end = row_begin_;
  for (int row = row_begin_; row < row_end_; ++row) {
    const auto g0 = static_cast<int>(fast_floor((row + 0.5) * scale_ - 0.5));
    if (g0 + 1 < dirty_first_ || g0 > dirty_last_) continue;
    first = std::min(first, row);
    end = row + 1;
  }
  return {first, std::max(first, end)};
}

void SplatBuffer::resolve_rows_into(float* rgba_rows) const {
  const std::size_t grid_row_size = static_cast<std::size_t>(grid_width_) * kChannels;
  // Only the rows written, and those interpolated from them: every other entry is 0 (touched_rows).
  const auto [first_row, end_row] = touched_rows();
  if (first_row >= end_row) return;
  if (options_.downsample == 1) {
    for (int row = first_row; row < end_row; ++row) {
      const double* d = diff_.data() + static_cast<std::size_t>(row - row_begin_) * grid_row_size;
      float* out = rgba_rows + static_cast<std::size_t>(row - row_begin_) * grid_row_size;
      double sum[kChannels] = {0.0, 0.0, 0.0, 0.0};
      for (std::size_t i = 0; i < grid_row_size; i += kChannels) {
        for (int c = 0; c < kChannels; ++c) {
          sum[c] += d[i + c];
          out[i + c] += static_cast<float>(sum[c]);
        }
      }
      if (dense_used_) {
        const float* e = dense_.data() + static_cast<std::size_t>(row - grid_row_begin_) * grid_row_size;
        for (std::size_t i = 0; i < grid_row_size; ++i) out[i] += e[i];
      }
    }
    return;
  }
  // Grid cells integrated, then each output pixel bilinearly between the four cells around its
  // centre, divided by k^2: the weights of a cell over the output pixels sum to k^2 (k samples per
  // unit of a tent with unit integral, per axis), so the energy is kept.
  // The cell rows those output rows interpolate from: the dirty ones and one either side (0).
  LargeVector<double>& cells = cells_;
  cells.resize(diff_.size());
  const int cell_first = std::max(grid_row_begin_, dirty_first_ - 1), cell_last = std::min(grid_row_end_ - 1, dirty_last_ + 1);
  const std::size_t cells_begin = static_cast<std::size_t>(cell_first - grid_row_begin_) * grid_row_size;
  const std::size_t cells_end = static_cast<std::size_t>(cell_last + 1 - grid_row_begin_) * grid_row_size;
  for (std::size_t r = cells_begin; r < cells_end; r += grid_row_size) {
    double sum[kChannels] = {0.0, 0.0, 0.0, 0.0};
    for (std::size_t i = 0; i < grid_row_size; i += kChannels) {
      for (int c = 0; c < kChannels; ++c) {
        sum[c] += diff_[r + i + static_cast<std::size_t>(c)];
        cells[r + i + static_cast<std::size_t>(c)] = sum[c];
      }
    }
  }
  if (dense_used_) {
    for (std::size_t r = cells_begin; r < cells_end; ++r) cells[r] += dense_[r];
  }
  const double norm = scale_ * scale_;
  const std::size_t out_row_size = static_cast<std::size_t>(width_) * kChannels;
  for (int row = first_row; row < end_row; ++row) {
    const double gy = (row + 0.5) * scale_ - 0.5;
    const double g0 = fast_floor(gy);
    const double fy = gy - g0;
    const std::size_t r0 = static_cast<std::size_t>(static_cast<int>(g0) - grid_row_begin_);
    const double* top = cells.data() + r0 * grid_row_size;
    const double* bottom = top + grid_row_size;
    float* out = rgba_rows + static_cast<std::size_t>(row - row_begin_) * out_row_size;
    for (int x = 0; x < width_; ++x) {
      const double gx = (x + 0.5) * scale_ - 0.5 + x_offset_;
      const double c0 = fast_floor(gx);
      const double fx = gx - c0;
      const std::size_t i0 = static_cast<std::size_t>(c0) * kChannels;
      const double w00 = (1.0 - fx) * (1.0 - fy) * norm, w01 = fx * (1.0 - fy) * norm;
      const double w10 = (1.0 - fx) * fy * norm, w11 = fx * fy * norm;
      for (int c = 0; c < kChannels; ++c) {
        const std::size_t a = i0 + static_cast<std::size_t>(c);
        out[static_cast<std::size_t>(x) * kChannels + static_cast<std::size_t>(c)] +=
            static_cast<float>(w00 * top[a] + w01 * top[a + kChannels] + w10 * bottom[a] + w11 * bottom[a + kChannels]);
      }
    }
  }
}

void SplatBuffer::resolve_into(Image& rgba) const {
  if (rgba.width != width_ || rgba.channels != kChannels || rgba.height < row_end_) {
    throw OptionsError("SplatBuffer::resolve_into: " + rgba.to_string() + " must be " + std::to_string(width_) +
                       " px wide with 4 channels and at least " + std::to_string(row_end_) + " rows");
  }
  resolve_into(rgba.data.data());
}

std::string SplatBuffer::to_string() const {
  return "SplatBuffer(" + std::to_string(width_) + " px wide, rows [" + std::to_string(row_begin_) + ", " +
         std::to_string(row_end_) + "), " + std::to_string(options_.subrows) + " sub-rows, " +
         (options_.downsample > 1 ? "1/" + std::to_string(options_.downsample) + " resolution, " : "") +
         std::to_string(skipped_) + " skipped)";
}

}  // namespace lensmith
