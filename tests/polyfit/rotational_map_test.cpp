// Rotation-invariant maps: a map that is exactly of the invariant form is recovered to rounding, the
// Jacobian agrees with finite differences, the blocked batch path with the per-point one, and the
// form itself turns with the ray (rotating the input rotates a vector output, leaves a scalar one).
#include "lensmith/polyfit/rotational_map.h"

#include <catch2/catch.hpp>
#include <cmath>
#include <random>

using Catch::Matchers::WithinAbs;
using namespace lensmith;

namespace {
// Exact data and QR: coefficients come back to ~1e-13; 1e-9 leaves margin.
constexpr double kRecovered = 1e-9;

std::vector<PolyPoint> random_points(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> c(-1.0, 1.0);
  std::vector<PolyPoint> points(n);
  for (auto& p : points) {
    for (double& x : p) x = c(rng);
  }
  return points;
}

InvariantTerm term(int a, int b, int c, int e, RayFactor f) {
  InvariantTerm t;
  t.exponents = {static_cast<std::uint8_t>(a), static_cast<std::uint8_t>(b), static_cast<std::uint8_t>(c),
                 static_cast<std::uint8_t>(e)};
  t.factor = f;
  return t;
}

// Two vector outputs of degree <= 7 built from 6 terms.
RotationalMap known_map() {
  return RotationalMap({term(0, 0, 0, 0, RayFactor::kPosition), term(0, 0, 0, 1, RayFactor::kDirection),
                        term(1, 0, 0, 0, RayFactor::kPosition), term(0, 1, 1, 0, RayFactor::kDirection),
                        term(2, 0, 1, 0, RayFactor::kPosition), term(0, 0, 1, 2, RayFactor::kDirection)},
                       2, {1.5, -0.2, 0.3, 0.8, -0.7, 0.05, 0.25, -0.4, 0.11, 0.6, -0.09, 0.33});
}
}  // namespace

TEST_CASE("an exactly invariant map is recovered to rounding, terms and coefficients") {
  const RotationalMap truth = known_map();
  const auto inputs = random_points(3000, 7);
  std::vector<std::vector<std::array<double, 2>>> targets(2);
  for (const auto& p : inputs) {
    std::array<double, 4> out;
    truth.evaluate(p, out);
    targets[0].push_back({out[0], out[1]});
    targets[1].push_back({out[2], out[3]});
  }
  FitOptions options;
  options.max_degree = 7;
  options.max_terms = 6;
  const RotationalFitResult fit = fit_rotational_map(inputs, targets, vector_invariant_terms(7), options);
  REQUIRE(fit.map.size() == 6);
  for (std::size_t t = 0; t < truth.size(); ++t) {
    const auto it = std::find(fit.map.terms().begin(), fit.map.terms().end(), truth.terms()[t]);
    REQUIRE(it != fit.map.terms().end());
    const std::size_t j = static_cast<std::size_t>(it - fit.map.terms().begin());
    for (int k = 0; k < 2; ++k) CHECK_THAT(fit.map.coefficient(j, k), WithinAbs(truth.coefficient(t, k), kRecovered));
  }
  CHECK(fit.train_rms[0] < 1e-12);
}

TEST_CASE("rotating the input ray rotates a vector output and leaves a scalar output alone") {
  const RotationalMap vector_map = known_map();
  const RotationalMap scalar_map({term(0, 0, 0, 0, RayFactor::kOne), term(1, 1, 0, 1, RayFactor::kOne)}, 1, {0.9, -0.3});
  const double angle = 0.7, c = std::cos(angle), s = std::sin(angle);
  for (const auto& p : random_points(50, 3)) {
    const PolyPoint r{c * p[0] - s * p[1], s * p[0] + c * p[1], c * p[2] - s * p[3], s * p[2] + c * p[3], p[4]};
    std::array<double, 4> a, b;
    vector_map.evaluate(p, a);
    vector_map.evaluate(r, b);
    CHECK_THAT(b[0], WithinAbs(c * a[0] - s * a[1], 1e-12));
    CHECK_THAT(b[1], WithinAbs(s * a[0] + c * a[1], 1e-12));
    std::array<double, 1> u, v;
    scalar_map.evaluate(p, u);
    scalar_map.evaluate(r, v);
    CHECK_THAT(v[0], WithinAbs(u[0], 1e-12));
  }
}

