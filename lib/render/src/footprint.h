// A source pixel's footprint on the output: planned from a probe of the ray model (its size, the
// rows it may touch, how many wavelength groups and which pupil mesh it needs), then deposited into
// SplatBuffers as the model maps the aperture. Three ways, cheapest first:
// - a point, for footprints under 0.2 px (the 2 px tent filter hides their shape);
// - one uniformly lit polygon, the aperture's outline mapped by three rays, where the model is
//   affine in the pupil (thin, paraxial) or departs from its affine fit by under 1/4 px; where that
//   polygon is the outline scaled about the pixel's centre (the thin lens), from a stamp
//   (footprint_stamps.h);
// - a pupil mesh mapped vertex by vertex: nested ring polygons where the mapped rings nest (the
//   radial light distribution kept), else as its triangles, deposited together edge by edge
//   (SplatBuffer::add_mesh; folds, caustics, vignetting).
#pragma once

#include <algorithm>
#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <utility>
#include <vector>

#include "lensmith/camera/ray_model.h"
#include "lensmith/render/splat_buffer.h"
#include "footprint_stamps.h"
#include "illumination_table.h"
#include "image_area_table.h"
#include "mapped_pupil_table.h"
#include "pupil_mesh_table.h"
#include "scatter_source.h"
#include "shared_memo.h"
#include "spectral_groups.h"

