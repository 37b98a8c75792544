// fit_polynomial: an exactly polynomial system is recovered to rounding (terms and coefficients),
// the error of a smooth non-polynomial function falls with the degree, and options validate.
#include "lensmith/polyfit/polynomial_fit.h"

#include <catch2/catch.hpp>
#include <algorithm>
#include <cmath>
#include <random>

#include "lensmith/polyfit/term_pool.h"

using Catch::Matchers::Contains;
using Catch::Matchers::WithinAbs;
using namespace lensmith;

namespace {
// Exact data and a well-conditioned QR: coefficients come back to ~1e-14; 1e-9 leaves ample margin
// for the pool's worst-conditioned columns.
constexpr double kRecovered = 1e-9;

std::vector<PolyPoint> random_points(std::mt19937_64& rng, std::size_t n) {
  std::uniform_real_distribution<double> coordinate(-1.0, 1.0);
  std::vector<PolyPoint> points(n);
  for (auto& p : points) {
    for (double& x : p) x = coordinate(rng);
  }
  return points;
}

std::vector<double> evaluate_all(const SparsePolynomial& p, const std::vector<PolyPoint>& points) {
  std::vector<double> out(points.size());
  p.evaluate(points, out);
  return out;
}

// Degree 5, 6 terms, every variable used.
SparsePolynomial known_polynomial() {
  return SparsePolynomial({Monomial{{1, 0, 0, 0, 1}}, Monomial{{0, 2, 1, 0, 0}}, Monomial{{2, 1, 0, 1, 1}},
                           Monomial{{0, 0, 0, 2, 0}}, Monomial{{0, 0, 0, 0, 3}}, Monomial{{1, 0, 3, 0, 1}}},
                          {1.25, -0.8, 0.45, 2.1, -0.6, 0.9});
}

void check_recovers(const SparsePolynomial& truth, const FitResult& fit) {
  INFO(fit);
  REQUIRE(fit.polynomial.size() == truth.size());
  for (std::size_t i = 0; i < truth.size(); ++i) {
    const auto& terms = fit.polynomial.terms();
    const auto at = std::find(terms.begin(), terms.end(), truth.terms()[i]);
    INFO("term " << truth.terms()[i]);
    REQUIRE(at != terms.end());
    const auto j = static_cast<std::size_t>(at - terms.begin());
    CHECK_THAT(fit.polynomial.coefficients()[j], WithinAbs(truth.coefficients()[i], kRecovered));
  }
  CHECK(fit.train_max_abs < kRecovered);
}

// Smooth, not a polynomial, depends on all five variables.
double smooth_function(const PolyPoint& v) {
  return std::sin(1.3 * v[0] + 0.7 * v[3]) * std::exp(0.4 * v[1] * v[4]) + 0.3 * std::cos(2.0 * v[2]);
}
}  // namespace

TEST_CASE("polynomial fit: a known 6-term degree-5 polynomial is recovered from the full degree-5 pool", "[polyfit]") {
  std::mt19937_64 rng(42);
  const auto inputs = random_points(rng, 2000);
  const SparsePolynomial truth = known_polynomial();
  const auto targets = evaluate_all(truth, inputs);
  FitOptions options;
  options.max_degree = 5;
  SECTION("with a budget of exactly 6 terms matching pursuit picks exactly the true terms") {
    options.max_terms = 6;
    check_recovers(truth, fit_polynomial(inputs, targets, all_monomials(5), options));
  }
  SECTION("with a budget of 40 terms selection stops once the data are explained") {
    options.max_terms = 40;
    const FitResult fit = fit_polynomial(inputs, targets, all_monomials(5), options);
    check_recovers(truth, fit);
    CHECK(fit.selection_rms.size() == 6);
  }
}

TEST_CASE("polynomial fit: a dense fit on the true terms converges in a few Levenberg-Marquardt iterations", "[polyfit]") {
  std::mt19937_64 rng(1);
  const auto inputs = random_points(rng, 500);
  const SparsePolynomial truth = known_polynomial();
  FitOptions options;
  options.max_terms = 6;
  const FitResult fit = fit_polynomial(inputs, evaluate_all(truth, inputs), truth.terms(), options);
  check_recovers(truth, fit);
  CHECK(fit.selection_rms.empty());
  CHECK(fit.solver_iterations <= 4);  // linear problem: one step, then convergence checks
}

