// The scatter primitive of the bokeh renderer: deposits the energy of convex polygons (a pixel's PSF
// footprint, or the triangles of a mapped pupil mesh) into a band of image rows at O(polygon height)
// cost, by first differences along each row that a final prefix sum integrates: the constant-time
// rectangle spreading of T. J. Kosloff, M. W. Tao, B. A. Barsky, "Depth of field postprocessing for
// layered scenes using constant-time rectangle spreading", Graphics Interface 2009, pp. 39-46,
// generalised to polygons with a tent filter.
#pragma once

#include <algorithm>
#include <array>
#include <limits>
#include <cstddef>
#include <cstdint>
#include <ostream>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "lensmith/core/huge_page_allocator.h"

namespace lensmith {

struct Image;

// A point in continuous output pixel coordinates, px: pixel (i, j) covers [i, i+1] x [j, j+1],
// x to the right, y down. float resolves 2.4e-4 px at x = 4096: footprints of equal shape then
// differ by up to half that, which leaves a flat field flat to 1e-5 (splat_buffer_test).
struct Point2f {
  float x = 0.0f;
  float y = 0.0f;

  std::string to_string() const;  // "(12.5, 3.25)"
  friend std::ostream& operator<<(std::ostream& os, const Point2f& p) { return os << p.to_string(); }
};

// Area of a simple polygon by the shoelace formula, px^2, for either winding; 0 for fewer than 3
// vertices. The exact area, not the rasterised one SplatBuffer normalises by.
double polygon_area(std::span<const Point2f> vertices);

struct SplatOptions {
  // Sub-rows per pixel row, in [1, 16]: y is sampled at k + (m + 0.5) / subrows on the global pixel
  // grid, so a near-horizontal edge is placed to within 1 / (2 subrows) px (at 4, up to 8% of a
  // pixel's value along such an edge; 1% at 16). Energy is conserved at any count; cost grows with it.
  int subrows = 4;
  // Output pixels per grid cell along each axis, in [1, 8]. Above 1 the buffer deposits into cells of
  // downsample x downsample output pixels (coordinates stay in output px), with the tent one cell
  // wide, and resolve_into upsamples bilinearly: the cost of a footprint falls by downsample per
  // axis, its edges soften to about 2 downsample px, energy is kept. For large blur only.
  int downsample = 1;

  // Throws OptionsError naming the field and the violated constraint.
  void validate() const;
  std::string to_string() const;  // "SplatOptions(subrows 4)"
  friend std::ostream& operator<<(std::ostream& os, const SplatOptions& o) { return os << o.to_string(); }
};

// A polygon's deposit recorded in SplatBuffer's own form, first differences along x row by row, so
// that the same polygon moved by whole pixels is deposited by adding its entries (a few per row)
// instead of scanning its sub-rows: what SplatBuffer::add_stamp at anchor (i, j) deposits equals
// add_polygon of the recorded polygon moved by (i, j) px, at the recording's sub-row count. Made by
// SplatBuffer::record.
struct DifferenceStamp {
  int first_row = 0;                       // of its entries, relative to the anchor's row
  std::vector<std::uint32_t> row_entries;  // row first_row + r has entries [row_entries[r], row_entries[r + 1])
  std::vector<std::int32_t> column;        // relative to the anchor's column
  std::vector<double> weight;              // difference per unit of deposited value

