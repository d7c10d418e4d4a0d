#include "surface_search.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

#include "articula/geometry/fibonacci.hpp"

namespace articula::phantom::detail {

using Eigen::Vector3d;

double along(const Inside& inside, const Vector3d& c, const Vector3d& d, double reach, double tolerance) {
  double lo = 0, hi = reach;
  while (hi - lo > tolerance) (inside(c + 0.5 * (lo + hi) * d) ? lo : hi) = 0.5 * (lo + hi);
  return 0.5 * (lo + hi);
}

Vector3d perpendicular(const Vector3d& u) {
  const Vector3d helper = std::abs(u.x()) < 0.9 ? Vector3d::UnitX() : Vector3d::UnitY();
  return u.cross(helper).normalized();
}

Vector3d support(const Inside& inside, const Vector3d& c, const Vector3d& u, double reach) {
  const auto point = [&](const Vector3d& d) { return c + along(inside, c, d, reach) * d; };
  const Vector3d e1 = perpendicular(u), e2 = u.cross(e1);
  Vector3d best_d = u;
  double best = (point(u) - c).dot(u);
  for (double step = 0.2; step > 1e-7; step *= 0.5) {
    for (bool improved = true; improved;) {
      improved = false;
      for (const Vector3d& e : {Vector3d(e1), Vector3d(-e1), Vector3d(e2), Vector3d(-e2)}) {
        const Vector3d d = (best_d + step * e).normalized();
        const double v = (point(d) - c).dot(u);
        if (v > best + 1e-12) best = v, best_d = d, improved = true;
      }
    }
  }
  return point(best_d);
}

// A Fibonacci lattice of solid angles about the axis, each worth
// t^2 / (n . d) of surface (t: the distance to the surface, n its normal).
double modelArea(const geometry::PosedSurface& head, const Vector3d& c, double reach, const Vector3d& axis,
                 double cos_limit, const Inside& in_region) {
  const Inside model = [&head](const Vector3d& x) { return head.value(x) < 0; };
  constexpr int kDirections = 200000;
  const double solid_angle = 4.0 * M_PI / kDirections;
  const Eigen::Matrix3d turn = Eigen::Quaterniond::FromTwoVectors(Vector3d::UnitZ(), axis).toRotationMatrix();
  double area = 0;
  for (int i = 0; i < kDirections; ++i) {
    const Vector3d d = turn * geometry::fibonacciDirection(i, kDirections);
    if (d.dot(axis) < cos_limit) continue;
    const double t = along(model, c, d, reach, 1e-7);
    const Vector3d q = c + t * d;
    if (!in_region(q)) continue;
    const Vector3d n = head.evaluate(q, 1).gradient.normalized();
    area += t * t / std::max(n.dot(d), 1e-3) * solid_angle;
  }
  return area;
}

}  // namespace articula::phantom::detail
