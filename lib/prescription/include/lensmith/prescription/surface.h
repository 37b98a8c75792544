// One surface of a sequential lens: a refracting or reflecting (mirror) surface, a dummy or stop, or a
// coordinate break; its shape, the medium after it, and its clear aperture. Shapes (docs/lens-format.md):
// - Standard: z(r) = c r^2 / (1 + sqrt(1 - (1 + k) c^2 r^2)) + sum_j a_{2j} r^{2j} (Zemax "Even
//   Asphere"; the r^2 term a2 adds 2 a2 to the paraxial curvature).
// - Toroidal (Zemax TOROIDAL): the curve z_y(y) = c y^2 / (1 + sqrt(1 - (1 + k) c^2 y^2)) + sum_j a_{2j} y^{2j}
//   in the y-z plane, swept about an axis parallel to y at distance R (the radius of rotation) from the
//   vertex: z = R - sign(R - z_y) sqrt((R - z_y)^2 - x^2); R infinite (curvature_x 0) is a cylinder.
// - Biconic (Zemax BICONICX): z = (cx x^2 + cy y^2) / (1 + sqrt(1 - (1 + kx) cx^2 x^2 - (1 + ky) cy^2 y^2)).
// - CoordinateBreak: no optical effect; the surfaces after it are decentred and tilted (Zemax COORDBRK).
#pragma once

#include <array>
#include <optional>
#include <ostream>
#include <string>
#include <string_view>

#include "lensmith/glass/glass.h"
#include "lensmith/prescription/material.h"

namespace lensmith {

// An explicit aperture on a surface, in the surface's local x-y plane (mm), for apertures other than
// the plain circle of Surface::semi_diameter_mm: an annulus, a rectangle, an ellipse, their
// obscuring versions (rays inside are stopped: a central obscuration), decentred. Zemax CLAP,
// SQAP, ELAP, OBSC, OBSQ, ELOB with OBDC; CODE V CIR/REX/ELX with OBS. docs/lens-format.md.
struct SurfaceAperture {
  enum class Shape { Circular, Rectangular, Elliptical };
  Shape shape = Shape::Circular;
  bool obscuration = false;     // true: stops the rays inside the shape and passes those outside
  double min_radius_mm = 0.0;   // Circular, not an obscuration: the inner radius of an annulus (0 = none)
  double half_x_mm = 0.0;       // Circular: the radius; Rectangular/Elliptical: half width in x
  double half_y_mm = 0.0;       // Circular: unused (= half_x_mm); Rectangular/Elliptical: half width in y
  double decenter_x_mm = 0.0;   // the shape's centre in the surface's x-y plane
  double decenter_y_mm = 0.0;

  // True when a ray meeting the surface at (x, y) (mm, local) passes, within `tolerance_mm` of the
  // edge in its favour (the rim tolerance of docs/trace.md).
  bool passes(double x_mm, double y_mm, double tolerance_mm) const;
  // How far inside what passes (x, y) lies, relative to the shape's size: 1 - r / R for a circle, 1 -
  // max(|x| / a, |y| / b) for a rectangle, 1 - sqrt((x / a)^2 + (y / b)^2) for an ellipse; for an
  // obscuration the same measure outside it, negated; for an annulus the smaller of the outer and inner
  // margins. 0 on the rim, < 0 where the ray is stopped (the edge of a beam lies between rays by it).
  double clearance(double x_mm, double y_mm) const;
  // The radius of the circle about the axis that holds every point that can pass (mm; +infinity for
  // an obscuration): the surface's extent for drawing and for fits.
  double outer_radius_mm() const;
  friend bool operator==(const SurfaceAperture&, const SurfaceAperture&) = default;
  std::string to_string() const;  // "circular r 12.5 mm", "rectangular obscuration 3 x 2 mm at (0, 1)"
};

// Zemax's coordinate break: the local frame of the surfaces after it moved and turned. Tilts are right-handed
// rotations of the coordinate system about its own (already turned) axes, degrees. Order 0 (tilt_first false):
// decentre in x and y, then tilt about x, then y, then z. Order 1: tilt about z, then y, then x, then decentre
// (in the tilted frame). A break with every value negated and the order toggled undoes it. The break's own
// thickness is then measured along the new z axis.
struct CoordinateBreak {
  double decenter_x_mm = 0.0;
  double decenter_y_mm = 0.0;
  double tilt_x_deg = 0.0;
  double tilt_y_deg = 0.0;
  double tilt_z_deg = 0.0;
  bool tilt_first = false;  // Zemax's order flag 1
  bool is_identity() const {
    return decenter_x_mm == 0.0 && decenter_y_mm == 0.0 && tilt_x_deg == 0.0 && tilt_y_deg == 0.0 && tilt_z_deg == 0.0;
  }
  CoordinateBreak inverse() const;  // the break that undoes this one
  friend bool operator==(const CoordinateBreak&, const CoordinateBreak&) = default;
  std::string to_string() const;  // "decentre (0, 5) mm, tilt (45, 0, 0) deg, decentre first"
};

// The shape family of a surface (see the file comment).
enum class SurfaceKind { Standard, Toroidal, Biconic, CoordinateBreak };
std::string_view to_string(SurfaceKind kind);  // "standard", "toroidal", "biconic", "coordinate_break"

// The two principal sections of a surface that is not rotationally symmetric: y (tangential, the y-z
// plane, Zemax's paraxial section) and x (sagittal, x-z).
enum class Section { Y, X };

struct Surface {
  // Even-asphere coefficients a2, a4, ..., a16 (index j holds the r^(2j+2) term), in mm^(1 - 2(j+1)).
  using EvenAsphere = std::array<double, 8>;