TEST_CASE("polynomial fit: held-out error of a smooth function falls as the degree grows", "[polyfit]") {
  std::mt19937_64 rng(9);
  const auto train = random_points(rng, 3000);
  const auto test = random_points(rng, 1000);  // held out: overfitting would show here
  std::vector<double> train_targets, test_targets;
  for (const auto& p : train) train_targets.push_back(smooth_function(p));
  for (const auto& p : test) test_targets.push_back(smooth_function(p));
  double previous = INFINITY;
  double first = 0.0;
  for (int degree = 1; degree <= 5; ++degree) {
    FitOptions options;
    options.max_degree = degree;
    options.max_terms = 1000;  // dense: every term of the pool
    const FitResult fit = fit_polynomial(train, train_targets, all_monomials(degree), options);
    const auto predicted = evaluate_all(fit.polynomial, test);
    double sum2 = 0.0;
    for (std::size_t i = 0; i < test.size(); ++i) sum2 += (predicted[i] - test_targets[i]) * (predicted[i] - test_targets[i]);
    const double test_rms = std::sqrt(sum2 / static_cast<double>(test.size()));
    INFO("degree " << degree << " train RMS " << fit.train_rms << " held-out RMS " << test_rms);
    CHECK(test_rms < previous);
    if (degree == 1) first = test_rms;
    // Degree 5 leaves Taylor terms of order 6 of a function with O(1) derivatives on [-1, 1].
    if (degree == 5) CHECK(test_rms < 1e-2 * first);
    previous = test_rms;
  }
}

TEST_CASE("polynomial fit: matching pursuit's residual never grows as terms are added", "[polyfit]") {
  std::mt19937_64 rng(17);
  const auto inputs = random_points(rng, 1500);
  std::vector<double> targets;
  for (const auto& p : inputs) targets.push_back(smooth_function(p));
  FitOptions options;
  options.max_terms = 30;
  const FitResult fit = fit_polynomial(inputs, targets, all_monomials(5), options);
  INFO(fit);
  REQUIRE(fit.selection_rms.size() == 30);
  for (std::size_t i = 1; i < fit.selection_rms.size(); ++i) CHECK(fit.selection_rms[i] <= fit.selection_rms[i - 1]);
  // Ceres' solve of the chosen terms reaches the least-squares optimum that selection computed.
  CHECK_THAT(fit.train_rms, WithinAbs(fit.selection_rms.back(), 1e-12));
}

TEST_CASE("polynomial fit: a Huber loss ignores a few gross outliers that pull least squares away", "[polyfit]") {
  std::mt19937_64 rng(23);
  const auto inputs = random_points(rng, 1000);
  const SparsePolynomial truth = known_polynomial();
  auto targets = evaluate_all(truth, inputs);
  for (std::size_t i = 0; i < targets.size(); i += 25) targets[i] += 5.0;  // 4% outliers
  FitOptions options;
  options.max_terms = 6;
  const auto error = [&](const FitResult& fit) {
    double worst = 0.0;
    for (std::size_t i = 0; i < truth.size(); ++i) worst = std::max(worst, std::abs(fit.polynomial.coefficients()[i] - truth.coefficients()[i]));
    return worst;
  };
  const double plain = error(fit_polynomial(inputs, targets, truth.terms(), options));
  options.huber_scale = 0.01;
  const double robust = error(fit_polynomial(inputs, targets, truth.terms(), options));
  INFO("least squares coefficient error " << plain << ", Huber " << robust);
  CHECK(robust < 0.1 * plain);
}

TEST_CASE("polynomial fit: options and data are validated with the field and constraint named", "[polyfit]") {
  FitOptions options;
  options.max_degree = 0;
  CHECK_THROWS_WITH(options.validate(), "FitOptions::max_degree = 0: must be in 1..11");
  options.max_degree = 12;
  CHECK_THROWS_AS(options.validate(), OptionsError);
  options = {};
  options.max_terms = 0;
  CHECK_THROWS_WITH(options.validate(), "FitOptions::max_terms = 0: must be >= 1");
  options = {};
  options.huber_scale = -1.0;
  CHECK_THROWS_WITH(options.validate(), Contains("FitOptions::huber_scale") && Contains("must be finite and > 0"));
  options = {};
  const std::vector<PolyPoint> inputs{{0, 0, 0, 0, 0}, {1, 1, 1, 1, 1}};
  CHECK_THROWS_AS(fit_polynomial(inputs, {1.0}, all_monomials(2), options), FitError);
  CHECK_THROWS_WITH(fit_polynomial(inputs, {1.0, 2.0}, {Monomial{}, Monomial{}}, options), Contains("holds 1 twice"));
  CHECK_THROWS_AS(fit_polynomial(inputs, {1.0, NAN}, all_monomials(2), options), FitError);
  CHECK_THROWS_AS(fit_polynomial(inputs, {1.0, 2.0}, {Monomial{{3, 3, 0, 0, 0}}}, options), FitError);
}
