// Zernike circle polynomials: radial polynomials by their closed sum (Born & Wolf, Principles of Optics,
// sec. 9.2.1, eq. 9.2(6)), the two index orderings, and a least-squares fit (Eigen's column-pivoting QR,
// which also says when the samples do not determine the terms).
#include "lensmith/analysis/zernike.h"

#include <cmath>
#include <string>

#include <Eigen/Dense>

#include "lensmith/core/errors.h"

namespace lensmith {

namespace {

constexpr int kFringeTerms = 37;
constexpr int kMaxStandardDegree = 20;
constexpr int kStandardTerms = (kMaxStandardDegree + 1) * (kMaxStandardDegree + 2) / 2;  // 231

double factorial(int k) {
  double f = 1.0;
  for (int i = 2; i <= k; ++i) f *= i;
  return f;
}

// R_n^m(rho) = sum_s (-1)^s (n - s)! / (s! ((n + m)/2 - s)! ((n - m)/2 - s)!) rho^(n - 2s), m >= 0.
double radial(int n, int m, double rho) {
  double sum = 0.0;
  for (int s = 0; s <= (n - m) / 2; ++s) {
    const double c = factorial(n - s) / (factorial(s) * factorial((n + m) / 2 - s) * factorial((n - m) / 2 - s));
    sum += (s % 2 == 0 ? c : -c) * std::pow(rho, n - 2 * s);
  }
  return sum;
}

ZernikeTerm fringe_term(int j) {
  // Group k = (n + |m|) / 2 holds 2k + 1 terms: |m| = k, k - 1, ..., 1 (cos, sin), then m = 0; n = 2k - |m|.
  // The set stops after group 5 (Z36, n = 10) with one more term, the next spherical: Z37 (12, 0).
  if (j == kFringeTerms) return {12, 0};
  int first = 1;
  for (int k = 0;; ++k) {
    const int count = 2 * k + 1;
    if (j < first + count) {
      const int at = j - first;  // 0-based inside the group
      if (at == count - 1) return {2 * k, 0};
      const int abs_m = k - at / 2;
      return {2 * k - abs_m, at % 2 == 0 ? abs_m : -abs_m};
    }
    first += count;
  }
}

ZernikeTerm standard_term(int j) {
  // Noll: degree n holds j = n (n + 1) / 2 + 1 .. (n + 1)(n + 2) / 2, |m| rising (n - |m| even); a term with
  // m != 0 takes two indices, the even one cos and the odd one sin.
  int n = 0;
  while ((n + 1) * (n + 2) / 2 < j) ++n;
  int index = n * (n + 1) / 2 + 1;
  for (int abs_m = n % 2; abs_m <= n; abs_m += 2) {
    if (abs_m == 0) {
      if (index == j) return {n, 0};
      ++index;
      continue;
    }
    for (int k = 0; k < 2; ++k, ++index) {
      if (index == j) return {n, j % 2 == 0 ? abs_m : -abs_m};
    }
  }
  return {n, 0};  // unreachable for j in range
}

}  // namespace

std::string_view to_string(ZernikeOrdering ordering) { return ordering == ZernikeOrdering::Fringe ? "fringe" : "standard"; }

ZernikeOrdering parse_zernike_ordering(std::string_view text) {
  if (text == "fringe") return ZernikeOrdering::Fringe;
  if (text == "standard" || text == "noll") return ZernikeOrdering::Standard;
  throw OptionsError("unknown Zernike ordering '" + std::string(text) + "': expected fringe or standard (Noll)");
}

int max_zernike_terms(ZernikeOrdering ordering) { return ordering == ZernikeOrdering::Fringe ? kFringeTerms : kStandardTerms; }

ZernikeTerm zernike_term(ZernikeOrdering ordering, int j) {
  if (j < 1 || j > max_zernike_terms(ordering)) {
    throw OptionsError("Zernike " + std::string(to_string(ordering)) + " term " + std::to_string(j) + ": expected 1 to " +
                       std::to_string(max_zernike_terms(ordering)));
  }
  return ordering == ZernikeOrdering::Fringe ? fringe_term(j) : standard_term(j);
}

double zernike_value(ZernikeOrdering ordering, int j, double rho, double theta) {
  const ZernikeTerm t = zernike_term(ordering, j);
  const int abs_m = std::abs(t.m);
  double v = radial(t.n, abs_m, rho);
  if (t.m > 0) v *= std::cos(abs_m * theta);
  if (t.m < 0) v *= std::sin(abs_m * theta);
  if (ordering == ZernikeOrdering::Standard) v *= std::sqrt((t.m == 0 ? 1.0 : 2.0) * (t.n + 1));
  return v;
}

std::vector<double> fit_zernike(ZernikeOrdering ordering, int terms, std::span<const double> px, std::span<const double> py,
                                std::span<const double> values) {
  zernike_term(ordering, terms);  // checks the count
  const auto samples = static_cast<Eigen::Index>(values.size());
  if (px.size() != values.size() || py.size() != values.size()) {
    throw OptionsError("fit_zernike: " + std::to_string(px.size()) + " x, " + std::to_string(py.size()) + " y and " +
                       std::to_string(values.size()) + " values");
  }
  if (samples < terms) {
    throw ComputationError("a Zernike fit of " + std::to_string(terms) + " terms needs at least as many pupil samples; there are " +
                           std::to_string(samples) + " (sample the pupil more finely)");
  }
  Eigen::MatrixXd a(samples, terms);
  Eigen::VectorXd b(samples);
  for (Eigen::Index k = 0; k < samples; ++k) {
    const auto i = static_cast<std::size_t>(k);
    const double rho = std::hypot(px[i], py[i]), theta = std::atan2(py[i], px[i]);
    for (int j = 1; j <= terms; ++j) a(k, j - 1) = zernike_value(ordering, j, rho, theta);
    b(k) = values[i];
  }
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(a);
  if (qr.rank() < terms) {
    throw ComputationError("the pupil samples determine only " + std::to_string(qr.rank()) + " of " + std::to_string(terms) +
                           " Zernike terms (sample the pupil more finely, or fit fewer terms)");
  }
  const Eigen::VectorXd c = qr.solve(b);
  return std::vector<double>(c.data(), c.data() + terms);
}

}  // namespace lensmith