  std::size_t entries() const { return column.size(); }
  std::string to_string() const;  // "DifferenceStamp(14 rows, 96 entries)"
  friend std::ostream& operator<<(std::ostream& os, const DifferenceStamp& s) { return os << s.to_string(); }
};

// A cell of a mesh that SplatBuffer::add_mesh deposits: a convex polygon of 3 or 4 corners (indices
// into the mesh's vertices, in order around it), its edges corner 0-1, 1-2, ..., last-0 (indices into
// the mesh's edge list) with +1 where it walks an edge from the edge's first end to its second and -1
// the other way, and the light (times the value's R, G, B) and coverage (times its alpha) it carries.
struct MeshCell {
  static constexpr std::size_t kMaxCorners = 4;
  std::array<std::uint32_t, kMaxCorners> corner{};
  std::array<std::uint32_t, kMaxCorners> edge{};
  std::array<std::int8_t, kMaxCorners> direction{};
  std::uint32_t corners = 3;
  float light = 0.0f;
  float coverage = 0.0f;
};

// Accumulates RGBA energy deposits for rows [row_begin, row_end) of an image width_px wide.
//
// Filtering: a polygon P carrying value v deposits into pixel (i, j)
//   v / A * integral over P of T(x - (i + 0.5)) T(y - (j + 0.5)) dx dy,   T(u) = max(0, 1 - |u|),
// exactly in x and by S = subrows midpoint sub-rows per pixel in y, where A is P's area as rasterised
// (the sum over its sub-rows of span length / S), so that a polygon deposits exactly v in total
// before clipping at the image's left/right edges and at the band. T is the source pixel's box
// convolved with the output pixel's box: a point on a pixel centre lands entirely in that pixel.
// Polygons too thin to cross a sub-row (|A| below 1e-9 px^2) are deposited as points at their vertex
// centroid with bilinear (tent) weights.
//
// Footprints are clipped to the band, and sub-rows lie on the global grid, so bands filled
// separately (one per thread) and resolved into one image give what one full-height buffer gives.
// A polygon costs O(vertices + sub-rows inside the band); add_* never allocate once the scratch
// space has grown to the largest polygon seen. Not thread-safe: one buffer per thread.
class SplatBuffer {
 public:
  // Throws OptionsError for width_px < 1, row_begin < 0, row_end < row_begin or invalid options.
  SplatBuffer(int width_px, int row_begin, int row_end, const SplatOptions& options = {});

  // Zeroes the accumulated deposits (and the skipped count) without releasing memory.
  void clear();
  // Zeroed for another band of rows of the same width and options, keeping its memory where it is
  // large enough; throws OptionsError for row_begin < 0 or row_end < row_begin.
  void reset(int row_begin, int row_end);

  // Simple polygon, either winding, vertices in px; value = (R, G, B, alpha) energy it deposits.
  // Polygons with no vertex, a non-finite vertex or a non-finite value are not deposited but counted
  // in skipped(); 1 or 2 vertices are a point at their centroid. A y-monotone polygon (convex ones
  // included) is scanned between its two chains from the topmost to the bottommost vertex; any other
  // by the even-odd pairs of each sub-row's edge crossings (a crescent, a ring that turns back in
  // y); either way exactly its value. A self-crossing polygon is not supported (a y-monotone one is
  // spread between its chains, any other filled by the even-odd rule). `subrows` (1..16) samples
  // this polygon at its own count of sub-rows per pixel instead of the buffer's (0): a tall
  // polygon's top and bottom rows alone see the y sampling, so a renderer samples it more coarsely
  // in the same buffer. Throws OptionsError for a count outside [0, 16].
  void add_polygon(std::span<const Point2f> vertices, const std::array<float, 4>& value, int subrows = 0);
  void add_triangle(Point2f a, Point2f b, Point2f c, const std::array<float, 4>& value);
  // The cells of a mesh (MeshCell: triangles, or triangles a clear aperture cut to quadrilaterals),
  // each vertex moved by `offset` px, each depositing exactly what add_polygon of it would (its value
  // over its rasterised area, a point where that is below add_polygon's threshold), but walked edge
  // by edge: an edge two cells share takes one entry a sub-row (their densities' difference) where
  // the cells one by one take two, and no cell is set up as a polygon. `edges` are vertex index
  // pairs; `value` scales each cell's light (R, G, B) and coverage (alpha). Non-finite input is
  // skipped and counted as add_polygon's; an index out of range or a corner count outside [3, 4]
  // throws OptionsError. Costs O(edges + cells + crossings of edges and sub-rows); `subrows` as
  // add_polygon's.
  void add_mesh(std::span<const Point2f> vertices, std::span<const std::array<std::uint32_t, 2>> edges,
                std::span<const MeshCell> cells, const std::array<float, 4>& value, Point2f offset = {}, int subrows = 0);
  // A point deposit with bilinear weights over the 2 x 2 pixels whose centres surround p.
  void add_point(Point2f p, const std::array<float, 4>& value);
  // The stamp's polygon moved by (anchor_x, anchor_y) whole px, carrying `value`; clipped like
  // add_polygon (entries left of the image fold into its first column, those right of it and
  // outside the band are dropped). Full-resolution buffers only (downsample 1: OptionsError).
  void add_stamp(const DifferenceStamp& stamp, int anchor_x, int anchor_y, const std::array<float, 4>& value);
  // A tabulated light distribution turned and moved: `samples` (nx x ny, row-major) lie at
  // (origin_x + a cell_px, origin_y + b cell_px) in the image's own frame (px), and the output pixel
  // whose centre is q receives value times the bilinear interpolation of the samples at
  // to_image * (q - anchor) (to_image a 2 x 2 matrix, row-major; 0 outside the samples); with
  // `normalise`, scaled so that all the pixels it reaches, in and out of the band and the frame,
  // receive exactly `value` (as add_polygon's; the image is then sampled whole). For
  // light distributions already filtered by the buffer's tent, sampled finely enough for bilinear
  // interpolation (FootprintScatter's light images). In a buffer of coarse cells the cells' centres
  // sample it, and it must be filtered by the cells' tent. `diagonals` bound the samples with light (in
  // samples: a + b within [0], [1] and a - b within [2], [3]), so that the image's empty corners are
  // not drawn; the default bounds nothing. Non-finite input is skipped and counted. Costs O(cells
  // covered).
  void add_image(std::span<const float> samples, int nx, int ny, float origin_x, float origin_y, float cell_px,
                 const std::array<float, 4>& to_image, Point2f anchor, const std::array<float, 4>& value,
                 const std::array<float, 4>& diagonals = kNoDiagonals, bool normalise = true);
  static constexpr std::array<float, 4> kNoDiagonals{-std::numeric_limits<float>::infinity(), std::numeric_limits<float>::infinity(),
                                                    -std::numeric_limits<float>::infinity(), std::numeric_limits<float>::infinity()};
  // Points (x, y, weight) of a light distribution in its own frame (px), turned and moved as
  // add_image's samples (output position anchor + from_image * (x, y), from_image row-major): each
  // deposits value times its weight as add_point does.
  void add_points(std::span<const std::array<float, 3>> points, const std::array<float, 4>& from_image, Point2f anchor,
                  const std::array<float, 4>& value);
  // The stamp of a polygon (px; its deposit at anchor (0, 0) is add_polygon's of `vertices`)
  // sampled at `subrows` sub-rows per pixel (SplatOptions::subrows' range). Empty (no entries) for
  // a polygon add_polygon would skip; a polygon with no area records as a point.
  static DifferenceStamp record(std::span<const Point2f> vertices, int subrows);