  double curvature_per_mm = 0.0;     // 1 / radius; 0 = plane (conventions.h for the sign)
  double thickness_mm = 0.0;         // vertex of this surface to the next vertex (last: to the image plane)
  MaterialSpec material;             // the medium after this surface (on its image side)
  Glass medium = Glass::air();       // `material` resolved against a glass catalogue
  // The surface's semi-diameter; empty = not given. Whether it stops rays is `clips_rays`.
  std::optional<double> semi_diameter_mm;
  // True (lensmith JSON, pbrt, lentil, CODE V CIR): semi_diameter_mm is a clear aperture, and rays
  // beyond it are vignetted. False (Zemax DIAM without an aperture on the surface, as OpticStudio
  // means it): the semi-diameter only sizes the surface (drawing, edge thickness, a stop that the
  // aperture floats by) and real-ray analyses do not clip there. The bokeh camera clips at every
  // semi-diameter either way: a real lens's glass ends at its edge (docs/lens-format.md, "Apertures").
  bool clips_rays = true;
  // An explicit aperture that replaces the circle of semi_diameter_mm for clipping; empty = none.
  std::optional<SurfaceAperture> aperture;
  bool is_stop = false;              // the aperture stop
  double conic = 0.0;                // conic constant k: 0 sphere, -1 paraboloid, < -1 hyperboloid (Toroidal,
                                     // Biconic: of the y section)
  EvenAsphere even_asphere{};        // all zero for a conic or sphere (Toroidal: the y^2 ... y^16 terms)
  SurfaceKind kind = SurfaceKind::Standard;
  // A mirror: rays reflect here, and the medium after it is the medium before it (the material is set so when
  // the prescription resolves its glasses). Sequential convention: after an odd number of mirrors rays travel
  // toward -z of the local frame and thicknesses are negative.
  bool mirror = false;
  // Toroidal: 1 / the radius of rotation (the curvature in x at the vertex; 0: a cylinder, flat in x).
  // Biconic: the x curvature cx. Unused by the other kinds.
  double curvature_x_per_mm = 0.0;
  double conic_x = 0.0;              // Biconic: the x conic constant kx
  CoordinateBreak coordinate_break;  // CoordinateBreak only
  std::string comment;

  double radius_mm() const;          // 1 / curvature; +infinity for a plane (the y radius of a toroid or biconic)
  // The largest semi-diameter the conic's sag is defined for (mm): 1 / sqrt((1 + k) c^2) where
  // (1 + k) c^2 > 0 (a sphere: |R|), else +infinity.
  double max_semi_diameter_mm() const;
  // The sag z(r) of the conic plus even asphere at radius r (mm), measured from the vertex along
  // +z; NaN where the conic is undefined (r beyond max_semi_diameter_mm()). For a toroid or biconic, the
  // sag along y (the y section); a coordinate break has none (0).
  double sag_mm(double r_mm) const;
  // The sag at (x, y) (mm, local frame) of any kind, and its partial derivatives dz/dx, dz/dy; false (and
  // nothing set) outside the shape's domain. One home for the shapes that are not rotationally symmetric.
  bool sag_and_slope(double x_mm, double y_mm, double& sag_mm, double& dz_dx, double& dz_dy) const;
  bool is_plane() const {
    return kind == SurfaceKind::CoordinateBreak ||
           (curvature_per_mm == 0.0 && !has_asphere() && (kind == SurfaceKind::Standard || curvature_x_per_mm == 0.0));
  }
  // Rotationally symmetric about the local z axis (Standard, or a toroid/biconic with equal sections).
  bool is_rotationally_symmetric() const;
  bool is_coordinate_break() const { return kind == SurfaceKind::CoordinateBreak; }
  bool has_asphere() const;          // any non-zero even-asphere coefficient
  // Curvature that paraxial optics sees: c + 2 a2 (1/mm), in the y section (Zemax's paraxial section).
  double paraxial_curvature_per_mm() const { return paraxial_curvature_per_mm(Section::Y); }
  // ... in either section: y as above; x: c + 2 a2 (Standard), curvature_x_per_mm (Toroidal, Biconic).
  double paraxial_curvature_per_mm(Section section) const;

  friend bool operator==(const Surface&, const Surface&) = default;
  std::string to_string() const;
  friend std::ostream& operator<<(std::ostream& os, const Surface& s) { return os << s.to_string(); }
};

}  // namespace lensmith
