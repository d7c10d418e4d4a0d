#include "articula/fit/synthetic_cap.hpp"

#include <cmath>
#include <random>

#include "articula/geometry/fibonacci.hpp"
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

}  // namespace articula::fit
