#include "lensmith/prescription/surface.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <cstdio>

#include "lensmith/core/units.h"
#include "lensmith/prescription/conic_profile.h"

namespace lensmith {

std::string_view to_string(SurfaceKind kind) {
  switch (kind) {
    case SurfaceKind::Standard: return "standard";
    case SurfaceKind::Toroidal: return "toroidal";
    case SurfaceKind::Biconic: return "biconic";
    case SurfaceKind::CoordinateBreak: return "coordinate_break";
  }
  return "standard";
}

CoordinateBreak CoordinateBreak::inverse() const {
  return CoordinateBreak{-decenter_x_mm, -decenter_y_mm, -tilt_x_deg, -tilt_y_deg, -tilt_z_deg, !tilt_first};
}

std::string CoordinateBreak::to_string() const {
  char buffer[200];
  std::snprintf(buffer, sizeof buffer, "decentre (%.6g, %.6g) mm, tilt (%.6g, %.6g, %.6g) deg, %s", decenter_x_mm, decenter_y_mm,
                tilt_x_deg, tilt_y_deg, tilt_z_deg, tilt_first ? "tilt first" : "decentre first");
  return buffer;
}

bool Surface::is_rotationally_symmetric() const {
  switch (kind) {
    case SurfaceKind::Standard:
    case SurfaceKind::CoordinateBreak: return true;
    case SurfaceKind::Toroidal:
      // A toroid whose radius of rotation equals its y radius, without y terms, is a sphere.
      return conic == 0.0 && !has_asphere() && curvature_x_per_mm == curvature_per_mm;
    case SurfaceKind::Biconic: return curvature_x_per_mm == curvature_per_mm && conic_x == conic;
  }
  return true;
}

double Surface::paraxial_curvature_per_mm(Section section) const {
  switch (kind) {
    case SurfaceKind::Standard: return curvature_per_mm + 2.0 * even_asphere[0];
    case SurfaceKind::CoordinateBreak: return 0.0;
    case SurfaceKind::Toroidal: return section == Section::Y ? curvature_per_mm + 2.0 * even_asphere[0] : curvature_x_per_mm;
    case SurfaceKind::Biconic: return section == Section::Y ? curvature_per_mm : curvature_x_per_mm;
  }
  return curvature_per_mm;
}

namespace {

// The conic-plus-even-polynomial profile z(u), u = r^2, and dz/du (Standard surfaces, and a toroid's y curve
// with u = y^2); false outside the conic's domain. conic_profile.h is its one home.
bool profile(double c, double conic, const Surface::EvenAsphere& a, double u, double& z, double& dz_du) {
  return conic_profile(c, 1.0 + conic, a.data(), static_cast<int>(a.size()), u, z, dz_du);
}

}  // namespace

bool Surface::sag_and_slope(double x, double y, double& sag, double& dz_dx, double& dz_dy) const {
  switch (kind) {
    case SurfaceKind::CoordinateBreak:
      sag = dz_dx = dz_dy = 0.0;
      return true;
    case SurfaceKind::Standard: {
      double z = 0.0, dz_du = 0.0;
      if (!profile(curvature_per_mm, conic, even_asphere, x * x + y * y, z, dz_du)) return false;
      sag = z;
      dz_dx = 2.0 * x * dz_du;
      dz_dy = 2.0 * y * dz_du;
      return true;
    }
    case SurfaceKind::Toroidal: {
      double zy = 0.0, dzy_du = 0.0;
      if (!profile(curvature_per_mm, conic, even_asphere, y * y, zy, dzy_du)) return false;
      const double dzy = 2.0 * y * dzy_du;
      if (curvature_x_per_mm == 0.0) {  // a cylinder: the y curve swept along x
        sag = zy;
        dz_dx = 0.0;
        dz_dy = dzy;
        return true;
      }
      const double radius = 1.0 / curvature_x_per_mm;
      const double a = radius - zy;  // distance of the y curve from the axis of rotation
      const double q2 = a * a - x * x;
      if (!(q2 > 0.0)) return false;
      const double q = std::sqrt(q2);
      const double s = a > 0.0 ? 1.0 : -1.0;
      // z = R - s q: at x = 0, z = R - |a| s = z_y.  dz/dx = s x / q, dz/dy = s a z_y' / q.
      sag = radius - s * q;
      dz_dx = s * x / q;
      dz_dy = s * a * dzy / q;
      return std::isfinite(sag);
    }
    case SurfaceKind::Biconic: {
      const double cx = curvature_x_per_mm, cy = curvature_per_mm;
      const double d = 1.0 - (1.0 + conic_x) * cx * cx * x * x - (1.0 + conic) * cy * cy * y * y;
      if (d < 0.0) return false;
      const double root = std::sqrt(d);
      const double numerator = cx * x * x + cy * y * y;
      const double denominator = 1.0 + root;
      sag = numerator / denominator;
      if (root == 0.0) return false;  // the rim of the domain: the slope is infinite
      // dz/dx = (2 cx x (1 + S) - N dS/dx) / (1 + S)^2 with dS/dx = -(1 + kx) cx^2 x / S.
      const double ds_dx = -(1.0 + conic_x) * cx * cx * x / root;
      const double ds_dy = -(1.0 + conic) * cy * cy * y / root;
      dz_dx = (2.0 * cx * x * denominator - numerator * ds_dx) / (denominator * denominator);
      dz_dy = (2.0 * cy * y * denominator - numerator * ds_dy) / (denominator * denominator);
      return std::isfinite(sag);
    }
  }
  return false;
}

double Surface::radius_mm() const { return curvature_per_mm == 0.0 ? kInfinity : 1.0 / curvature_per_mm; }

double Surface::max_semi_diameter_mm() const { return conic_max_radius_mm(curvature_per_mm, 1.0 + conic); }

double Surface::sag_mm(double r_mm) const {
  return conic_sag(curvature_per_mm, 1.0 + conic, even_asphere.data(), static_cast<int>(even_asphere.size()), r_mm * r_mm);
}

bool SurfaceAperture::passes(double x_mm, double y_mm, double tolerance_mm) const {
  const double x = x_mm - decenter_x_mm;
  const double y = y_mm - decenter_y_mm;
  // inside: within the shape grown by the tolerance (an aperture lets its rim pass); for an
  // obscuration the shape shrinks by it instead (its rim passes too).
  const double grow = obscuration ? -tolerance_mm : tolerance_mm;
  bool inside = false;
  switch (shape) {
    case Shape::Circular: {
      const double r = half_x_mm + grow;
      inside = r > 0.0 && x * x + y * y <= r * r;
      if (inside && !obscuration && min_radius_mm > 0.0) {
        const double r_min = std::max(0.0, min_radius_mm - tolerance_mm);
        if (x * x + y * y < r_min * r_min) return false;
      }
      break;
    }
    case Shape::Rectangular: inside = std::abs(x) <= half_x_mm + grow && std::abs(y) <= half_y_mm + grow; break;
    case Shape::Elliptical: {
      const double a = half_x_mm + grow, b = half_y_mm + grow;
      inside = a > 0.0 && b > 0.0 && (x / a) * (x / a) + (y / b) * (y / b) <= 1.0;
      break;
    }
  }
  return obscuration ? !inside : inside;
}

double SurfaceAperture::clearance(double x_mm, double y_mm) const {
  const double x = x_mm - decenter_x_mm, y = y_mm - decenter_y_mm;
  double inside = 0.0;  // 1 - (relative distance from the centre), for the shape itself
  switch (shape) {
    case Shape::Circular: inside = 1.0 - std::hypot(x, y) / half_x_mm; break;
    case Shape::Rectangular: inside = 1.0 - std::max(std::abs(x) / half_x_mm, std::abs(y) / half_y_mm); break;
    case Shape::Elliptical: inside = 1.0 - std::hypot(x / half_x_mm, y / half_y_mm); break;
  }
  if (obscuration) return -inside;
  if (shape == Shape::Circular && min_radius_mm > 0.0) inside = std::min(inside, std::hypot(x, y) / min_radius_mm - 1.0);
  return inside;
}

double SurfaceAperture::outer_radius_mm() const {
  if (obscuration) return kInfinity;
  const double dx = std::abs(decenter_x_mm), dy = std::abs(decenter_y_mm);
  switch (shape) {
    case Shape::Circular: return std::hypot(dx, dy) + half_x_mm;
    case Shape::Rectangular: return std::hypot(dx + half_x_mm, dy + half_y_mm);
    case Shape::Elliptical: return std::hypot(dx, dy) + std::max(half_x_mm, half_y_mm);
  }
  return kInfinity;
}

std::string SurfaceAperture::to_string() const {
  char buffer[160];
  const char* kind = shape == Shape::Circular ? "circular" : shape == Shape::Rectangular ? "rectangular" : "elliptical";
  if (shape == Shape::Circular) {
    std::snprintf(buffer, sizeof buffer, "%s%s r %.6g mm", kind, obscuration ? " obscuration" : "", half_x_mm);
  } else {
    std::snprintf(buffer, sizeof buffer, "%s%s %.6g x %.6g mm (half widths)", kind, obscuration ? " obscuration" : "", half_x_mm,
                  half_y_mm);
  }
  std::string s = buffer;
  if (min_radius_mm > 0.0) {
    std::snprintf(buffer, sizeof buffer, ", inner r %.6g mm", min_radius_mm);
    s += buffer;
  }
  if (decenter_x_mm != 0.0 || decenter_y_mm != 0.0) {
    std::snprintf(buffer, sizeof buffer, " at (%.6g, %.6g) mm", decenter_x_mm, decenter_y_mm);
    s += buffer;
  }
  return s;
}

bool Surface::has_asphere() const {
  return std::any_of(even_asphere.begin(), even_asphere.end(), [](double a) { return a != 0.0; });
}

std::string Surface::to_string() const {
  char buffer[256];
  const double r = radius_mm();
  char radius[32];
  if (curvature_per_mm == 0.0) {
    std::snprintf(radius, sizeof radius, "%s", "flat");
  } else {
    std::snprintf(radius, sizeof radius, "%.6g", r);
  }
  char semi[32];
  if (semi_diameter_mm) {
    std::snprintf(semi, sizeof semi, "%.6g", *semi_diameter_mm);
  } else {
    std::snprintf(semi, sizeof semi, "%s", "-");
  }
  std::snprintf(buffer, sizeof buffer, "R=%s mm t=%.6g mm %s sd=%s%s%s%s", radius, thickness_mm, material.to_string().c_str(),
                semi, semi_diameter_mm && !clips_rays ? " (not clipping)" : "", is_stop ? " STOP" : "", conic != 0.0 ? " conic" : "");
  std::string s = buffer;
  if (conic != 0.0) {
    std::snprintf(buffer, sizeof buffer, "=%.6g", conic);
    s += buffer;
  }
  if (has_asphere()) {
    s += " asphere[";
    for (std::size_t j = 0; j < even_asphere.size(); ++j) {
      if (even_asphere[j] == 0.0) continue;
      std::snprintf(buffer, sizeof buffer, " a%zu=%.6g", 2 * (j + 1), even_asphere[j]);
      s += buffer;
    }
    s += " ]";
  }
  if (aperture) s += " aperture[" + aperture->to_string() + "]";
  if (mirror) s += " MIRROR";
  if (kind == SurfaceKind::Toroidal || kind == SurfaceKind::Biconic) {
    std::snprintf(buffer, sizeof buffer, " %s Rx=%.6g", kind == SurfaceKind::Toroidal ? "toroidal" : "biconic",
                  curvature_x_per_mm == 0.0 ? kInfinity : 1.0 / curvature_x_per_mm);
    s += buffer;
    if (kind == SurfaceKind::Biconic && conic_x != 0.0) {
      std::snprintf(buffer, sizeof buffer, " kx=%.6g", conic_x);
      s += buffer;
    }
  }
  if (kind == SurfaceKind::CoordinateBreak) {
    std::snprintf(buffer, sizeof buffer, "coordinate break: %s, t=%.6g mm", coordinate_break.to_string().c_str(), thickness_mm);
    return buffer;
  }
  return s;
}

}  // namespace lensmith
