#include "articula/fit/levenberg_marquardt.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <Eigen/Cholesky>

namespace articula::fit {

using Eigen::MatrixXd;
using Eigen::VectorXd;

LeastSquaresResult levenbergMarquardt(LeastSquaresProblem& problem, const VectorXd& x0, const VectorXd& lower,
                                      const VectorXd& upper, const LeastSquaresOptions& o) {
  const Eigen::Index n = x0.size();
  LeastSquaresResult result;
  result.x = x0.cwiseMax(lower).cwiseMin(upper);
  VectorXd r;
  ++result.evaluations;
  if (!problem.evaluate(result.x, r) || !r.allFinite()) {
    result.cost = std::numeric_limits<double>::infinity();
    result.termination = "invalid start";
    result.type = Termination::InvalidStart;
    return result;
  }
  result.cost = r.squaredNorm();
  MatrixXd J;
  problem.accept(J);
  VectorXd scale = VectorXd::Zero(n);  // Marquardt's D^2: the largest diag(J^T J) so far
  double mu = 1e-3, nu = 2.0;  // damping (relative to the scale) and its growth on rejection
  VectorXd r_trial;
  for (;;) {
    if (result.cost <= o.absolute_cost) {
      result.termination = "residuals at rounding level";
      result.type = Termination::ExactFit;
      result.converged = true;
      break;
    }
    if (result.evaluations >= o.max_evaluations) {
      result.termination = "evaluation limit reached";
      result.type = Termination::EvaluationLimit;
      break;
    }
    // J^T J through its lower half (half the work of the full product).
    MatrixXd A = MatrixXd::Zero(n, n);
    A.selfadjointView<Eigen::Lower>().rankUpdate(J.transpose());
    A = A.selfadjointView<Eigen::Lower>();
    const VectorXd g = J.transpose() * r;  // half the gradient of |r|^2
    scale = scale.cwiseMax(A.diagonal()).cwiseMax(1e-300);
    // The damped Gauss-Newton step, with the variables at a bound that the
    // descent direction -g would leave held there, and those the step would
    // carry across a bound stopped on it and held while the rest is solved
    // again (a projected step alone crawled along active bounds).
    std::vector<bool> held(static_cast<size_t>(n));
    for (Eigen::Index k = 0; k < n; ++k)
      held[k] = (result.x[k] <= lower[k] && g[k] > 0.0) || (result.x[k] >= upper[k] && g[k] < 0.0);
    VectorXd x_trial = result.x;
    for (Eigen::Index pass = 0; pass < n; ++pass) {
      std::vector<Eigen::Index> free;
      for (Eigen::Index k = 0; k < n; ++k)
        if (!held[k]) free.push_back(k);
      const Eigen::Index m = static_cast<Eigen::Index>(free.size());
      if (m == 0) break;
      const VectorXd rhs = -(g + A * (x_trial - result.x));
      MatrixXd M(m, m);
      VectorXd b(m);
      for (Eigen::Index i = 0; i < m; ++i) {
        b[i] = rhs[free[i]];
        for (Eigen::Index j = 0; j < m; ++j) M(i, j) = A(free[i], free[j]);
        M(i, i) += mu * scale[free[i]];
      }
      const VectorXd step_free = M.ldlt().solve(b);
      bool crossed = false;
      for (Eigen::Index i = 0; i < m; ++i) {
        const Eigen::Index k = free[i];
        x_trial[k] = result.x[k] + step_free[i];
        if (x_trial[k] < lower[k] || x_trial[k] > upper[k]) {
          x_trial[k] = std::clamp(x_trial[k], lower[k], upper[k]);
          held[k] = true;
          crossed = true;
        }
      }
      if (!crossed) break;
      for (Eigen::Index i = 0; i < m; ++i)
        if (!held[free[i]]) x_trial[free[i]] = result.x[free[i]];  // solved again from the current point
    }
    x_trial = x_trial.cwiseMax(lower).cwiseMin(upper);
    const VectorXd step = x_trial - result.x;
    const double scaled_step = step.cwiseProduct(scale.cwiseSqrt()).norm();
    const double scaled_x = result.x.cwiseProduct(scale.cwiseSqrt()).norm();
    if (!(scaled_step > o.parameter_tolerance * (scaled_x + o.parameter_tolerance))) {
      result.termination = "parameter tolerance reached";
      result.type = Termination::ParameterTolerance;
      result.converged = true;
      break;
    }
    // Reduction predicted by the linear model |r + J step|^2.
    const double predicted = -(2.0 * g.dot(step) + step.dot(A * step));
    ++result.evaluations;
    const bool valid = problem.evaluate(x_trial, r_trial) && r_trial.allFinite();
    const double cost_trial = valid ? r_trial.squaredNorm() : std::numeric_limits<double>::infinity();
    const double rho = predicted > 0.0 ? (result.cost - cost_trial) / predicted : -1.0;
    if (cost_trial < result.cost && rho > 0.0) {
      const double gain = result.cost - cost_trial;
      result.x = x_trial;
      r.swap(r_trial);
      result.cost = cost_trial;
      ++result.iterations;
      problem.accept(J);
      mu *= std::max(1.0 / 3.0, 1.0 - std::pow(2.0 * rho - 1.0, 3));
      nu = 2.0;
      if (gain <= o.relative_tolerance * (result.cost + gain)) {
        result.termination = "objective tolerance reached";
        result.type = Termination::ObjectiveTolerance;
        result.converged = true;
        break;
      }
    } else {
      mu *= nu;
      nu *= 2.0;
      if (mu > 1e20) {
        result.termination = "no further descent (damping limit)";
        result.type = Termination::NoFurtherDescent;
        result.converged = true;
        break;
      }
    }
  }
  return result;
}

}  // namespace articula::fit
