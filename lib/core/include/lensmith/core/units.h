// Unit conversions: one named function per unit pair, so no inline `/ 1000` hides a unit change.
// Lens geometry is in millimetres, wavelengths in nanometres, scene depth in metres.
#pragma once

#include <cmath>
#include <limits>

namespace lensmith {

inline constexpr double kInfinity = std::numeric_limits<double>::infinity();
inline constexpr double kPi = 3.14159265358979323846;

constexpr double mm_from_m(double metres) { return metres * 1000.0; }
constexpr double m_from_mm(double millimetres) { return millimetres / 1000.0; }
constexpr double mm_from_cm(double centimetres) { return centimetres * 10.0; }
constexpr double mm_from_inch(double inches) { return inches * 25.4; }
constexpr double um_from_nm(double nanometres) { return nanometres / 1000.0; }
constexpr double nm_from_um(double micrometres) { return micrometres * 1000.0; }
// A wavelength read in micrometres (as Zemax writes it) in nanometres, rounded to 1e-6 nm so that
// "0.5875618" becomes exactly the double nearest 587.5618 rather than 587.5618000000001.
inline double nm_from_um_rounded(double micrometres) {
  // Outside any optical range (or NaN) there is nothing to round; avoid an overflowing cast.
  if (!(micrometres > -1.0e6 && micrometres < 1.0e6)) return nm_from_um(micrometres);
  return static_cast<double>(static_cast<long long>(micrometres * 1.0e9 + (micrometres >= 0 ? 0.5 : -0.5))) / 1.0e6;
}
constexpr double um_from_mm(double millimetres) { return millimetres * 1000.0; }
constexpr double mm_from_nm(double nanometres) { return nanometres / 1.0e6; }
// The one conversion between a distance and its inverse (depth and object distance in the camera and
// the aberration tables, which interpolate in 1/distance): 1/mm, with 0 for +inf both ways.
inline double inverse_per_mm(double distance_mm) { return std::isinf(distance_mm) ? 0.0 : 1.0 / distance_mm; }
inline double distance_mm_from_inverse(double inverse_per_mm) { return inverse_per_mm > 0.0 ? 1.0 / inverse_per_mm : kInfinity; }
// Inverse planar depth (1/mm) of a scene depth in metres (+inf: 0).
inline double inverse_depth_per_mm(double depth_m) { return inverse_per_mm(mm_from_m(depth_m)); }
constexpr double rad_from_deg(double degrees) { return degrees * (kPi / 180.0); }
constexpr double deg_from_rad(double radians) { return radians * (180.0 / kPi); }

// Fraunhofer lines used for nd, Vd and primary colour (nm; Schott catalogue values).
inline constexpr double kWavelengthD_nm = 587.5618;  // helium d
inline constexpr double kWavelengthF_nm = 486.1327;  // hydrogen F
inline constexpr double kWavelengthC_nm = 656.2725;  // hydrogen C

}  // namespace lensmith
