#include "articula/testsupport/synthetic_cap.hpp"

#include <cmath>
#include <random>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>

#include "articula/geometry/fibonacci.hpp"
#include "articula/geometry/pose.hpp"
#include "articula/geometry/surface.hpp"

namespace articula::fit {

Eigen::MatrixX3d syntheticCap(const geometry::ShapeParameters& shape, double half_angle, int n, double sigma,
                              unsigned seed) {
  const auto s = geometry::makeSurface(shape);
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, sigma > 0.0 ? sigma : 1.0);
  Eigen::MatrixX3d pts(n, 3);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d dir = geometry::fibonacciDirection(i, n, std::cos(half_angle));
    // The body is convex and holds its local origin: one crossing per ray.
    double lo = 0.0, hi = 1.0;
    while (s->evaluateCanonical(hi * dir, 0).value < 0.0) hi *= 2.0;
    for (int k = 0; k < 80; ++k) {
      const double mid = 0.5 * (lo + hi);
      (s->evaluateCanonical(mid * dir, 0).value < 0.0 ? lo : hi) = mid;
    }
    Eigen::Vector3d x = s->pose().toGlobal(0.5 * (lo + hi) * dir);
    if (sigma > 0.0) x += noise(rng) * s->gradient(x).normalized();
    pts.row(i) = x.transpose();
  }
  return pts;
}

Eigen::VectorXd exponentialField(const Eigen::MatrixX3d& points, double sigma, double length_mm, unsigned seed) {
  const Eigen::Index n = points.rows();
  Eigen::MatrixXd covariance(n, n);
  for (Eigen::Index i = 0; i < n; ++i)
    for (Eigen::Index j = 0; j < n; ++j)
      covariance(i, j) = sigma * sigma * std::exp(-(points.row(i) - points.row(j)).norm() / length_mm);
  covariance.diagonal().array() += 1e-12 * sigma * sigma;  // roundoff: keep it positive definite
  std::mt19937 rng(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  Eigen::VectorXd z(n);
  for (Eigen::Index i = 0; i < n; ++i) z[i] = gauss(rng);
  return covariance.llt().matrixL() * z;
}

Eigen::MatrixX3d correlatedCap(const geometry::ShapeParameters& shape, double half_angle, int n, double sigma,
                               double length_mm, unsigned seed) {
  Eigen::MatrixX3d pts = syntheticCap(shape, half_angle, n, 0.0, seed);
  const Eigen::VectorXd field = exponentialField(pts, sigma, length_mm, seed);
  const auto s = geometry::makeSurface(shape);
  for (Eigen::Index i = 0; i < pts.rows(); ++i) {
    const Eigen::Vector3d x = pts.row(i).transpose();
    pts.row(i) += field[i] * s->gradient(x).normalized().transpose();
  }
  return pts;
}

geometry::ShapeParameters randomHeadShape(geometry::ShapeModel model, double radius_spread, unsigned seed) {
  using geometry::ShapeModel;
  std::mt19937 rng(seed);
  auto uniform = [&rng](double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); };
  geometry::ShapeParameters p;
  p.model = model;
  const double r0 = uniform(18.0, 28.0);
  for (int k = 0; k < 3; ++k) p.radii[k] = r0 * (1.0 + uniform(-0.5, 0.5) * radius_spread);
  if (model == ShapeModel::Sphere) p.radii.setConstant(r0);
  if (model == ShapeModel::Superellipsoid || model == ShapeModel::Superovoid)
    for (int k = 0; k < 3; ++k) p.exponents[k] = uniform(2.0, 3.0);
  if (model == ShapeModel::Ovoid || model == ShapeModel::Superovoid) {
    p.cx = Eigen::Vector4d(1.0, uniform(0.0, 0.1), uniform(-0.03, 0.03), uniform(-0.03, 0.03));
    p.cy = Eigen::Vector4d(1.0, uniform(0.0, 0.1), uniform(-0.03, 0.03), uniform(-0.03, 0.03));
  }
  // A uniformly random rotation: a normalised Gaussian quaternion.
  std::normal_distribution<double> gauss(0.0, 1.0);
  Eigen::Quaterniond q(gauss(rng), gauss(rng), gauss(rng), gauss(rng));
  q.normalize();
  if (model != ShapeModel::Sphere) p.angles = geometry::anglesFromRotation(q.toRotationMatrix());
  p.center = Eigen::Vector3d(uniform(-50, 50), uniform(-50, 50), uniform(-50, 50));
  return p;
}

}  // namespace articula::fit
