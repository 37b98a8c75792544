// Linear Rec.709 values and the small 3x3 algebra the spectral calibration needs.
#include "lensmith/color/rgb.h"

#include <cmath>
#include <sstream>

#include "lensmith/core/errors.h"

namespace lensmith {

Matrix3 Matrix3::identity() { return Matrix3{{{{1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 1.0}}}}; }

std::array<double, 3> Matrix3::operator*(const std::array<double, 3>& v) const {
  std::array<double, 3> out{};
  for (int i = 0; i < 3; ++i) out[i] = m[i][0] * v[0] + m[i][1] * v[1] + m[i][2] * v[2];
  return out;
}

Matrix3 Matrix3::operator*(const Matrix3& o) const {
  Matrix3 out;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) out.m[i][j] = m[i][0] * o.m[0][j] + m[i][1] * o.m[1][j] + m[i][2] * o.m[2][j];
  return out;
}

double Matrix3::determinant() const {
  return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
         m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
}

Matrix3 Matrix3::inverse() const {
  const double det = determinant();
  if (!(std::abs(det) > 1e-300)) {
    throw ComputationError("Matrix3::inverse of " + to_string() + ": singular (determinant " + std::to_string(det) + ")");
  }
  // Adjugate over determinant; the cofactor of (j, i) goes to (i, j).
  Matrix3 out;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      const int r0 = (j + 1) % 3, r1 = (j + 2) % 3, c0 = (i + 1) % 3, c1 = (i + 2) % 3;
      out.m[i][j] = (m[r0][c0] * m[r1][c1] - m[r0][c1] * m[r1][c0]) / det;
    }
  }
  return out;
}

std::string Matrix3::to_string() const {
  std::ostringstream os;
  os.precision(10);
  os << "[";
  for (int i = 0; i < 3; ++i) {
    os << (i ? ", [" : "[") << m[i][0] << ", " << m[i][1] << ", " << m[i][2] << "]";
  }
  os << "]";
  return os.str();
}

std::string Rgb::to_string() const {
  std::ostringstream os;
  os.precision(10);
  os << "RGB(" << r << ", " << g << ", " << b << ")";
  return os.str();
}

Rgb rec709_from_xyz(const Xyz& xyz) {
  const auto v = kRec709FromXyz * std::array<double, 3>{xyz.x, xyz.y, xyz.z};
  return {v[0], v[1], v[2]};
}

}  // namespace lensmith
