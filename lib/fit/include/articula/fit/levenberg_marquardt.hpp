#pragma once
// Box-constrained Levenberg-Marquardt for small nonlinear least squares
// (orthogonal distance fitting, Ahn 2004): minimises |r(x)|^2 within
// lower <= x <= upper.
//
// Hand-written (about 100 lines) rather than Eigen's unsupported
// LevenbergMarquardt because that one has no bounds (the thesis bounds are
// active here: exponents at 2, c0 at 1) and no way to reject an invalid
// parameter set (an ovoid denominator reaching 0) other than a fake residual.
#include <string>

#include <Eigen/Core>

#include "articula/fit/termination.hpp"

namespace articula::fit {

/// The residuals of a least-squares problem. `evaluate` is always followed
/// by either another `evaluate` (step rejected) or by `accept` (step taken).
class LeastSquaresProblem {
 public:
  virtual ~LeastSquaresProblem() = default;
  /// Residuals at `x` (#R) into `r`; false if `x` is outside the valid set.
  virtual bool evaluate(const Eigen::VectorXd& x, Eigen::VectorXd& r) = 0;
  /// The last evaluated point becomes the current one (e.g. closest points
  /// become the warm starts): its Jacobian dr/dx (#R x #x) into `J`.
  virtual void accept(Eigen::MatrixXd& J) = 0;
};

struct LeastSquaresOptions {
  int max_evaluations = 200;          // residual evaluations, the start included
  double relative_tolerance = 1e-12;  // stop when an accepted step gains less than this fraction of |r|^2
  double parameter_tolerance = 1e-10; // or when the scaled step is this small relative to the scaled x
  double absolute_cost = 0.0;         // or when |r|^2 <= this (exact data)
};

struct LeastSquaresResult {
  Eigen::VectorXd x;   // the best point evaluated (the start if nothing was better)
  double cost = 0.0;   // |r(x)|^2
  int evaluations = 0;
  int iterations = 0;  // accepted steps
  std::string termination;
  Termination type = Termination::InvalidStart;
  bool converged = false;
};

/// Minimises |r(x)|^2 from `x0` (#x, clamped into the box) within
/// [`lower`, `upper`] (#x each; infinite entries allowed). Marquardt's
/// scaling by the largest diagonal of J^T J seen so far, Nielsen's damping
/// update; a variable at a bound whose descent direction points outwards is
/// held for that step. Deterministic. If the start itself is invalid,
/// returns it with cost +inf.
LeastSquaresResult levenbergMarquardt(LeastSquaresProblem& problem, const Eigen::VectorXd& x0,
                                      const Eigen::VectorXd& lower, const Eigen::VectorXd& upper,
                                      const LeastSquaresOptions& options = {});

}  // namespace articula::fit
