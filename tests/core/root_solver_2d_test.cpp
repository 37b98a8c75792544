// The two-unknown root solver of ray aiming (root_solver_2d.h), on problems whose answers are known
// from the theory of the methods: Dennis & Schnabel, "Numerical Methods for Unconstrained
// Optimization and Nonlinear Equations" (SIAM 1996), and D. M. Gay, "Some convergence properties of
// Broyden's method", SIAM J. Numer. Anal. 16 (1979) 623-630.
#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

#include "lensmith/core/errors.h"
#include "lensmith/core/root_solver_2d.h"

using lensmith::JacobianSource;
using lensmith::Matrix2;
using lensmith::RootSolver2d;
using lensmith::RootSolver2dOptions;
using lensmith::RootSolver2dStatus;
using lensmith::Vector2;

namespace {

// Dennis & Schnabel's example 6.5.1 (also 5.4.1): F = (x0^2 + x1^2 - 2, e^(x0 - 1) + x1^3 - 2), root
// (1, 1); from (2, 0.5) Newton's full first step increases |F|, so the line search must act.
bool dennis_schnabel(const Vector2& x, Vector2& r, Matrix2* j) {
  r = {x[0] * x[0] + x[1] * x[1] - 2.0, std::exp(x[0] - 1.0) + x[1] * x[1] * x[1] - 2.0};
  if (j) *j = {2.0 * x[0], 2.0 * x[1], std::exp(x[0] - 1.0), 3.0 * x[1] * x[1]};
  return true;
}

// A linear system A x = b with a non-symmetric A; root (1, -2).
constexpr Matrix2 kA{3.0, 1.0, -1.0, 2.0};
constexpr Vector2 kB{1.0, -5.0};
bool linear(const Vector2& x, Vector2& r, Matrix2* j) {
  r = {kA[0] * x[0] + kA[1] * x[1] - kB[0], kA[2] * x[0] + kA[3] * x[1] - kB[1]};
  if (j) *j = kA;
  return true;
}

// Newton converges quadratically near a simple root: the residual at least squares (times a constant) each step.
constexpr double kNewtonTolerance = 1e-13;  // a hundred times the rounding of residuals of size ~1
// |x - x*| <= |J^-1| |r|: at Dennis & Schnabel's root (1, 1) |J^-1| is about 1.1 and |r| <= kNewtonTolerance.
constexpr double kNewtonRoot = 1e-12;

}  // namespace

TEST_CASE("Newton with the analytic Jacobian finds Dennis & Schnabel's root where the full first step fails", "[core][solver]") {
  RootSolver2dOptions o;
  o.jacobian = JacobianSource::Analytic;
  o.tolerance = kNewtonTolerance;
  o.armijo = 1e-4;  // their alpha
  std::vector<double> norms;
  Vector2 x{2.0, 0.5}, r{};
  auto record = [&]() {
    dennis_schnabel(x, r, nullptr);
    norms.push_back(std::hypot(r[0], r[1]));
  };
  const auto summary = RootSolver2d(o).solve(dennis_schnabel, x, nullptr, record);
  REQUIRE(summary.converged());
  CHECK(x[0] == Approx(1.0).margin(kNewtonRoot));
  CHECK(x[1] == Approx(1.0).margin(kNewtonRoot));
  // The full Newton step from (2, 0.5) lands where |F| is larger: the line search shortened it.
  Vector2 full_step;
  Matrix2 j;
  Vector2 r0;
  dennis_schnabel({2.0, 0.5}, r0, &j);
  REQUIRE(lensmith::solve_2x2(j, {-r0[0], -r0[1]}, full_step));
  Vector2 r_full;
  dennis_schnabel({2.0 + full_step[0], 0.5 + full_step[1]}, r_full, nullptr);
  CHECK(lensmith::norm_2d(r_full) > lensmith::norm_2d(r0));
  // Quadratic convergence at the end: |F_k+1| <= C |F_k|^2 with C of the order of |J^-1| |F''| (~10 here).
  REQUIRE(norms.size() >= 3);
  const std::size_t n = norms.size();
  CHECK(norms[n - 2] <= 10.0 * norms[n - 3] * norms[n - 3]);
  CHECK(summary.residual_norm <= kNewtonTolerance);
}

