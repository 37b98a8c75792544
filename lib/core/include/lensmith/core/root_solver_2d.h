// One small solver for the two-unknown root problems of ray aiming: find x with r(x) = 0 where r
// maps 2 unknowns to 2 residuals (a stop point's miss, the angle between two directions). Newton's
// method with the Jacobian supplied, by finite differences, updated by Broyden's rank-one rule, or
// held fixed (the chord method); optionally a trust region and a backtracking line search. The shape
// follows Ceres Solver's TinySolver (ceres/tiny_solver.h: options, a summary with a status, a
// residual functor that says whether it could be evaluated), cut down to 2 x 2 and without
// allocation: the exact tracer's aimer, the ray models' per-ray aiming and the fits' aiming all
// solve millions of these.
//
// Methods: J. E. Dennis, R. B. Schnabel, "Numerical Methods for Unconstrained Optimization and
// Nonlinear Equations" (SIAM 1996): Newton with backtracking and Armijo's sufficient decrease
// (sec. 6.3), finite-difference Jacobians (sec. 5.4), Broyden's update (sec. 8.1).
#pragma once

#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <string_view>

namespace lensmith {

// Two unknowns or two residuals.
using Vector2 = std::array<double, 2>;
// A 2 x 2 Jacobian, row-major: {dr0/dx0, dr0/dx1, dr1/dx0, dr1/dx1}.
using Matrix2 = std::array<double, 4>;

// Solves J s = b by Cramer's rule; false when J is singular or the result is not finite.
inline bool solve_2x2(const Matrix2& j, const Vector2& b, Vector2& s) {
  const double det = j[0] * j[3] - j[1] * j[2];
  if (!(std::abs(det) > 0.0) || !std::isfinite(det)) return false;
  s = {(j[3] * b[0] - j[1] * b[1]) / det, (j[0] * b[1] - j[2] * b[0]) / det};
  return std::isfinite(s[0]) && std::isfinite(s[1]);
}

inline double norm_2d(const Vector2& v) { return std::sqrt(v[0] * v[0] + v[1] * v[1]); }

// Where each step's Jacobian comes from.
enum class JacobianSource {
  Analytic,           // the residual functor fills it when asked (at every accepted point)
  ForwardDifference,  // forward differences of `difference_step`; backward where the forward point fails
  Broyden,            // the initial Jacobian, updated by Broyden's rank-one rule after every step
  Fixed,              // the initial Jacobian throughout (the chord method)
};

struct RootSolver2dOptions {
  JacobianSource jacobian = JacobianSource::ForwardDifference;
  // Converged when |r| <= tolerance (Euclidean norm, in the residual's units); > 0.
  double tolerance = 1e-10;
  // Steps at most (each one Jacobian and one line search); 0 evaluates the start only.
  int max_iterations = 20;
  // ForwardDifference: the step in x's units (> 0).
  double difference_step = 1e-7;
  // A step longer than this (x's units) is shortened to it: a trust region that keeps a nearly
  // singular Jacobian from throwing x out of the residual's domain. Infinity: none.
  double max_step = std::numeric_limits<double>::infinity();
  // True: a step is halved (at most max_halvings times) until |r| falls strictly and by Armijo's
  // sufficient decrease |r(x + t s)| <= (1 - armijo t) |r(x)|; a step that never does stalls the
  // solve. False: every full step is taken, and the next evaluation judges it (Broyden, chord).
  bool line_search = true;
  double armijo = 0.0;  // in [0, 1)
  int max_halvings = 20;

  // Throws OptionsError naming the field and its constraint.
  void validate() const;
  std::string to_string() const;
};

enum class RootSolver2dStatus {
  Converged,         // |r| <= tolerance
  FailedAtStart,     // the residual could not be evaluated at the start
  FailedEvaluation,  // a step's point, or both difference points, could not be evaluated (no line search)
  SingularJacobian,  // the step could not be solved for
  NoDecrease,        // the line search found no point with a smaller residual
  OutOfIterations,   // max_iterations steps taken, not converged
};

std::string_view to_string(RootSolver2dStatus status);

struct RootSolver2dSummary {
  RootSolver2dStatus status = RootSolver2dStatus::FailedAtStart;
  int iterations = 0;           // steps taken
  Vector2 residual{};           // at the returned x
  double residual_norm = std::numeric_limits<double>::infinity();
  // Analytic: at the returned x. ForwardDifference: at the point of the last step (x unless it is
  // the start). Broyden, Fixed: the last estimate.
  Matrix2 jacobian{};
  bool converged() const { return status == RootSolver2dStatus::Converged; }
  std::string to_string() const;  // "RootSolver2dSummary(converged, 3 iterations, |r| 1.2e-13)"
};

// The residual functor: `bool f(const Vector2& x, Vector2& r, Matrix2* jacobian)` returns false
// where r cannot be evaluated (a ray that dies, a point outside a fit's domain); `jacobian` is
// non-null only for JacobianSource::Analytic at points the solver accepts. The optional
// `on_accept()` runs each time the point just evaluated becomes the current x (the start included),
// so that a caller can keep what its evaluation computed besides r.
struct NoAcceptHook {
  void operator()() const {}
};

class RootSolver2d {
 public:
  // Throws OptionsError for invalid options.
  explicit RootSolver2d(const RootSolver2dOptions& options) : options_(options) { options_.validate(); }

