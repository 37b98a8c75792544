// The exact and poly models' maps of the renderer's fixed pupil sets (the probe, the polar meshes),
// tabulated over the scene point's field radius and inverse depth and interpolated, instead of aimed
// and traced for every source pixel: those two models spent about 85 % of a render mapping (perf,
// bench/bokeh_bench's scene through pbrt-dgauss-50mm), hundreds of aimed rays a footprint.
//
// Why a table over two coordinates holds the whole map: a lens whose surfaces are all rotationally
// symmetric about one axis, imaged onto a sensor centred on it, images a scene point turned by an
// angle about the axis as the point itself with everything turned by that angle: map(R P, R m) =
// R map(P, m) for pupil points m and sensor hits. So a point at field radius r and azimuth phi is
// tabulated as the point (r, 0) on the x axis, and its hits are turned by phi. Turning the hits
// alone gives the hits of the pupil set turned by phi, not of the set itself: through a circular
// aperture that is the same pupil sampled at other angles, which is all the renderer asks of a mesh
// (its outer ring on the aperture's edge, its triangles' pupil areas unchanged). Blades and aperture
// pictures are not round, nor are a surface's rectangular, elliptical or decentred clear apertures:
// they keep the model's own map.
//
// Nodes lie every kFieldStepPx pixels of field radius (pinhole pixels from the frame's centre; finer
// on small frames, at least kFieldNodes across the half-diagonal) and every kBlurStepPx pixels of blur
// (inverse depth, by the camera's circle of confusion), made when a source first needs them; a
// source's hits are the bilinear interpolation of its four nodes' (sensor positions, radiometric
// weights and clear-aperture clearances alike: the clearance's sign then says whether the
// interpolated ray passes), a ray lost at any of them lost. Through the bench scene at 480 x 270 the
// interpolated rays land within 0.02 px of the model's (mean 0.002 px) and weigh within 1e-4;
// tests/render compares a frame drawn from them with one traced per pixel (bokeh_renderer_test.cpp).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "lensmith/camera/ray_model.h"
#include "shared_memo.h"

namespace lensmith::render_detail {

class MappedPupilTable {
 public:
  // Pupil sets besides the polar meshes (whose PupilMeshTable index is their set).
  static constexpr int kProbeSet = 1000;
  static constexpr int kCentreSet = 1001;
  static constexpr int kBasisSet = 1002;
  static constexpr int kLightSet = 1003;  // passing_light's
  // Node spacing: pinhole pixels of field radius, and output pixels of blur diameter.
  static constexpr double kFieldStepPx = 8.0;
  static constexpr double kBlurStepPx = 1.0;
  static constexpr double kFieldNodes = 128.0;  // at least this many nodes across the half-diagonal

  // Whether the table can stand in for `model`'s map through `aperture`: the exact or poly model of a
  // rotationally symmetric lens (no anamorphic squeeze, nothing that only the exact model takes),
  // through a circular aperture.
  static bool applies(const RayModel& model, const Aperture& aperture);
  // Whether the camera's lens is round about its axis: a prescription (not a thin lens) with no
  // mirrors, tilts or anamorphic squeeze, every clear aperture a centred circle.
  static bool round_lens(const Camera& camera);

  explicit MappedPupilTable(const RayModel& model);
  ~MappedPupilTable();
  MappedPupilTable(const MappedPupilTable&) = delete;
  MappedPupilTable& operator=(const MappedPupilTable&) = delete;

  struct Node;
  // A thread's recently used nodes, so that most lookups take no lock (one per thread, e.g. in its
  // scratch space; it must not outlive the table).
  using Cache = SharedMemo<Node>::ThreadSlots;

  // The hits of pupil set `set` (whose points are `pupil`, the same for every call with that set)
  // for `point` at `wavelength_nm`: the model's map of the set turned by the point's azimuth (see
  // above), interpolated. Thread-safe.
  void map(const ScenePoint& point, double wavelength_nm, int set, std::span<const PupilPoint> pupil, std::span<SensorHit> hits,
           Cache& cache) const;
  // The light the point's beam passes at `wavelength_nm`: the mean over the pupil of the rays'
  // radiometric weights where they pass, measured on `fine` (a polar mesh of the aperture, the same
  // for every call), its triangles clipped where their corners' interpolated clearance is < 0, at the
  // nodes, and interpolated. A clipped footprint's light is taken from here rather than from its own
  // mesh (FootprintScatter::record_mesh): a mesh of 4 rings cut by two clear apertures' kinked edge
  // misjudged a cat's eye's light by up to 3 %, the same at every azimuth of a field radius once the
  // mesh turns with the point (a white wall's corners 0.302 where the ground truth has 0.294).
  double passing_light(const ScenePoint& point, double wavelength_nm, const PupilMesh& fine, Cache& cache) const;

  // Where a point lies among the nodes: the nearest node in field radius, its inverse depth in
  // units of the nodes' step, and its azimuth (a node lies on the x axis; the point's hits are the
  // node's turned by the azimuth). For the light images, drawn from the nearest of finer depth steps
  // rather than interpolated (FootprintScatter::deposit_light_images).
  struct Place {
    std::int64_t field_index = 0;
    double depth_index = 0.0;
    double cos_azimuth = 1.0, sin_azimuth = 0.0;
  };
  Place place(const ScenePoint& point) const;
  // The scene point on the x axis at a field and depth index (whole at the nodes).
  ScenePoint point_at(double field_index, double depth_index) const { return {field_index * field_step_, 0.0, depth_index * depth_step_}; }

 private:
  // The node of `set` (pupil points `pupil`; for kLightSet the points of `fine`, reduced to its light).
  const Node& node(int set, double wavelength_nm, std::int64_t field_index, std::int64_t depth_index, std::span<const PupilPoint> pupil,
                   Cache& cache, const PupilMesh* fine = nullptr) const;
  // The four nodes around a point and their bilinear weights.
  struct Cell {
    std::int64_t i = 0, j = 0;
    double a = 0.0, b = 0.0;  // fractions along field and depth
    double cos_azimuth = 1.0, sin_azimuth = 0.0;
  };
  Cell cell(const ScenePoint& point) const;

  const RayModel& model_;
  double field_step_ = 0.0;  // direction tangent per node
  double depth_step_ = 0.0;  // inverse depth (1/mm) per node
  SharedMemo<Node> nodes_;
};

}  // namespace lensmith::render_detail