  // Prefix-sums each row and adds the band into rgba_full_image: the full image, width() x (at
  // least row_end()) pixels x 4 floats, row-major, top row first; rows outside the band untouched.
  void resolve_into(float* rgba_full_image) const;
  // The same into the band's rows alone: `rgba_rows` holds width() x (row_end() - row_begin())
  // pixels x 4 floats, row row_begin() first (a renderer's band-sized image of a layer).
  void resolve_rows_into(float* rgba_rows) const;
  // The output rows [first, second) that resolving may change: those the deposits since the last
  // reset or clear reached (with the rows a coarse grid interpolates from them); empty (first >=
  // second) when nothing was deposited. The band's other rows resolve to 0.
  std::pair<int, int> touched_rows() const;
  // The same into an Image; throws OptionsError unless it is width() wide, 4 channels and at least
  // row_end() rows high.
  void resolve_into(Image& rgba) const;

  int width() const { return width_; }
  int row_begin() const { return row_begin_; }
  int row_end() const { return row_end_; }
  const SplatOptions& options() const { return options_; }
  // Polygons and points rejected for non-finite coordinates or values since construction or clear().
  std::size_t skipped() const { return skipped_; }

  std::string to_string() const;  // "SplatBuffer(640 px wide, rows [0, 37), 4 sub-rows, 0 skipped)"
  friend std::ostream& operator<<(std::ostream& os, const SplatBuffer& b) { return os << b.to_string(); }

 private:
  // One vertex of a chain from the topmost to the bottommost vertex.
  struct ChainVertex {
    double x;
    double y;
    // The first global sub-row with centre at or below y, made non-decreasing along the chain; the
    // chain edge from this vertex covers sub-rows [first_subrow, next vertex's first_subrow).
    double first_subrow;
    double slope;  // dx/dy of that edge; 0 when it covers no sub-row
  };

  // The two chains from the topmost to the bottommost vertex; false where y turns back along one
  // (the polygon is not y-monotone).
  bool build_chains(std::span<const Point2f> vertices, int subrows);
  // add_polygon for a polygon that is not y-monotone; (cx, cy) its vertex centroid in cells.
  void add_general_polygon(std::span<const Point2f> vertices, int subrows, double cx, double cy, const std::array<float, 4>& value);
  // One sub-row (class m of `subrows` per pixel) and its span into the two rows its tent reaches
  // (splat_buffer.cpp).
  void deposit_span(int pixel_row, int subrows, int m, double x_enter, double x_leave, const double unit[4]);
  template <class Add>
  void tent_rows(int pixel_row, int subrows, int m, Add&& add);  // splat_buffer.cpp
  // One span end of weight coef (first differences per channel) at x in sub-row class m of pixel row
  // `pixel_row`, into the two rows the sub-row's tent reaches.
  void deposit_end(int pixel_row, int subrows, int m, double x, const double coef[4]);
  void deposit_point(double x_out_px, double y_out_px, const std::array<float, 4>& value);
  void deposit_grid_point(double x_px, double y_px, const std::array<float, 4>& value);  // grid cells

