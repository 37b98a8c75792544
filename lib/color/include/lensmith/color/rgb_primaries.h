// RGB colour spaces by their primaries and white point (CIE 1931 xy), and the 3x3 matrices between
// their linear values: RGB -> XYZ by SMPTE RP 177-1993 (the primaries scaled so that RGB (1, 1, 1)
// is the white with Y = 1), and a change of white by the Bradford chromatic adaptation (Lam 1985,
// as ACES and Lindbloom use it). lensmith's working space is linear Rec.709 (rgb.h); colour
// management (color_space_conversion.h) reaches it from ACES2065-1 with rgb_conversion below.
#pragma once

#include <ostream>
#include <string>

#include "lensmith/color/cie1931.h"  // Chromaticity
#include "lensmith/color/rgb.h"

namespace lensmith {

struct RgbPrimaries {
  const char* name = "";
  Chromaticity red, green, blue, white;

  std::string to_string() const;  // "Rec.709 primaries (R 0.64, 0.33; G ...; white 0.3127, 0.329)"
  friend std::ostream& operator<<(std::ostream& os, const RgbPrimaries& p) { return os << p.to_string(); }
};

// ITU-R BT.709-6 (sRGB's primaries), D65 white.
inline constexpr RgbPrimaries kRec709Primaries{"Rec.709", {0.64, 0.33}, {0.30, 0.60}, {0.15, 0.06}, {0.3127, 0.3290}};
// ACES AP0 (ACES2065-1, SMPTE ST 2065-1:2012), the ACES white (x 0.32168, y 0.33767, near D60).
inline constexpr RgbPrimaries kAcesAp0Primaries{"ACES AP0", {0.7347, 0.2653}, {0.0, 1.0}, {0.0001, -0.0770}, {0.32168, 0.33767}};
// ACES AP1 (ACEScg, Academy S-2014-004), the ACES white.
inline constexpr RgbPrimaries kAcesAp1Primaries{"ACES AP1", {0.713, 0.293}, {0.165, 0.830}, {0.128, 0.044}, {0.32168, 0.33767}};

// Linear RGB of `primaries` -> XYZ (Y of the white = 1), SMPTE RP 177-1993 section 3.3.
Matrix3 xyz_from_rgb(const RgbPrimaries& primaries);

// XYZ under white `from` -> XYZ under white `to` by the Bradford transform (identity when equal).
Matrix3 bradford_adaptation(const Chromaticity& from, const Chromaticity& to);

// Linear RGB of `from` -> linear RGB of `to`, adapting the white by Bradford when the whites differ
// (so `from`'s white maps to `to`'s white, RGB (1, 1, 1) -> (1, 1, 1)).
Matrix3 rgb_conversion(const RgbPrimaries& from, const RgbPrimaries& to);

}  // namespace lensmith
