#include "articula/geometry/sphere_fit.hpp"

#include <cmath>
#include <string>

#include <Eigen/Dense>

#include "articula/core/error.hpp"

namespace articula::geometry {

Sphere fitSphere(const Eigen::MatrixX3d& points) {
  if (points.rows() < 4)
    throw ProcessingError("sphere fit: expected at least 4 points, found " + std::to_string(points.rows()));
  const Eigen::RowVector3d centroid = points.colwise().mean();
  Eigen::MatrixX3d centred = points.rowwise() - centroid;
  const double scale = std::sqrt(centred.rowwise().squaredNorm().mean());
  if (!(scale > 0.0)) throw ProcessingError("sphere fit: all points coincide");
  centred /= scale;
  Eigen::MatrixXd A(centred.rows(), 4);
  A.leftCols<3>() = 2.0 * centred;
  A.col(3).setOnes();
  const Eigen::VectorXd b = centred.rowwise().squaredNorm();
  const Eigen::Vector4d s = A.colPivHouseholderQr().solve(b);
  const Eigen::Vector3d c = s.head<3>();
  const double r2 = s[3] + c.squaredNorm();
  if (!s.allFinite() || !(r2 > 0.0)) throw ProcessingError("sphere fit failed: the points are degenerate");
  return {centroid.transpose() + scale * c, scale * std::sqrt(r2)};
}

}  // namespace articula::geometry