namespace lensmith::render_detail {

// Footprints narrower than this (px) are deposited as points: the 2 px tent hides their shape.
inline constexpr double kPointFootprintPx = 0.2;
// Margin (px of the footprint's grid cells) around a footprint's probed extent that its deposit may
// reach: the 2 px tent.
inline constexpr double kTentMarginPx = 2.0;

// Footprint sizes (px) from which the deposit goes to a grid of 2 x 2 and of 4 x 4 px cells: the
// cost of a polygon falls with the cells per side, and its edge, softened to about two cells, stays
// under 5 % of its size, invisible in a disc that large (bench/blender's scenes: within 0.1 dB).
inline constexpr double kHalfResolutionPx = 40.0;
inline constexpr double kQuarterResolutionPx = 96.0;

// The splat grid for a footprint this large (px): 0 (full resolution), 1 (cells of 2 x 2 px) or 2
// (4 x 4 px).
inline int grid_level(double footprint_px) {
  return footprint_px >= kQuarterResolutionPx ? 2 : footprint_px >= kHalfResolutionPx ? 1 : 0;
}

// What the planner decided for one source.
struct FootprintPlan {
  static constexpr int kPoint = -2;  // `outline` value of the point path
  float y_min = 0.0f;  // rows the footprint may touch (px, with margin)
  float y_max = 0.0f;
  int groups = 1;      // wavelength groups
  float blend = 1.0f;  // share of the light in `groups` groups; the rest in groups - 1 (a smooth switch)
  int mesh = -1;       // PupilMeshTable mesh index, or -1 for the single-polygon and point paths
  int outline = 0;     // PupilMeshTable sector step (single polygon), or kPoint
  int level = 0;       // the splat grid: 2^level output px per cell side (large footprints are coarse)
  // Share of a uniform convex aperture that passes those discs, measured on an outline of at least
  // PupilMeshTable::kShareSectorStep's vertices (1 without discs; 0: the whole beam is stopped).
  float passing = 1.0f;
  bool discs = false;  // the model clips this point's beam by pupil discs (RayModel::clip_discs)
  // An affine footprint's rays at the reference wavelength, kept for the deposit of a single
  // wavelength group (whose wavelength that is), which would map them again: where the pupil's
  // centre lands (output px, x and y), where its points (1, 0) and (0, 1) land relative to it (px,
  // x and y each: differences of floats near 1000 would be off by 1e-4 px, beyond the stamps'
  // tolerances), and the centre ray's radiometric weight. `mapped` says whether they are set.
  // Every plan whose chief ray passes has the first two (where a mesh footprint's shape is anchored
  // when a neighbour draws it: FootprintShape) and the weight.
  bool mapped = false;
  // Drawn from the table's light images (FootprintScatter::deposit_light_images) at `level`.
  bool images = false;
  std::array<float, 6> affine_px{};
  float centre_weight = 1.0f;
  // The layer index of the source whose mapped shape this footprint draws, moved to its own chief
  // ray (FootprintScatter::plan_range), or -1: its own.
  std::int32_t shape_source = -1;
  // The output area its pixel's image covers, relative to a pixel's at the frame's centre
  // (ImageAreaTable): its coverage, not its light, scales by it, so that where distortion packs
  // more of the scene into a pixel the light of more sources shares it. 1 for models without
  // distortion (thin, paraxial).
  float area = 1.0f;
  // The factor on its light that makes a uniform surface as bright across the frame as through the
  // real lens (IlluminationTable; 1 for an ideal thin lens, a lens that is not round and without vignetting).
  float light = 1.0f;
};

// What the planner probed of a footprint: where the probe's rays land (output px) at up to three
// wavelengths (the reference, the lowest, the highest) and which of them land at all.
struct FootprintProbe {
  struct Pixel {
    double x, y;  // read only where `ok` (left uninitialised: see FootprintScatter::plan)
  };
  std::array<std::array<Pixel, 9>, 3> px;
  std::array<std::array<bool, 9>, 3> ok{};
  std::size_t wavelengths = 0;
  bool chief_passes = false;  // the pupil centre's ray at the reference wavelength (FootprintPlan::affine_px)
};

// A mesh footprint as the polygons its wavelength groups' light goes down as, per unit of their
// value (light in RGB, coverage in alpha), in output px: mapped once, then drawn at its own place and
// at its neighbours' (FootprintScatter::deposit). `key` is the layer index of the source it stands
// for; `light_scale` its chief ray's weight times its passing share, which a neighbour's light is
// scaled against.
struct FootprintShape {
  struct Polygon {
    std::uint32_t begin = 0;  // its vertices in `points`
    std::uint32_t count = 0;
    float light = 0.0f;
    float coverage = 0.0f;
    int subrows = 0;  // SplatBuffer::add_polygon's
  };
  bool valid = false;
  std::int64_t key = -1;
  std::array<float, 2> chief_px{};  // where its source's chief ray lands (FootprintPlan::affine_px)
  double light_scale = 1.0;
  std::vector<Point2f> points;
  std::vector<Polygon> polygons;
  // Per wavelength-group deposit, in the order FootprintScatter::deposit makes them: where its
  // polygons end, and how many of them were mesh triangles.
  std::vector<std::size_t> group_end;
  std::vector<std::size_t> group_triangles;
  // A group's mesh triangles, whole or cut where a clear aperture stops part of them, deposited
  // together (SplatBuffer::add_mesh; one set per group in the same order, empty where there are
  // none): its cells in `mesh_cells` (light and coverage per unit of the group's value, corners in
  // `points`) and its edges in `mesh_edges`, which the cells index from the set's first.
  struct MeshSet {
    std::uint32_t cell_begin = 0;
    std::uint32_t cell_count = 0;
    std::uint32_t edge_begin = 0;
    std::uint32_t edge_count = 0;
  };
  std::vector<MeshCell> mesh_cells;
  std::vector<std::array<std::uint32_t, 2>> mesh_edges;
  std::vector<MeshSet> mesh_sets;

