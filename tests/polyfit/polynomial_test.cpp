// SparsePolynomial: the power-table evaluation and its gradient agree with a naive std::pow sum,
// and the value type validates and prints itself.
#include "lensmith/polyfit/polynomial.h"

#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "lensmith/polyfit/term_pool.h"

using Catch::Matchers::Contains;
using Catch::Matchers::WithinAbs;
using namespace lensmith;

namespace {
// Both sides round each of ~60 products of <= 11 factors; compared against the sum of |terms|.
constexpr double kRounding = 1e-14;

double naive_term(const Monomial& m, const PolyPoint& v) {
  double t = 1.0;
  for (int k = 0; k < kPolyVariables; ++k) t *= std::pow(v[k], m.exponents[k]);
  return t;
}

// A random polynomial with `count` distinct terms of total degree <= 11 and coefficients in [-2, 2].
SparsePolynomial random_polynomial(std::mt19937_64& rng, std::size_t count) {
  std::vector<Monomial> pool = all_monomials(kMaxPolyDegree);
  std::shuffle(pool.begin(), pool.end(), rng);
  pool.resize(count);
  std::uniform_real_distribution<double> coefficient(-2.0, 2.0);
  std::vector<double> c(count);
  for (double& v : c) v = coefficient(rng);
  return SparsePolynomial(pool, c);
}
}  // namespace

TEST_CASE("sparse polynomial: evaluation equals the naive sum of c times pow products", "[polyfit]") {
  std::mt19937_64 rng(7);
  const SparsePolynomial p = random_polynomial(rng, 60);
  std::uniform_real_distribution<double> coordinate(-1.5, 1.5);
  for (int trial = 0; trial < 200; ++trial) {
    PolyPoint v{};
    for (double& x : v) x = coordinate(rng);
    if (trial == 0) v[2] = 0.0;  // a zero coordinate: 0^0 = 1 in both
    double naive = 0.0, scale = 0.0;
    for (std::size_t i = 0; i < p.size(); ++i) {
      const double t = p.coefficients()[i] * naive_term(p.terms()[i], v);
      naive += t;
      scale += std::abs(t);
    }
    INFO("trial " << trial << " polynomial " << p);
    CHECK_THAT(p.evaluate(v), WithinAbs(naive, kRounding * scale));
  }
}

TEST_CASE("sparse polynomial: gradient equals the naive derivative e c v^(e-1) times the other factors", "[polyfit]") {
  std::mt19937_64 rng(11);
  const SparsePolynomial p = random_polynomial(rng, 60);
  std::uniform_real_distribution<double> coordinate(-1.5, 1.5);
  for (int trial = 0; trial < 100; ++trial) {
    PolyPoint v{};
    for (double& x : v) x = coordinate(rng);
    if (trial == 0) v = {0.0, 0.5, 0.0, -0.3, 0.0};  // zeros must not poison the other partials
    std::array<double, kPolyVariables> grad{};
    const double value = p.evaluate_with_gradient(v, grad);
    CHECK(value == p.evaluate(v));
    std::array<double, kPolyVariables> grad_only{};
    p.gradient(v, grad_only);
    CHECK(grad_only == grad);
    for (int k = 0; k < kPolyVariables; ++k) {
      double naive = 0.0, scale = 0.0;
      for (std::size_t i = 0; i < p.size(); ++i) {
        const Monomial& m = p.terms()[i];
        if (m.exponents[k] == 0) continue;
        double t = p.coefficients()[i] * m.exponents[k] * std::pow(v[k], m.exponents[k] - 1);
        for (int j = 0; j < kPolyVariables; ++j) {
          if (j != k) t *= std::pow(v[j], m.exponents[j]);
        }
        naive += t;
        scale += std::abs(t);
      }
      INFO("trial " << trial << " variable " << k);
      CHECK_THAT(grad[k], WithinAbs(naive, 11 * kRounding * scale));
    }
  }
}

TEST_CASE("sparse polynomial: batch evaluation equals one-by-one evaluation", "[polyfit]") {
  std::mt19937_64 rng(3);
  const SparsePolynomial p = random_polynomial(rng, 20);
  std::vector<PolyPoint> points(17, PolyPoint{0.1, -0.2, 0.3, 0.4, 0.55});
  for (std::size_t i = 0; i < points.size(); ++i) points[i][0] = 0.05 * static_cast<double>(i);
  std::vector<double> out(points.size());
  p.evaluate(points, out);
  for (std::size_t i = 0; i < points.size(); ++i) CHECK(out[i] == p.evaluate(points[i]));
  std::vector<double> too_short(3);
  CHECK_THROWS_AS(p.evaluate(points, too_short), FitError);
}

TEST_CASE("sparse polynomial: prints its terms and coefficients", "[polyfit]") {
  const SparsePolynomial p({Monomial{{2, 0, 0, 1, 0}}, Monomial{{0, 0, 0, 0, 1}}, Monomial{}}, {1.5, -0.25, 2.0});
  CHECK(p.to_string() == "+1.5*x^2*dy -0.25*lambda +2");
  CHECK(SparsePolynomial().to_string() == "0");
  CHECK(SparsePolynomial().evaluate({1, 2, 3, 4, 5}) == 0.0);
  CHECK(Monomial{{0, 1, 1, 0, 3}}.to_string() == "y*dx*lambda^3");
  CHECK(p.degree() == 3);
}

TEST_CASE("sparse polynomial: rejects mismatched sizes and degrees above 11", "[polyfit]") {
  CHECK_THROWS_WITH(SparsePolynomial({Monomial{}}, {}), Contains("1 terms but 0 coefficients"));
  CHECK_THROWS_WITH(SparsePolynomial({Monomial{{6, 6, 0, 0, 0}}}, {1.0}),
                    Contains("x^6*y^6 has total degree 12: must be <= 11"));
}
