#pragma once
// Parameter uncertainty at a least-squares optimum of the signed distances:
// the Gauss-Newton covariance s^2 (J^T J)^-1, with J the derivatives of the
// distances with respect to the parameters of thesis table 3.2 and s^2 the
// residual variance SSE / (n - M). Standard errors, 95 % intervals, and
// which parameters the points cannot identify (a cap seen from one side
// leaves some directions of the parameter space nearly free).
#include <string>
#include <vector>

#include <Eigen/Core>

#include "articula/geometry/shape.hpp"

namespace articula::fit {

struct ParameterUncertainty {
  Eigen::VectorXd standard_error;           // table 3.2 order; infinity where not identifiable
  Eigen::VectorXd ci95_lower, ci95_upper;   // estimate -+ 1.96 standard errors
  std::vector<std::string> not_identifiable;  // parameter names: a near-singular J^T J or a very wide interval
  double condition_number = 0;              // of J^T J with unit-scaled columns
};

/// The uncertainty of `fitted` (a least-squares optimum) on `points` (#P x 3);
/// `closest`: the points' closest points on `fitted` if known (#P x 3, else
/// empty), which spares their global search.
/// Throws InputError when there are no more points than parameters.
ParameterUncertainty parameterUncertainty(const geometry::ShapeParameters& fitted, const Eigen::MatrixX3d& points,
                                          const Eigen::MatrixX3d& closest = {});

}  // namespace articula::fit