  void clear();
  void add(std::span<const Point2f> vertices, const std::array<float, 4>& unit_value, int subrows);
};

// A footprint's light at a MappedPupilTable node (FootprintScatter::light_image): its mesh deposited
// as the renderer deposits it, at azimuth 0, filtered by the splat buffer's tent and sampled every
// cell_px; positions are output px from the node's chief ray.
struct LightImage {
  bool ok = false;  // false: the node's beam passes no light, or its chief ray is lost
  double extent_px = 0.0;  // the larger side of the mesh's passing part
  int level = 0;           // the splat grid it is for: the one asked, or finer where the passing part is small
  // A footprint this wide or more (px) is kept as samples of its light filtered by the tent (drawn
  // turned by SplatBuffer::add_image); a smaller one as the light of its cells, each drawn as a
  // point (the tent stays the output pixels': turning a filtered point would turn the tent too).
  bool dense = false;
  int nx = 0, ny = 0;
  float origin_x = 0.0f, origin_y = 0.0f;  // sample (0, 0)
  float cell_px = 0.5f;
  std::vector<float> samples;  // row-major, per unit of light: their sum times (cell_px / grid cell)^2 is 1
  std::array<float, 4> diagonals{};  // bounds of the samples with light (SplatBuffer::add_image)
  // Whether its samples over a grid of pixels, turned and moved, may sum to other than 1 by more than
  // kLatticeRipple (a sharp core's do: a turned tent is not the pixels' tent): drawn normalised.
  bool normalise = true;
  std::vector<std::array<float, 3>> points;  // x, y (px from the chief ray) and light, per unit of light
};

// Per-thread scratch space, so planning and deposits allocate nothing once warm.
struct FootprintScratch {
  std::vector<PupilPoint> pupil;
  std::vector<SensorHit> hits;
  std::vector<Point2f> points;
  std::vector<double> areas;
  std::vector<PupilDisc> discs;     // the model's first-order clipping of the current point
  std::vector<PupilPoint> clipped;  // the aperture's outline less what they cut off
  std::vector<PupilPoint> clip_work;
  std::vector<double> reach;  // the discs' reach along an outline's vertex directions
  std::vector<PupilPoint> ring_pupil;     // clipped rings' vertices, the centre first
  std::vector<std::size_t> ring_offsets;  // clipped rings: where each ring's vertices end in `pupil`
  std::vector<double> pupil_areas;
  // record_mesh: each mesh triangle's passing share.
  std::vector<double> fractions;
  // record_mesh, per PupilMeshTable::Edges entry: its edge (whole, or its passing part) in the
  // shape's mesh set, and the point where its clearance crosses 0 in the shape's points (or kNoSlot).
  std::vector<std::uint32_t> edge_slot;
  std::vector<std::uint32_t> clip_slot;
  static constexpr std::uint32_t kNoSlot = ~std::uint32_t{0};
  std::vector<double> ring_weights;
  // Ring polygons to deposit (deposit_nested_rings): the ring (1-based), its light and coverage.
  struct RingDeposit {
    int ring = 0;
    double light = 0.0;
    double coverage = 0.0;
  };
  std::vector<RingDeposit> ring_deposits;
  std::vector<Point2f> moved;  // a ring or a shared shape's polygon moved (deposit_nested_rings, draw_shape)
  std::vector<Point2f> ring_points;  // mapped points of the ring polygons, untangled (footprint.cpp)
  std::vector<std::span<const Point2f>> ring_spans;
  // One footprint's maps at each of its wavelengths, kept from the check whether its rings nest at
  // all of them to their deposit (set 0: the mesh by map, 1: the clipped rings by map_passing).
  struct CachedMap {
    double wavelength_nm = 0.0;
    int set = 0;
    std::vector<SensorHit> hits;
  };
  std::vector<CachedMap> cached_maps;
  std::size_t cached_count = 0;
  // Planning: the probes of a range's planned sources (plan_range).
  std::vector<FootprintProbe> range_probes;
  // Deposit: the mesh footprint drawn last, for its neighbours; forget_shape() before each band of
  // rows, so that what a band draws does not depend on which thread drew which band before.
  FootprintShape shape;
  void forget_shape() { shape.valid = false; }
  void forget_light_images() { light_images.forget(); }
  // The mapped-pupil table's nodes this thread used last (FootprintScatter's table, where it has one).
  MappedPupilTable::Cache table_cache;
  // The light images this thread used last, and the scratch space it makes new ones in.
  SharedMemo<LightImage>::ThreadSlots light_images;
  std::unique_ptr<FootprintScratch> image_scratch;
  // One footprint's light images to draw (deposit_light_images).
  struct ImageDraw {
    const LightImage* image = nullptr;
    Point2f anchor;
    std::array<float, 4> value{};
  };
  std::vector<ImageDraw> image_draws;
};

// The plan of source `from` moved to source `to`'s pixel (where its chief ray lands, the rows it
// touches), for a model that images every point of a depth alike (the thin lens: plan_range).
FootprintPlan moved_plan(const FootprintPlan& p, const ScatterSource& from, const ScatterSource& to);

// Sub-rows per pixel (of `buffer_subrows`, the buffer's) at which a footprint's own polygons (its
// outline, its ring polygons) are scanned: all of them below kMediumFootprintPx grid cells high, half
// below kTallFootprintPx, a quarter above (at least 1). Only a tall footprint's top and bottom rows
// see the y sampling; its mesh triangles keep every sub-row.
int footprint_subrows(const FootprintPlan& p, int buffer_subrows);

// Where the ranges of a layer's sources planned together (FootprintScatter::plan_range) begin, about
// `target` sources apart, each where no run of neighbours that may share a mapped shape continues
// across (a row's first pixel, a gap), so that the plans depend neither on the threads nor on where
// the ranges are cut; the last entry is sources.size().
void plan_range_starts(std::span<const ScatterSource> sources, std::size_t target, std::vector<std::size_t>& starts);

// Everything a footprint depends on besides its source; one per render, shared by the threads.
class FootprintScatter {
 public:
  // `areas`: the image area of a pixel over the frame (FootprintPlan::area); kept by the caller.
  // `illumination`: the real lens's brightness across the frame (FootprintPlan::light); kept by the caller.
  FootprintScatter(const RayModel& model, const Aperture& aperture, const SpectralGroups& groups,
                   const PupilMeshTable& meshes, const ImageAreaTable& areas, const IlluminationTable& illumination,
                   const BokehOptions& options);
  // Light images made (BokehStatistics::light_images), kept or forgotten.
  std::size_t light_images() const { return images_.made(); }
  // Frees the light images made so far (a layer's; the next layer makes those it needs again): they
  // are keyed by depth as well as by field, and a frame's layers together would keep hundreds of MB
  // (a 960 x 540 depth ramp from 0.5 to 10 m: 19,526 images, a 627 MB peak). No thread may hold one:
  // each thread's scratch forgets its own (FootprintScratch::forget_light_images).
  void forget_light_images() const;

