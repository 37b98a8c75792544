// Least-squares fit of a SparsePolynomial to samples, with greedy term selection (order-recursive
// matching pursuit: Natarajan 1995; Rebollo-Neira & Lowe 2002) and coefficients by a rank-revealing QR (Ceres for a robust loss).
// This is the fitting step of polynomial optics (Schrade, Hanika & Dachsbacher 2016, sec. 4).
#pragma once

#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "lensmith/polyfit/polynomial.h"

namespace lensmith {

struct FitOptions {
  // Terms of the pool with total degree above this are not considered. Range 1..kMaxPolyDegree.
  int max_degree = 5;
  // Term budget. When the (degree-filtered) pool has at most this many terms, all of them are fitted
  // (a dense fit, no selection). >= 1.
  int max_terms = 40;
  // Selection stops early once the residual 2-norm falls to this fraction of the target 2-norm
  // (the data are then explained to rounding). In [0, 1).
  double relative_residual_tolerance = 1e-12;
  // Term selection scores candidates on at most this many samples (the first ones; 0 = all); the
  // coefficients are always solved on every sample. >= 0.
  int max_selection_samples = 0;
  // Huber loss scale, in the units of the targets, for the final coefficient solve; nullopt for
  // plain least squares. > 0. Selection always uses the least-squares residual.
  std::optional<double> huber_scale;

  // Throws OptionsError naming the field and the violated constraint.
  void validate() const;
};

struct FitResult {
  SparsePolynomial polynomial;         // terms in the order they were selected
  double train_rms = 0.0;              // RMS of (fit - target) over the training samples, target units
  double train_max_abs = 0.0;          // largest |fit - target| over the training samples
  std::vector<double> selection_rms;   // least-squares RMS after each greedy step (empty for a dense fit)
  int solver_iterations = 0;           // Ceres iterations of the final coefficient solve

  std::string to_string() const;
  friend std::ostream& operator<<(std::ostream& os, const FitResult& r) { return os << r.to_string(); }
};

// Fits targets[i] ~ p(inputs[i]) with p's terms drawn from `pool`.
// Inputs:  inputs and targets of equal, non-zero size; a pool without duplicate monomials.
// Output:  the fitted polynomial and its training errors.
// Throws OptionsError for invalid options, FitError for mismatched sizes, an empty or duplicated
// pool, no pool term within max_degree, non-finite data, or a Ceres failure.
FitResult fit_polynomial(const std::vector<PolyPoint>& inputs, const std::vector<double>& targets,
                         const std::vector<Monomial>& pool, const FitOptions& options);

}  // namespace lensmith
