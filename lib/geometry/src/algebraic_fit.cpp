#include "articula/geometry/algebraic_fit.hpp"

#include <complex>
#include <limits>

#include <Eigen/Dense>

#include "articula/core/error.hpp"
#include "articula/geometry/pose.hpp"
#include "articula/geometry/sphere_fit.hpp"

namespace articula::geometry {

using Eigen::Matrix3d;
using Eigen::MatrixXd;
using Eigen::Vector3d;

namespace {
// Centred and scaled copy of the points, for conditioning.
struct Normalised {
  Eigen::MatrixX3d points;
  Vector3d centroid;
  double scale;
};
Normalised normalise(const Eigen::MatrixX3d& points) {
  if (points.rows() < 4) throw ProcessingError("algebraic fit: expected at least 4 points, found " +
                                               std::to_string(points.rows()));
  Normalised n;
  n.centroid = points.colwise().mean().transpose();
  n.points = points.rowwise() - n.centroid.transpose();
  n.scale = std::sqrt(n.points.rowwise().squaredNorm().mean());
  if (!(n.scale > 0.0)) throw ProcessingError("algebraic fit: all points coincide");
  n.points /= n.scale;
  return n;
}
}  // namespace

ShapeParameters algebraicSphere(const Eigen::MatrixX3d& points) {
  const Sphere sphere = fitSphere(points);
  ShapeParameters p;
  p.model = ShapeModel::Sphere;
  p.center = sphere.center;
  p.radii.setConstant(sphere.radius);
  return p;
}

ShapeParameters algebraicEllipsoid(const Eigen::MatrixX3d& points) {
  const Normalised n = normalise(points);
  const Eigen::Index N = n.points.rows();
  MatrixXd D(10, N);
  for (Eigen::Index i = 0; i < N; ++i) {
    const double x = n.points(i, 0), y = n.points(i, 1), z = n.points(i, 2);
    D.col(i) << x * x, y * y, z * z, 2 * y * z, 2 * x * z, 2 * x * y, 2 * x, 2 * y, 2 * z, 1.0;
  }
  const MatrixXd S = D * D.transpose();
  const MatrixXd S11 = S.topLeftCorner(6, 6), S12 = S.topRightCorner(6, 4), S22 = S.bottomRightCorner(4, 4);
  const double k = 4.0;
  Eigen::Matrix<double, 6, 6> C1 = Eigen::Matrix<double, 6, 6>::Zero();
  C1.topLeftCorner<3, 3>().setConstant(k / 2.0 - 1.0);
  C1.topLeftCorner<3, 3>().diagonal().setConstant(-1.0);
  C1.bottomRightCorner<3, 3>().diagonal().setConstant(-k);
  const MatrixXd S22_inv_S21 = S22.ldlt().solve(S12.transpose());
  const MatrixXd M = C1.inverse() * (S11 - S12 * S22_inv_S21);
  // The solution is the eigenvector with 4J - I^2 = v^T C1 v > 0 (its
  // eigenvalue is the algebraic error, >= 0, and 0 to rounding on exact data).
  Eigen::EigenSolver<MatrixXd> eig(M);
  int best = -1;
  double best_error = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 6; ++i) {
    const std::complex<double> lambda = eig.eigenvalues()[i];
    if (std::abs(lambda.imag()) > 1e-9 * (1.0 + std::abs(lambda))) continue;
    const Eigen::VectorXd v = eig.eigenvectors().col(i).real();
    if (!(v.dot(C1 * v) > 0.0)) continue;
    if (std::abs(lambda.real()) < best_error) {
      best_error = std::abs(lambda.real());
      best = i;
    }
  }
  if (best < 0) throw ProcessingError("ellipsoid-specific fit: no ellipsoid solution (degenerate points)");
  const Eigen::VectorXd v1 = eig.eigenvectors().col(best).real();
  const Eigen::VectorXd v2 = -S22_inv_S21 * v1;
  Matrix3d A;
  A << v1[0], v1[5], v1[4], v1[5], v1[1], v1[3], v1[4], v1[3], v1[2];
  const Vector3d b = v2.head<3>();
  const double d = v2[3];
  const Vector3d c = -A.ldlt().solve(b);
  const double k0 = c.dot(A * c) - d;
  Eigen::SelfAdjointEigenSolver<Matrix3d> axes(A / k0);
  if (!c.allFinite() || !(axes.eigenvalues().minCoeff() > 0.0))
    throw ProcessingError("ellipsoid-specific fit: the quadric is not an ellipsoid");
  const Vector3d radii = axes.eigenvalues().cwiseSqrt().cwiseInverse() * n.scale;
  ShapeParameters p;
  p.model = ShapeModel::Ellipsoid;
  p.center = n.centroid + n.scale * c;
  // Local z: the principal axis nearest the cap direction, pointing at the points.
  const Vector3d cap = (n.centroid - p.center).normalized();
  int iz = 0;
  for (int i = 1; i < 3; ++i)
    if (std::fabs(axes.eigenvectors().col(i).dot(cap)) > std::fabs(axes.eigenvectors().col(iz).dot(cap))) iz = i;
  const int ix = (iz + 1) % 3, iy = (iz + 2) % 3;
  Matrix3d R;
  R.col(0) = axes.eigenvectors().col(ix);
  R.col(2) = axes.eigenvectors().col(iz);
  if (R.col(2).dot(cap) < 0.0) R.col(2) *= -1.0;
  R.col(1) = R.col(2).cross(R.col(0));
  p.radii = Vector3d(radii[ix], radii[iy], radii[iz]);
  p.angles = anglesFromRotation(R);
  return p;
}

}  // namespace articula::geometry