  // One source's plan; its probe is written to `*probe` where given.
  FootprintPlan plan(const ScatterSource& s, FootprintScratch& scratch, FootprintProbe* probe = nullptr) const;
  // The plans of sources [begin, end) of a layer (indices into `sources` and `plans`). Where
  // BokehOptions::reuse_shapes is on and the model clips by pupil discs (paraxial, Seidel), a run of
  // neighbouring pixels of one row whose probes differ from the first's by under kShapeTolerancePx
  // beyond the move of their chief rays draws the first's mapped shape (FootprintPlan::shape_source):
  // only the pixels every kShapeStride apart and where that fails are probed, the others map their
  // chief ray alone (see the .cpp). Through a thin lens a source at the depth of one planned before
  // it in the range takes that plan moved to its pixel (moved_plan). The result depends on
  // [begin, end) alone, not on the thread.
  void plan_range(std::span<const ScatterSource> sources, std::span<FootprintPlan> plans, std::size_t begin,
                  std::size_t end, FootprintScratch& scratch) const;
  // Deposits a sharp pixel's footprint, a point planned at the reference wavelength in one group, as
  // deposit() would: its light at the plan's chief ray. Returns false, depositing nothing, for any
  // other plan. Apart from deposit(), whose preparations (the scene point, the discs, the outline) a
  // planned point does not use: the wall of the fence scene focused at 6 m is about 0.25 million of
  // them, and its layer's deposit took 7.4 ms with them, 5.0 ms without (docs/performance.md).
  bool deposit_planned_point(const ScatterSource& s, const FootprintPlan& p, SplatBuffer& buffer) const;
  // Deposits the footprint of layer source `index` into `buffer` (the plan's grid level):
  // footprint-sized polygons at the plan's sub-rows (footprint_subrows), mesh triangles at every
  // sub-row of the buffer. Adds the mesh triangles deposited to `triangles`, and to `reused` one
  // where a mesh footprint drew a neighbour's shape from scratch.shape.
  void deposit(const ScatterSource& s, const FootprintPlan& p, std::size_t index, SplatBuffer& buffer,
               FootprintScratch& scratch, std::size_t& triangles, std::size_t& reused) const;