  int width_;
  int row_begin_;
  int row_end_;
  SplatOptions options_;
  std::size_t skipped_ = 0;
  // The grid (output px with downsample 1): cells per row, its band of cell rows, and the map from
  // output px: cell = px * scale_ (+ x_offset_ in x, a column left of the image for upsampling).
  int grid_width_ = 0;
  int grid_row_begin_ = 0;
  int grid_row_end_ = 0;
  double scale_ = 1.0;
  double x_offset_ = 0.0;
  std::vector<Point2f> scaled_;  // scratch: a polygon's vertices in cells
  mutable LargeVector<double> cells_;  // scratch of resolve_into: the grid's integrated cells
  // First differences along x, double: width_ x (row_end_ - row_begin_) x 4 channels, row-major.
  // double keeps a bright highlight's rounding from streaking along its row through the prefix sum.
  LargeVector<double> diff_;
  std::vector<ChainVertex> forward_chain_;   // scratch: top to bottom vertex by increasing index
  std::vector<ChainVertex> backward_chain_;  // scratch: top to bottom vertex by decreasing index
  // Scratch of add_general_polygon: its edges by sub-row range, the active ones, one sub-row's
  // crossings, and the spans of all sub-rows.
  struct Edge {
    double first;  // first sub-row it covers
    double last;   // exclusive
    double x;      // upper end
    double y;
    double slope;  // dx/dy
  };
  struct SubrowSpan {
    double subrow;
    double x_enter;
    double x_leave;
  };
  std::vector<Edge> edges_;
  // Scratch of add_mesh: each edge's sub-rows and line, its x summed over them (for the cells'
  // rasterised areas), and the light and coverage density steps across it.
  struct EdgeRun {
    double first;  // first sub-row it covers
    double last;   // exclusive; first == last: it covers none
    double x;      // upper end
    double y;
    double slope;  // dx/dy
    double up;     // +1 where walking it from its first end to its second goes up (towards -y), else -1
    double x_sum;
    double light;
    double coverage;
  };
  std::vector<EdgeRun> edge_runs_;
  std::vector<std::size_t> active_edges_;
  std::vector<double> crossings_;
  std::vector<SubrowSpan> spans_;
  std::vector<float> image_row_;  // add_image: its rows' samples, one after the other
  std::vector<double> image_row_cells_;  // add_image: its rows' first and last cells and (u, v) at x = 0
  struct ImageSpan {
    int row = 0, x_first = 0;  // grid cells
    std::uint32_t offset = 0, count = 0;  // its samples in image_row_
  };
  std::vector<ImageSpan> image_spans_;
  // add_image's deposits as values (not differences), added to the picture by resolve_into; the
  // same rows as diff_, sized on a band's first add_image.
  LargeVector<float> dense_;
  bool dense_used_ = false;
  void use_dense();
  // The grid rows written since the last reset or clear, [dirty_first_, dirty_last_] (empty when
  // first > last). Every entry of diff_ and dense_ outside them is 0: a reset or clear zeroes them
  // alone, and resolving touches them alone (and the rows interpolated from them). A layer's band
  // of a renderer is written in a few of its rows (a stripe of a receding street), and zeroing and
  // resolving the whole band, 48 bytes a pixel, was most of what a sharp layer's band cost.
  int dirty_first_ = std::numeric_limits<int>::max();
  int dirty_last_ = std::numeric_limits<int>::min();
  void touch(int first_grid_row, int last_grid_row) {
    dirty_first_ = std::min(dirty_first_, first_grid_row);
    dirty_last_ = std::max(dirty_last_, last_grid_row);
  }
  // Zeroes the dirty rows of diff_ and dense_ and marks none dirty.
  void zero_dirty_rows();
  // Marks the rows a polygon or mesh spanning grid y in [top, bottom] may reach (none if not finite).
  void touch_cells(double top, double bottom);
};

}  // namespace lensmith
