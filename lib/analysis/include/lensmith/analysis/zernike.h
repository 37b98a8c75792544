// Zernike circle polynomials over the unit pupil, in the two orderings optical engineers read:
//
// - Fringe (University of Arizona; OpticStudio's "Zernike Fringe Coefficients", CODE V's ZFR): Z1..Z37,
//   not normalised, grouped by (n + |m|) / 2 with |m| falling inside a group, cos before sin:
//   Z4 = 2 rho^2 - 1 (defocus), Z9 = 6 rho^4 - 6 rho^2 + 1 (primary spherical).
// - Standard (Noll, J. Opt. Soc. Am. 66, 207 (1976); OpticStudio's "Zernike Standard Coefficients"):
//   j = 1, 2, ..., orthonormal over the unit disc (each term's RMS over the pupil is 1, so the RMS of a
//   wavefront without piston is the root sum of squares of its other coefficients); an even j carries
//   cos(m theta), an odd j sin(m theta): Z4 = sqrt(3) (2 rho^2 - 1), Z11 = sqrt(5) (6 rho^4 - 6 rho^2 + 1).
//
// theta is measured from the pupil's +x axis towards +y (normalised pupil coordinates px = rho cos theta,
// py = rho sin theta).
#pragma once

#include <span>
#include <string_view>
#include <vector>

namespace lensmith {

enum class ZernikeOrdering { Fringe, Standard };
std::string_view to_string(ZernikeOrdering ordering);         // "fringe", "standard"
ZernikeOrdering parse_zernike_ordering(std::string_view text);  // throws OptionsError naming the choices

// A term's radial degree n and azimuthal frequency m (m > 0: cos(m theta), m < 0: sin(|m| theta)).
struct ZernikeTerm {
  int n = 0;
  int m = 0;
  bool operator==(const ZernikeTerm&) const = default;
};

// The term of 1-based index j in an ordering (Fringe: 1 to 37; Standard: 1 to 231, n <= 20). Throws
// OptionsError outside that range.
ZernikeTerm zernike_term(ZernikeOrdering ordering, int j);
// The most terms an ordering defines here.
int max_zernike_terms(ZernikeOrdering ordering);

// The value of term j at (rho, theta), rho in [0, 1].
double zernike_value(ZernikeOrdering ordering, int j, double rho, double theta);

// The least-squares coefficients of terms 1..terms (the ordering's) for samples value_k at pupil points
// (px_k, py_k) inside the unit circle. Throws ComputationError when there are fewer samples than terms or
// the samples do not determine them (a pupil sampled too coarsely).
std::vector<double> fit_zernike(ZernikeOrdering ordering, int terms, std::span<const double> px, std::span<const double> py,
                                std::span<const double> values);

}  // namespace lensmith
