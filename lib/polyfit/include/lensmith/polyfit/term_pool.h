// Candidate monomials for a fit: every monomial up to a total degree, or only those a rotationally
// symmetric lens allows for a given output (Hullin, Hanika & Heidrich 2012, sec. 4.1; Schrade,
// Hanika & Dachsbacher 2016, sec. 4). Pools are in graded order: by total degree, then by exponents.
#pragma once

#include <ostream>
#include <vector>

#include "lensmith/polyfit/polynomial.h"

namespace lensmith {

// How an output of a rotationally symmetric lens transforms under the mirrors of the system.
//
// Why: a lens that is rotationally symmetric about z is also symmetric under the reflections
// x -> -x and y -> -y (every plane containing the axis is a mirror plane). The reflection
// x -> -x maps the input ray (x, y, dx, dy, lambda) to (-x, y, -dx, dy, lambda), and so must map
// the output ray in the same way: x_out and dx_out change sign, y_out, dy_out and any scalar
// (transmittance) do not. A monomial x^a y^b dx^c dy^d lambda^e changes by (-1)^(a+c) under that
// reflection and by (-1)^(b+d) under y -> -y, so
//   kOddInX   (x_out, dx_out):             a + c odd,  b + d even;
//   kOddInY   (y_out, dy_out):             a + c even, b + d odd;
//   kEven     (transmittance, |r|^2 ...):  a + c even, b + d even.
// The rotation by pi, -(x, y, dx, dy), is the product of both reflections, so the two odd classes
// contain only monomials of odd total degree in (x, y, dx, dy), and kEven only even ones.
// Wavelength is a scalar that no symmetry of the lens changes: its exponent is unrestricted.
// (Full rotational symmetry constrains the coefficients further, tying e.g. x^3 to x*y^2; these
// parity rules only remove terms whose coefficient must be zero.)
enum class OutputParity { kOddInX, kOddInY, kEven };

std::ostream& operator<<(std::ostream& os, OutputParity parity);

// All C(max_degree + 5, 5) monomials of total degree 0..max_degree.
// Throws OptionsError unless 0 <= max_degree <= kMaxPolyDegree.
std::vector<Monomial> all_monomials(int max_degree);

// True when the monomial may appear in an output of the given parity (rules above).
bool allowed_by_symmetry(const Monomial& m, OutputParity parity);

// all_monomials(max_degree) filtered by allowed_by_symmetry.
std::vector<Monomial> symmetric_monomials(int max_degree, OutputParity parity);

}  // namespace lensmith