 private:
  // The footprint's wavelength groups mapped into scratch.shape (its polygons per unit of each
  // group's value), and drawn from there at the plan's chief ray with the source's value.
  void map_shape(const ScatterSource& s, const FootprintPlan& p, int buffer_subrows, FootprintScratch& scratch) const;
  void draw_shape(const ScatterSource& s, const FootprintPlan& p, SplatBuffer& buffer, FootprintScratch& scratch,
                  std::size_t& triangles) const;
  // One group of a mesh not clipped by discs into scratch.shape: its ring polygons where they nest
  // (and `allow_rings`), else its triangles, each clipped by the interpolated clearances of its
  // corners (exact, poly); adds those to `triangles`.
  void record_mesh(const ScenePoint& point, double wavelength_nm, const FootprintPlan& p, bool allow_rings, bool rings_checked,
                   int own_subrows, FootprintScratch& scratch, std::size_t& triangles) const;
  // plan_range: whether the sources strictly between planned sources a and b (a run of one row)
  // may draw a's shape, and their plans when they do.
  bool shares_shape(std::span<const ScatterSource> sources, std::span<const FootprintPlan> plans, std::size_t a, std::size_t b,
                    const FootprintProbe& pa, const FootprintProbe& pb) const;
  bool follow(const ScatterSource& s, const FootprintPlan& a, const FootprintPlan& b, double along, std::int32_t a_index,
              FootprintPlan& out) const;