TEST_CASE("forward differences find the same root as the analytic Jacobian", "[core][solver]") {
  // Forward differences, h = 1e-7: h |F''| / 2 (|F''| <= 6) and eps |F| / h, at the last step's point, a step before x.
  constexpr double kDifferenceJacobian = 1e-5;
  RootSolver2dOptions o;
  o.jacobian = JacobianSource::ForwardDifference;
  o.tolerance = kNewtonTolerance;
  o.difference_step = 1e-7;  // sqrt of double's epsilon, for residuals of size ~1
  Vector2 x{2.0, 0.5};
  const auto summary = RootSolver2d(o).solve(dennis_schnabel, x);
  REQUIRE(summary.converged());
  CHECK(x[0] == Approx(1.0).margin(kNewtonRoot));
  CHECK(x[1] == Approx(1.0).margin(kNewtonRoot));
  // The difference Jacobian at the last step's point agrees with the analytic one to ~ step size.
  Vector2 r;
  Matrix2 j;
  dennis_schnabel(x, r, &j);
  for (std::size_t k = 0; k < 4; ++k) CHECK(summary.jacobian[k] == Approx(j[k]).margin(kDifferenceJacobian));
}

TEST_CASE("Broyden's method solves a linear system exactly in at most 2n = 4 steps from a wrong Jacobian (Gay 1979)", "[core][solver]") {
  // Solved to |r| <= 1e-12 (its tolerance below), and |x - x*| <= |A^-1| |r| with |A^-1| = 0.46.
  constexpr double kLinearRoot = 1e-12;
  RootSolver2dOptions o;
  o.jacobian = JacobianSource::Broyden;
  o.line_search = false;
  o.tolerance = 1e-12;
  o.max_iterations = 4;
  const Matrix2 identity{1.0, 0.0, 0.0, 1.0};
  Vector2 x{0.0, 0.0};
  const auto summary = RootSolver2d(o).solve(linear, x, &identity);
  REQUIRE(summary.converged());
  CHECK(summary.iterations <= 4);
  CHECK(x[0] == Approx(1.0).margin(kLinearRoot));
  CHECK(x[1] == Approx(-2.0).margin(kLinearRoot));
}

TEST_CASE("the chord method with twice the true Jacobian halves the error every step", "[core][solver]") {
  // x_k+1 - x* = (I - (2A)^-1 A)(x_k - x*) = (x_k - x*) / 2, so the residual A(x - x*) halves too.
  // Three halvings are exact in exact arithmetic: the double rounding of three steps on numbers of size ~5.
  constexpr double kThreeChordSteps = 1e-12;
  RootSolver2dOptions o;
  o.jacobian = JacobianSource::Fixed;
  o.line_search = false;
  o.tolerance = 1e-9;
  o.max_iterations = 100;
  const Matrix2 twice{2.0 * kA[0], 2.0 * kA[1], 2.0 * kA[2], 2.0 * kA[3]};
  Vector2 x{0.0, 0.0}, r0;
  linear(x, r0, nullptr);
  const auto summary = RootSolver2d(o).solve(linear, x, &twice);
  REQUIRE(summary.converged());
  CHECK(summary.iterations == static_cast<int>(std::ceil(std::log2(lensmith::norm_2d(r0) / o.tolerance))));

  o.max_iterations = 3;
  Vector2 y{0.0, 0.0};
  const auto stopped = RootSolver2d(o).solve(linear, y, &twice);
  CHECK(stopped.status == RootSolver2dStatus::OutOfIterations);
  CHECK(stopped.residual_norm == Approx(lensmith::norm_2d(r0) / 8.0).epsilon(kThreeChordSteps));
}

