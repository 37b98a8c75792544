// Matrices between RGB spaces from their primaries (SMPTE RP 177-1993) and Bradford adaptation.
#include "lensmith/color/rgb_primaries.h"

#include <array>
#include <sstream>

namespace lensmith {

namespace {

// XYZ of a chromaticity with Y = 1.
std::array<double, 3> xyz_of(const Chromaticity& c) { return {c.x / c.y, 1.0, (1.0 - c.x - c.y) / c.y}; }

// The Bradford cone-response matrix (Lam 1985; Lindbloom's "Chromatic Adaptation" page).
constexpr Matrix3 kBradford{{{
    {0.8951, 0.2664, -0.1614},
    {-0.7502, 1.7135, 0.0367},
    {0.0389, -0.0685, 1.0296},
}}};

}  // namespace

std::string RgbPrimaries::to_string() const {
  std::ostringstream os;
  os.precision(6);
  os << name << " primaries (R " << red.x << ", " << red.y << "; G " << green.x << ", " << green.y << "; B " << blue.x << ", " << blue.y
     << "; white " << white.x << ", " << white.y << ")";
  return os.str();
}

Matrix3 xyz_from_rgb(const RgbPrimaries& p) {
  // Columns: the primaries' XYZ at Y = 1, each scaled by S so that the columns sum to the white.
  const std::array<double, 3> r = xyz_of(p.red), g = xyz_of(p.green), b = xyz_of(p.blue);
  const Matrix3 unscaled{{{{r[0], g[0], b[0]}, {r[1], g[1], b[1]}, {r[2], g[2], b[2]}}}};
  const std::array<double, 3> s = unscaled.inverse() * xyz_of(p.white);
  Matrix3 out;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) out.m[i][j] = unscaled.m[i][j] * s[j];
  return out;
}

Matrix3 bradford_adaptation(const Chromaticity& from, const Chromaticity& to) {
  if (from.x == to.x && from.y == to.y) return Matrix3::identity();
  const std::array<double, 3> source = kBradford * xyz_of(from), target = kBradford * xyz_of(to);
  Matrix3 scale;
  for (int i = 0; i < 3; ++i) scale.m[i][i] = target[i] / source[i];
  return kBradford.inverse() * scale * kBradford;
}

Matrix3 rgb_conversion(const RgbPrimaries& from, const RgbPrimaries& to) {
  return xyz_from_rgb(to).inverse() * bradford_adaptation(from.white, to.white) * xyz_from_rgb(from);
}

}  // namespace lensmith