  // A polar mesh's rings clipped by scratch.discs (first-order vignetting), mapped and deposited as
  // nested rings (at `ring_subrows` sub-rows), or where they do not nest (a cat's eye mapped to a
  // crescent that turns back in y), as the triangles between them at every sub-row (adding them to
  // `triangles`).
  bool clip_rings(const FootprintPlan& p, FootprintScratch& scratch) const;  // into scratch.ring_pupil; false: do not nest
  // `passing` (> 0) is the share of the aperture that passes, measured on a dense outline: the rings'
  // own outline may be coarse (16 vertices cut a cat's eye's cusps by chords). `allow_rings` false:
  // the triangles whether or not the rings nest (another wavelength of the footprint's did not);
  // `shapes_checked`: every ring was found y-monotone and simple at this wavelength already.
  void deposit_clipped_rings(const ScenePoint& point, double wavelength_nm, const FootprintPlan& p, double passing,
                             bool allow_rings, bool shapes_checked, const std::array<float, 4>& value, FootprintShape& out,
                             int ring_subrows, FootprintScratch& scratch, std::size_t& triangles) const;
  // model.map (set 0: the points of mesh `mesh`, through map_set) or map_passing (set 1) of `pupil` at
  // one wavelength into `hits`, from scratch.cached_maps when this footprint mapped them there already,
  // else mapped (and kept when `keep`).
  void map_cached(const ScenePoint& point, double wavelength_nm, int set, int mesh, std::span<const PupilPoint> pupil,
                  std::vector<SensorHit>& hits, FootprintScratch& scratch, bool keep) const;
  // The model's map of a fixed pupil set (MappedPupilTable's sets: a mesh index, or its probe, centre
  // or basis set), from the table where the render has one.
  void map_set(const ScenePoint& point, double wavelength_nm, int set, std::span<const PupilPoint> pupil, std::span<SensorHit> hits,
               FootprintScratch& scratch) const;
  // Where a point draws its light images from: the table's nearest node in field radius, and the
  // nearest of kLightImageDepthSteps steps between its nodes in inverse depth (`depth_step`).
  struct ImagePlace {
    std::int64_t field_index = 0, depth_step = 0;
    double cos_azimuth = 1.0, sin_azimuth = 0.0;
  };
  ImagePlace image_place(const ScenePoint& point) const;
  // The light image of mesh `mesh` at a place and wavelength, made on first use (thread-safe).
  // `level`: the splat grid it is drawn into (FootprintPlan::level), whose cells' tent filters it.
  const LightImage& light_image(int mesh, std::int64_t field_index, std::int64_t depth_step, double wavelength_nm, int level,
                                FootprintScratch& scratch) const;
  LightImage make_light_image(int mesh, const ScenePoint& node, double wavelength_nm, int level, FootprintScratch& scratch) const;
  static std::uint64_t key_of(int mesh, std::int64_t field_index, std::int64_t depth_step, int level);
  // A mesh footprint of the table's models drawn from light images (one per wavelength group, from
  // its image_place, turned to its azimuth and placed at its chief ray); false, drawing nothing,
  // where an image is missing (its mesh is drawn instead).
  bool deposit_light_images(const ScatterSource& s, const FootprintPlan& p, SplatBuffer& buffer, FootprintScratch& scratch) const;
  // The clipped rings (clip_rings) mapped at one wavelength: scratch.hits, points, ring_spans, ring_weights.
  void map_clipped_rings(const ScenePoint& point, double wavelength_nm, const FootprintPlan& p, FootprintScratch& scratch,
                         bool keep = false) const;
  // The model's first-order discs of `point` (RayModel::clip_discs), widened where they pass less of
  // the pupil than the real lens's apertures (IlluminationTable::widen).
  void clip_discs(const ScenePoint& point, std::vector<PupilDisc>& discs) const;
  // The scene point a source stands for: its pixel centre's tangents at its inverse depth.
  ScenePoint scene_point(const ScatterSource& s) const;
  // FootprintPlan::light for a plan whose discs and passing share are set.
  float plan_light(const ScenePoint& point, const FootprintPlan& p) const;
  // FootprintPlan::passing for `discs` and a footprint drawn with `own_step`'s sector count.
  double disc_passing_share(const std::vector<PupilDisc>& discs, int own_step, FootprintScratch& scratch) const;
  // `value` with its light (not its coverage) scaled by a ray's radiometric weight (SensorHit), when
  // BokehOptions::vignetting is on.
  std::array<float, 4> lit(const std::array<float, 4>& value, double weight) const;

  const RayModel& model_;
  const Camera& camera_;
  const Aperture& aperture_;
  const SpectralGroups& groups_;
  const PupilMeshTable& meshes_;
  const BokehOptions& options_;
  // The probe: the pupil centre and 8 points on the aperture's edge, from the top anticlockwise.
  std::array<PupilPoint, 9> probe_{};
  PupilMeshTable::Directions probe_directions_;  // of the 8 edge points, for the discs' reach
  // Single-polygon footprints at full resolution that are the outline scaled about their pixel's
  // centre (the thin lens's): deposited from stamps.
  FootprintStamps stamps_;
  const ImageAreaTable& areas_;
  const IlluminationTable& illumination_;
  // The exact and poly models' maps interpolated over field and depth (BokehOptions::interpolated_rays).
  std::unique_ptr<MappedPupilTable> table_;
  // Light images by (mesh, node, wavelength), and the output pixels per sensor mm (Camera::output_pixel's
  // linear part, row-major), which turn an image to a point's azimuth.
  SharedMemo<LightImage> images_;
  std::array<double, 4> px_per_mm_{};
};

}  // namespace lensmith::render_detail