TEST_CASE("the Jacobian of a vector output agrees with central differences") {
  const RotationalMap map = known_map();
  for (const auto& p : random_points(20, 11)) {
    std::array<double, 2> value;
    std::array<double, 8> jacobian;
    map.evaluate_with_jacobian(p, 1, value, jacobian);
    const auto direct = map.evaluate_output(p, 1);
    CHECK_THAT(value[0], WithinAbs(direct[0], 1e-14));
    for (int i = 0; i < 4; ++i) {
      const double h = 1e-6;
      PolyPoint plus = p, minus = p;
      plus[static_cast<std::size_t>(i)] += h;
      minus[static_cast<std::size_t>(i)] -= h;
      const auto a = map.evaluate_output(plus, 1), b = map.evaluate_output(minus, 1);
      CHECK_THAT(jacobian[static_cast<std::size_t>(i)], WithinAbs((a[0] - b[0]) / (2 * h), 1e-7));
      CHECK_THAT(jacobian[static_cast<std::size_t>(4 + i)], WithinAbs((a[1] - b[1]) / (2 * h), 1e-7));
    }
  }
}

TEST_CASE("the batch path gives what the per-point path gives, for any count") {
  const RotationalMap map = known_map();
  const auto points = random_points(77, 5);  // not a multiple of the block
  std::array<std::vector<double>, kPolyVariables> in;
  for (const auto& p : points) {
    for (int i = 0; i < kPolyVariables; ++i) in[static_cast<std::size_t>(i)].push_back(p[static_cast<std::size_t>(i)]);
  }
  std::array<std::vector<double>, 4> out;
  for (auto& o : out) o.resize(points.size());
  const std::array<double*, 4> ptr{out[0].data(), out[1].data(), out[2].data(), out[3].data()};
  map.evaluate_batch({in[0].data(), in[1].data(), in[2].data(), in[3].data(), in[4].data()}, ptr, points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    std::array<double, 4> one;
    map.evaluate(points[i], one);
    for (std::size_t k = 0; k < 4; ++k) CHECK_THAT(out[k][i], WithinAbs(one[k], 1e-13));
  }
}

TEST_CASE("invariant pools hold each term once, within the degree, graded") {
  const auto pool = vector_invariant_terms(7);
  for (std::size_t i = 0; i < pool.size(); ++i) {
    CHECK(pool[i].total_degree() <= 7);
    if (i > 0) CHECK(pool[i - 1].total_degree() <= pool[i].total_degree());
    for (std::size_t j = 0; j < i; ++j) CHECK_FALSE(pool[i] == pool[j]);
  }
  // Degree 7: invariant monomials of weight s = a + b + c with 2 s + 1 + e <= 7, times p and d:
  // s = 0: e 0..6 (7); s = 1: 3 x 5; s = 2: 6 x 3; s = 3: 10 x 1; 50 monomials, 100 terms.
  CHECK(pool.size() == 100);
  CHECK(scalar_invariant_terms(2).size() == 3 + 3);  // 1, lambda, lambda^2, u, v, w
}

TEST_CASE("a map mixing vector and scalar terms is refused") {
  CHECK_THROWS_AS(RotationalMap({term(0, 0, 0, 0, RayFactor::kPosition), term(0, 0, 0, 0, RayFactor::kOne)}, 1, {1.0, 2.0}),
                  FitError);
  CHECK_THROWS_AS(RotationalMap({term(0, 0, 0, 0, RayFactor::kPosition)}, 1, {1.0, 2.0}), FitError);
}