  // Solves from x (updated in place to the last accepted point). `initial_jacobian` is required for
  // Broyden and Fixed (and ignored otherwise). Allocates nothing.
  template <class Residual, class OnAccept = NoAcceptHook>
  RootSolver2dSummary solve(Residual&& f, Vector2& x, const Matrix2* initial_jacobian = nullptr,
                            OnAccept&& on_accept = {}) const;

  const RootSolver2dOptions& options() const { return options_; }

 private:
  RootSolver2dOptions options_;
};

template <class Residual, class OnAccept>
RootSolver2dSummary RootSolver2d::solve(Residual&& f, Vector2& x, const Matrix2* initial_jacobian, OnAccept&& on_accept) const {
  const RootSolver2dOptions& o = options_;
  const bool analytic = o.jacobian == JacobianSource::Analytic;
  RootSolver2dSummary out;
  if (initial_jacobian) out.jacobian = *initial_jacobian;
  if (!f(x, out.residual, analytic ? &out.jacobian : nullptr)) return out;  // FailedAtStart
  on_accept();
  out.residual_norm = norm_2d(out.residual);
  for (;;) {
    if (out.residual_norm <= o.tolerance) {
      out.status = RootSolver2dStatus::Converged;
      return out;
    }
    if (out.iterations >= o.max_iterations) {
      out.status = RootSolver2dStatus::OutOfIterations;
      return out;
    }
    ++out.iterations;
    if (o.jacobian == JacobianSource::ForwardDifference) {
      for (int axis = 0; axis < 2; ++axis) {
        Vector2 side_x = x, side_r{};
        double h = o.difference_step;
        side_x[static_cast<std::size_t>(axis)] += h;
        if (!f(side_x, side_r, nullptr)) {
          h = -h;
          side_x[static_cast<std::size_t>(axis)] = x[static_cast<std::size_t>(axis)] + h;
          if (!f(side_x, side_r, nullptr)) {
            out.status = RootSolver2dStatus::FailedEvaluation;
            return out;
          }
        }
        out.jacobian[static_cast<std::size_t>(axis)] = (side_r[0] - out.residual[0]) / h;
        out.jacobian[static_cast<std::size_t>(2 + axis)] = (side_r[1] - out.residual[1]) / h;
      }
    }
    Vector2 step;
    if (!solve_2x2(out.jacobian, {-out.residual[0], -out.residual[1]}, step)) {
      out.status = RootSolver2dStatus::SingularJacobian;
      return out;
    }
    const double length = norm_2d(step);
    if (length > o.max_step) step = {step[0] * o.max_step / length, step[1] * o.max_step / length};

    if (!o.line_search) {
      const Vector2 next{x[0] + step[0], x[1] + step[1]};
      Vector2 r{};
      if (!f(next, r, analytic ? &out.jacobian : nullptr)) {
        out.status = RootSolver2dStatus::FailedEvaluation;
        return out;
      }
      if (o.jacobian == JacobianSource::Broyden) {
        // J += (dr - J s) s^T / |s|^2, kept only while it stays invertible.
        const double s2 = step[0] * step[0] + step[1] * step[1];
        const Matrix2& j = out.jacobian;
        const double ux = (r[0] - out.residual[0]) - (j[0] * step[0] + j[1] * step[1]);
        const double uy = (r[1] - out.residual[1]) - (j[2] * step[0] + j[3] * step[1]);
        const Matrix2 updated{j[0] + ux * step[0] / s2, j[1] + ux * step[1] / s2, j[2] + uy * step[0] / s2,
                              j[3] + uy * step[1] / s2};
        const double det = updated[0] * updated[3] - updated[1] * updated[2];
        if (s2 > 0.0 && std::abs(det) > 0.0 && std::isfinite(det)) out.jacobian = updated;
      }
      x = next;
      out.residual = r;
      out.residual_norm = norm_2d(r);
      on_accept();
      continue;
    }

    bool moved = false;
    double fraction = 1.0;
    for (int halving = 0; halving <= o.max_halvings; ++halving, fraction *= 0.5) {
      const Vector2 trial{x[0] + fraction * step[0], x[1] + fraction * step[1]};
      Vector2 r{};
      if (!f(trial, r, nullptr)) continue;
      const double size = norm_2d(r);
      if (!(size < out.residual_norm && size <= (1.0 - o.armijo * fraction) * out.residual_norm)) continue;
      x = trial;
      out.residual = r;
      out.residual_norm = size;
      on_accept();
      moved = true;
      break;
    }
    if (!moved) {
      out.status = RootSolver2dStatus::NoDecrease;
      return out;
    }
    // The Jacobian at the accepted point, when the functor gives it: the next step's, and the
    // caller's at the solution (the poly model's beam takes its pupil's scale from it).
    if (analytic) {
      Vector2 r{};
      if (f(x, r, &out.jacobian)) {
        out.residual = r;
        out.residual_norm = norm_2d(r);
      }
    }
  }
}

}  // namespace lensmith
