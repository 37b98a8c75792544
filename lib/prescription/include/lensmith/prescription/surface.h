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

struct Surface {
  // Even-asphere coefficients a2, a4, ..., a16 (index j holds the r^(2j+2) term), in mm^(1 - 2(j+1)).
  using EvenAsphere = std::array<double, 8>;

  double curvature_per_mm = 0.0;     // 1 / radius; 0 = plane (conventions.h for the sign)
  double thickness_mm = 0.0;         // vertex of this surface to the next vertex (last: to the image plane)
  MaterialSpec material;             // the medium after this surface (on its image side)
  Glass medium = Glass::air();       // `material` resolved against a glass catalogue
  std::optional<double> semi_diameter_mm;  // clear semi-diameter; empty = unlimited
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
