// Term pools: sizes are the binomial counts, and the symmetry filter keeps exactly the monomials
// whose values transform as the output does under the mirrors x -> -x and y -> -y of a
// rotationally symmetric lens (Hullin et al. 2012 sec. 4.1; Schrade et al. 2016 sec. 4).
#include "lensmith/polyfit/term_pool.h"

#include <catch2/catch.hpp>
#include <algorithm>
#include <random>

using namespace lensmith;

namespace {
long long binomial(int n, int k) {
  long long r = 1;
  for (int i = 1; i <= k; ++i) r = r * (n - k + i) / i;
  return r;
}

PolyPoint mirror_x(PolyPoint v) {
  v[0] = -v[0];
  v[2] = -v[2];
  return v;
}
PolyPoint mirror_y(PolyPoint v) {
  v[1] = -v[1];
  v[3] = -v[3];
  return v;
}
}  // namespace

TEST_CASE("term pool: all monomials up to degree N number C(N+5, 5), distinct, in graded order", "[polyfit]") {
  for (int n = 0; n <= kMaxPolyDegree; ++n) {
    const auto pool = all_monomials(n);
    INFO("degree " << n);
    CHECK(static_cast<long long>(pool.size()) == binomial(n + 5, 5));
    auto sorted = pool;
    std::sort(sorted.begin(), sorted.end());
    CHECK(std::adjacent_find(sorted.begin(), sorted.end()) == sorted.end());
    CHECK(std::is_sorted(pool.begin(), pool.end(),
                         [](const Monomial& a, const Monomial& b) { return a.total_degree() < b.total_degree(); }));
    CHECK(pool.back().total_degree() == n);
  }
  CHECK_THROWS_AS(all_monomials(12), OptionsError);
  CHECK_THROWS_AS(all_monomials(-1), OptionsError);
}

TEST_CASE("term pool: symmetric pools of small degree have the hand-counted sizes", "[polyfit]") {
  // Odd in x: (x, dx) exponents sum a odd, (y, dy) sum b even, lambda any; a pair with sum s comes
  // in s + 1 ways. Degree 1: x, dx. Degree 2 adds x*lambda, dx*lambda. Degree 3 adds 2 * 1 (a=1,
  // lambda^2) + 2 * 3 (a=1, b=2) + 4 (a=3) = 12.
  CHECK(symmetric_monomials(1, OutputParity::kOddInX).size() == 2);
  CHECK(symmetric_monomials(2, OutputParity::kOddInX).size() == 4);
  CHECK(symmetric_monomials(3, OutputParity::kOddInX).size() == 16);
  CHECK(symmetric_monomials(3, OutputParity::kOddInY).size() == 16);
  // Even: 1, lambda at degree 1; degree 2 adds lambda^2 and the 3 + 3 squares/products in each pair.
  CHECK(symmetric_monomials(1, OutputParity::kEven).size() == 2);
  CHECK(symmetric_monomials(2, OutputParity::kEven).size() == 9);
  const auto odd_x_1 = symmetric_monomials(1, OutputParity::kOddInX);
  CHECK(odd_x_1[0].to_string() == "x");
  CHECK(odd_x_1[1].to_string() == "dx");
}

TEST_CASE("term pool: a monomial is allowed exactly when it transforms like the output under both mirrors", "[polyfit]") {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> coordinate(0.2, 1.3);  // away from 0 so no sign is hidden
  PolyPoint v{};
  for (double& x : v) x = coordinate(rng);
  for (const Monomial& m : all_monomials(7)) {
    const SparsePolynomial p({m}, {1.0});
    const double value = p.evaluate(v);
    const bool flips_x = p.evaluate(mirror_x(v)) == -value;
    const bool flips_y = p.evaluate(mirror_y(v)) == -value;
    INFO("monomial " << m);
    CHECK(allowed_by_symmetry(m, OutputParity::kOddInX) == (flips_x && !flips_y));
    CHECK(allowed_by_symmetry(m, OutputParity::kOddInY) == (!flips_x && flips_y));
    CHECK(allowed_by_symmetry(m, OutputParity::kEven) == (!flips_x && !flips_y));
  }
}

TEST_CASE("term pool: the odd pools hold only odd total degree in x, y, dx, dy and any lambda power", "[polyfit]") {
  // Rotation by pi is the product of both mirrors, so x_out and y_out are odd under -(x, y, dx, dy).
  bool lambda_seen = false;
  for (const auto parity : {OutputParity::kOddInX, OutputParity::kOddInY}) {
    for (const Monomial& m : symmetric_monomials(9, parity)) {
      INFO(parity << ": " << m);
      CHECK(m.geometric_degree() % 2 == 1);
      lambda_seen = lambda_seen || m.exponents[4] == 8;
    }
  }
  CHECK(lambda_seen);
  for (const Monomial& m : symmetric_monomials(9, OutputParity::kEven)) CHECK(m.geometric_degree() % 2 == 0);
}
