// The pupil meshes and outlines a render uses, from fixed size steps: polar meshes (rings x
// sectors, the outer ring on the aperture's edge) for circles and blades, Cartesian grids for
// aperture pictures, and outlines for the single-polygon footprints of affine models. Outlines are
// made with the table; each mesh when a footprint first asks for it (a thin lens needs none, and
// making all 72 took about 5 ms of a 0.1 s render).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

#include "lensmith/camera/aperture.h"

namespace lensmith::render_detail {

class PupilMeshTable {
 public:
  explicit PupilMeshTable(const Aperture& aperture);

  // Step index of the sector count that keeps a polygon inscribed in a circle of this diameter (px)
  // within 0.1 px of it.
  static int sector_step(double diameter_px);
  // Mesh index of a polar mesh with at least `rings` rings (capped) and the sectors of `sector_step`.
  static int polar_mesh(double rings, int sector_step);
  // The sector step of a polar mesh index.
  static int sector_step_of_mesh(int mesh_index);
  // Mesh index of a grid with at least `cells` cells per side (capped); aperture pictures only.
  static int grid_mesh(double cells);

  // The polar mesh a beam's passing light is measured on (MappedPupilTable::passing_light,
  // IlluminationTable): 8 rings of 48 sectors. A white wall's corner through the double Gauss at f/2
  // (tests/scene's radiometry) 0.2959 with it against the ground truth's 0.2940; 0.302 from the
  // footprints' own 4-ring meshes.
  static int light_mesh() { return polar_mesh(8, 5); }
  static constexpr int kShareSectorStep = 4;  // 32 sectors: a polygon within 0.6 % of the circle's area
  // Made on first use (thread-safe); the table's aperture must outlive it.
  const PupilMesh& mesh(int index) const;
  // A mesh's edges, for depositing its triangles together (SplatBuffer::add_mesh): each edge's two
  // vertex indices, and per triangle its edges a-b, b-c, c-a with +1 where the triangle walks the
  // edge from ends[0] to ends[1], -1 the other way. Made with the mesh.
  struct Edges {
    std::vector<std::array<std::uint32_t, 2>> ends;
    std::vector<std::array<std::uint32_t, 3>> of_triangle;
    std::vector<std::array<std::int8_t, 3>> direction;
  };
  const Edges& edges(int index) const;
  // The outline for a sector step (blades: their corners only).
  const std::vector<PupilPoint>& outline(int sector_step) const { return outlines_[static_cast<std::size_t>(sector_step)]; }
  // The outline with the sector step's vertex count, blades' edges included point by point (for
  // cutting it along vertex directions).
  const std::vector<PupilPoint>& dense_outline(int sector_step) const { return dense_outlines_[static_cast<std::size_t>(sector_step)]; }
  // A dense outline's vertex directions from the centre, as unit vectors and 1 / the vertex's
  // distance (struct of arrays, for vectorised cuts along them).
  struct Directions {
    std::vector<double> ux, uy, inverse_length;
    // Half the cross product of vertex j and vertex j + 1 (the area of their triangle with the
    // centre), and the outline's area: an outline scaled by f_j along each direction has the area
    // sum of f_j f_(j+1) half_cross_j.
    std::vector<double> half_cross;
    double area = 0.0;
  };
  const Directions& dense_directions(int sector_step) const { return dense_directions_[static_cast<std::size_t>(sector_step)]; }

 private:
  const Aperture* aperture_;
  // polar: ring step * sector steps + sector step; masks: grid steps
  mutable std::vector<PupilMesh> meshes_;
  mutable std::vector<Edges> edges_;
  mutable std::unique_ptr<std::once_flag[]> built_;
  std::vector<std::vector<PupilPoint>> outlines_;  // per sector step
  std::vector<std::vector<PupilPoint>> dense_outlines_;
  std::vector<Directions> dense_directions_;
};

}  // namespace lensmith::render_detail