TEST_CASE("a trust region shortens a long step to its radius", "[core][solver]") {
  // A linear residual's difference Jacobian errs only by rounding, eps |r| / h = 2.2e-16 x 10 / 1e-7 = 2e-8 relative.
  constexpr double kLinearDifference = 1e-6;
  // x1's residual depends on x1 alone and x0's not on x1: the differences across are exactly 0 and x1 stays 0.
  constexpr double kUntouchedUnknown = 1e-9;
  RootSolver2dOptions o;
  o.max_step = 1.0;
  o.max_iterations = 1;
  Vector2 x{0.0, 0.0};
  const auto summary = RootSolver2d(o).solve([](const Vector2& p, Vector2& r, Matrix2*) { r = {p[0] - 10.0, p[1]}; return true; }, x);
  CHECK(summary.status == RootSolver2dStatus::OutOfIterations);
  CHECK(x[0] == Approx(1.0).epsilon(kLinearDifference));  // the difference Jacobian is exact for a linear residual up to rounding
  CHECK(x[1] == Approx(0.0).margin(kUntouchedUnknown));
}

TEST_CASE("a solve that cannot go on says why", "[core][solver]") {
  RootSolver2dOptions o;
  Vector2 x{0.0, 0.0};
  auto never = [](const Vector2&, Vector2&, Matrix2*) { return false; };
  CHECK(RootSolver2d(o).solve(never, x).status == RootSolver2dStatus::FailedAtStart);

  // Only the start point can be evaluated: neither difference point.
  auto only_origin = [](const Vector2& p, Vector2& r, Matrix2*) { r = {p[0] + 1.0, p[1] + 1.0}; return p[0] == 0.0 && p[1] == 0.0; };
  CHECK(RootSolver2d(o).solve(only_origin, x).status == RootSolver2dStatus::FailedEvaluation);

  // x0 + x1 = 0 and x0 + x1 = 1: no root, the Jacobian is singular everywhere.
  auto parallel = [](const Vector2& p, Vector2& r, Matrix2*) { r = {p[0] + p[1], p[0] + p[1] - 1.0}; return true; };
  CHECK(RootSolver2d(o).solve(parallel, x).status == RootSolver2dStatus::SingularJacobian);

  // A Jacobian of the wrong sign points uphill: no step length lowers |r|.
  RootSolver2dOptions wrong;
  wrong.jacobian = JacobianSource::Analytic;
  Vector2 start{1.0, 2.0};
  auto uphill = [](const Vector2& p, Vector2& r, Matrix2* j) {
    r = p;
    if (j) *j = {-1.0, 0.0, 0.0, -1.0};
    return true;
  };
  const auto summary = RootSolver2d(wrong).solve(uphill, start);
  CHECK(summary.status == RootSolver2dStatus::NoDecrease);
  CHECK(start == Vector2{1.0, 2.0});  // the last accepted point: the start
}

TEST_CASE("solver options that make no sense are refused by name", "[core][solver]") {
  using Catch::Matchers::Contains;
  RootSolver2dOptions o;
  o.tolerance = 0.0;
  CHECK_THROWS_WITH(RootSolver2d(o), Contains("tolerance"));
  o = {};
  o.armijo = 1.0;
  CHECK_THROWS_WITH(RootSolver2d(o), Contains("armijo"));
  o = {};
  o.max_step = -1.0;
  CHECK_THROWS_WITH(RootSolver2d(o), Contains("max_step"));
  o = {};
  o.max_iterations = -1;
  CHECK_THROWS_WITH(RootSolver2d(o), Contains("max_iterations"));
  CHECK(RootSolver2dOptions{}.to_string() == "RootSolver2dOptions(forward differences, tolerance 1e-10, 20 iterations, difference step 1e-07, line search (Armijo 0, 20 halvings))");
}
