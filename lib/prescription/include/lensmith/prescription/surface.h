// One refracting (or dummy / stop) surface of a sequential lens: shape, the medium after it, and
// its clear aperture. Shape: z(r) = c r^2 / (1 + sqrt(1 - (1 + k) c^2 r^2)) + sum_j a_{2j} r^{2j}
// (Zemax "Even Asphere"; the r^2 term a2 adds 2 a2 to the paraxial curvature).
#pragma once

#include <array>
#include <optional>
#include <ostream>
#include <string>

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
  // The radius of the circle about the axis that holds every point that can pass (mm; +infinity for
  // an obscuration): the surface's extent for drawing and for fits.
  double outer_radius_mm() const;
  friend bool operator==(const SurfaceAperture&, const SurfaceAperture&) = default;
  std::string to_string() const;  // "circular r 12.5 mm", "rectangular obscuration 3 x 2 mm at (0, 1)"
};

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
  double conic = 0.0;                // conic constant k: 0 sphere, -1 paraboloid, < -1 hyperboloid
  EvenAsphere even_asphere{};        // all zero for a conic or sphere
  std::string comment;

  double radius_mm() const;          // 1 / curvature; +infinity for a plane
  // The largest semi-diameter the conic's sag is defined for (mm): 1 / sqrt((1 + k) c^2) where
  // (1 + k) c^2 > 0 (a sphere: |R|), else +infinity.
  double max_semi_diameter_mm() const;
  // The sag z(r) of the conic plus even asphere at radius r (mm), measured from the vertex along
  // +z; NaN where the conic is undefined (r beyond max_semi_diameter_mm()).
  double sag_mm(double r_mm) const;
  bool is_plane() const { return curvature_per_mm == 0.0 && !has_asphere(); }
  bool has_asphere() const;          // any non-zero even-asphere coefficient
  // Curvature that paraxial optics sees: c + 2 a2 (1/mm).
  double paraxial_curvature_per_mm() const { return curvature_per_mm + 2.0 * even_asphere[0]; }

  friend bool operator==(const Surface&, const Surface&) = default;
  std::string to_string() const;
  friend std::ostream& operator<<(std::ostream& os, const Surface& s) { return os << s.to_string(); }
};

}  // namespace lensmith
