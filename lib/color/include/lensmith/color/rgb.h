// Linear Rec.709 / sRGB colour (ITU-R BT.709 primaries, D65 white) and its 3x3 matrices.
// The XYZ -> linear sRGB matrix is the one printed in IEC 61966-2-1:1999, section 5.2.
#pragma once

#include <array>
#include <ostream>
#include <string>

#include "lensmith/color/cie1931.h"

namespace lensmith {

// A linear (not gamma-encoded) Rec.709 RGB triple. Components may be negative for colours
// outside the Rec.709 gamut (e.g. a monochromatic wavelength).
struct Rgb {
  double r = 0.0;
  double g = 0.0;
  double b = 0.0;

  double operator[](int channel) const { return channel == 0 ? r : channel == 1 ? g : b; }
  double& operator[](int channel) { return channel == 0 ? r : channel == 1 ? g : b; }
  friend Rgb operator+(const Rgb& a, const Rgb& c) { return {a.r + c.r, a.g + c.g, a.b + c.b}; }
  friend Rgb operator*(double s, const Rgb& a) { return {s * a.r, s * a.g, s * a.b}; }
  Rgb& operator+=(const Rgb& a) { r += a.r; g += a.g; b += a.b; return *this; }

  std::string to_string() const;  // "RGB(0.18, 0.18, 0.18)"
  friend std::ostream& operator<<(std::ostream& os, const Rgb& v) { return os << v.to_string(); }
};

// A row-major 3x3 matrix acting on column vectors.
struct Matrix3 {
  std::array<std::array<double, 3>, 3> m{};

  static Matrix3 identity();
  std::array<double, 3> operator*(const std::array<double, 3>& v) const;
  Matrix3 operator*(const Matrix3& o) const;
  double determinant() const;
  // Throws ComputationError when the matrix is singular (|det| not > 1e-300).
  Matrix3 inverse() const;

  std::string to_string() const;  // "[[a, b, c], [d, e, f], [g, h, i]]"
  friend std::ostream& operator<<(std::ostream& os, const Matrix3& a) { return os << a.to_string(); }
};

// XYZ (Y of the white = 1) -> linear sRGB, IEC 61966-2-1:1999 eq. 5.2 (D65 white, 4 decimals).
inline constexpr Matrix3 kRec709FromXyz{{{
    {3.2406, -1.5372, -0.4986},
    {-0.9689, 1.8758, 0.0415},
    {0.0557, -0.2040, 1.0570},
}}};

// Linear Rec.709 from XYZ by kRec709FromXyz.
Rgb rec709_from_xyz(const Xyz& xyz);

}  // namespace lensmith
