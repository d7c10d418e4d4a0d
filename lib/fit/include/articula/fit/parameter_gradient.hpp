#pragma once
// Derivatives of a shape's implicit function with respect to its parameters.
#include <Eigen/Core>

#include "articula/geometry/shape.hpp"

namespace articula::fit {

/// dF/dlambda (#P x M, table 3.2 order, M = parameterCount(shape.model)) at the
/// points `at` (#P x 3, mm), in closed form for every model (the rotation's
/// angle derivatives by central differences of the 3 x 3 matrix, once), and
/// the norms of the spatial gradients |grad_x F| (#P) in `gradient_norms`.
/// With closest points as `at`, row i / |grad_x F| is the derivative of the
/// signed distance of point i (the envelope theorem). Rows are split over
/// `threads` threads (0: every hardware thread).
void parameterGradient(const geometry::ShapeParameters& shape, const Eigen::MatrixX3d& at, Eigen::MatrixXd& jacobian,
                       Eigen::VectorXd& gradient_norms, int threads = 1);

}  // namespace articula::fit
