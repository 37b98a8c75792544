// The shape of the aperture stop, in normalised pupil coordinates: the unit disc is the full
// aperture of the chosen f-number (radius 1 = the entrance-pupil radius EFL / (2 N)). A circular
// iris, a regular polygon of N straight blades inscribed in that circle, or a transmission mask
// read from an image over [-1, 1] x [-1, 1] (for cat's-eye, heart-shaped or apodised apertures).
#pragma once

#include <ostream>
#include <span>
#include <string>
#include <vector>

namespace lensmith {

struct PupilPoint {
  double x = 0.0;  // normalised pupil coordinates (sagittal x, y up), |p| <= 1 inside a circular aperture
  double y = 0.0;
};

// A triangle of a pupil mesh with the fraction of the aperture's transmitted energy it carries.
struct PupilTriangle {
  int a = 0, b = 0, c = 0;  // indices into PupilMesh::points
  double weight = 0.0;      // sum over the mesh is 1
};

// A triangulated aperture. Polar meshes (circle, blades) have their outer ring exactly on the
// aperture's edge, so a mapped mesh keeps a sharp bokeh edge whatever the ring count; mask meshes
// are Cartesian grids weighted by the mask's mean transmission per cell.
struct PupilMesh {
  std::vector<PupilPoint> points;
  std::vector<PupilTriangle> triangles;
  int rings = 0;    // polar meshes: rings of vertices outside the centre; grids: cells per side
  int sectors = 0;  // polar meshes: vertices per ring
  std::string to_string() const;
};

// A disc of the normalised pupil (centre and radius in pupil units): the pupil points whose rays
// pass one clear aperture, to first order (RayModel::clip_discs).
struct PupilDisc {
  double x = 0.0;
  double y = 0.0;
  double radius = 0.0;
};

// How far inside every one of `discs` (their radii scaled by `radius_scale`) pupil point `p` lies,
// as a fraction of each disc's radius: min over the discs of 1 - |p - c| / R, and at most 1 (the
// clearance a first-order model gives the ray through `p`, SensorHit::clearance).
double disc_clearance(const PupilPoint& p, std::span<const PupilDisc> discs, double radius_scale = 1.0);

// Area of a simple polygon of the pupil (shoelace formula), either winding.
double pupil_polygon_area(const std::vector<PupilPoint>& polygon);

// `convex` (a convex pupil polygon, either winding) less what lies outside any of `discs`, into
// `out` (empty when nothing is left): each disc cuts in turn, in O(vertices) — vertices inside it
// stay, an edge that leaves it ends where it crosses the circle, and the circle's arc inside the
// polygon (which, both being convex, runs from that exit to the next entry) is drawn in chords of
// at most 0.1 rad, within 1/800 of its radius. `work` is scratch space.
void clip_pupil_polygon(const std::vector<PupilPoint>& convex, std::span<const PupilDisc> discs, std::vector<PupilPoint>& out,
                        std::vector<PupilPoint>& work);

class Aperture {
 public:
  enum class Kind { Circular, Blades, Mask };

  static Aperture circular();
  // A regular polygon with `blades` corners (3..64) on the unit circle, one corner at
  // `rotation_deg` counter-clockwise from +y (the top of the picture).
  static Aperture blades(int blades, double rotation_deg);
  // A transmission mask sampled on a width x height grid covering [-1, 1]^2 (row 0 at the top,
  // values >= 0, at least one > 0). Throws OptionsError otherwise.
  static Aperture mask(int width, int height, std::vector<float> transmission);

  Kind kind() const { return kind_; }
  int blade_count() const { return blades_; }
  double rotation_deg() const { return rotation_deg_; }
  // Uniform transmission inside a convex outline (circle, blades): a thin-lens or paraxial bokeh
  // is then one uniformly lit polygon.
  bool is_uniform_convex() const { return kind_ != Kind::Mask; }

  // Distance from the centre to the edge along direction theta (radians, counter-clockwise from +x).
  double edge_radius(double theta_rad) const;
  // The outline as a counter-clockwise polygon with at least min_vertices vertices (polygons keep
  // their corners exactly). Circular and Blades only.
  std::vector<PupilPoint> outline(int min_vertices) const;
  // Transmission at a pupil point (0 outside).
  double transmission(const PupilPoint& p) const;
  // Area in normalised units times mean transmission (pi for the circle).
  double effective_area() const;

  // A mesh with `rings` rings and about `sectors` vertices per ring (rounded up to a multiple of the
  // blade count for polygons; mask grids use `rings` cells per side).
  PupilMesh mesh(int rings, int sectors) const;

  std::string to_string() const;  // "circular", "7 blades at 15 deg", "mask 64 x 64"
  friend std::ostream& operator<<(std::ostream& os, const Aperture& a) { return os << a.to_string(); }

 private:
  Kind kind_ = Kind::Circular;
  int blades_ = 0;
  double rotation_deg_ = 0.0;
  int mask_width_ = 0;
  int mask_height_ = 0;
  std::vector<float> mask_;
  double effective_area_ = 0.0;
};

}  // namespace lensmith
