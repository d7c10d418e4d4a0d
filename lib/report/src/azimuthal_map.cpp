#include "articula/report/azimuthal_map.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

namespace articula::report {

AzimuthalMap azimuthalEqualArea(const Eigen::MatrixX3d& points, const Eigen::Vector3d& centre) {
  AzimuthalMap map;
  map.centre = centre;
  const Eigen::Index n = points.rows();
  Eigen::MatrixX3d u(n, 3);
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double radius_sum = 0.0;
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::Vector3d v = points.row(i).transpose() - centre;
    const double r = v.norm();
    radius_sum += r;
    u.row(i) = r > 0.0 ? Eigen::RowVector3d((v / r).transpose()) : Eigen::RowVector3d::Zero();
    sum += u.row(i).transpose();
  }
  map.radius_mm = n ? radius_sum / static_cast<double>(n) : 0.0;
  map.axis = sum.norm() > 1e-9 * static_cast<double>(std::max<Eigen::Index>(n, 1)) ? sum.normalized()
                                                                                     : Eigen::Vector3d::UnitZ();
  // Up: the first of S, P, L that is not within acos(0.9) (26 degrees) of the axis.
  Eigen::Vector3d e = Eigen::Vector3d::UnitZ();
  for (const Eigen::Vector3d& c : {Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(1, 0, 0)})
    if (std::fabs(c.dot(map.axis)) < 0.9) {
      e = c;
      break;
    }
  map.up = (e - e.dot(map.axis) * map.axis).normalized();
  map.right = map.up.cross(map.axis);
  map.xy.resize(n, 2);
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::Vector3d d = u.row(i).transpose();
    const double x = d.dot(map.right), y = d.dot(map.up), sin_theta = std::hypot(x, y);
    if (d.squaredNorm() == 0.0) {  // at the centre
      map.xy.row(i) << 0.0, 0.0;
      continue;
    }
    // 2 R sin(theta/2) = R sqrt(2 (1 - cos theta)), well conditioned for all theta.
    const double r = map.radius_mm * std::sqrt(std::max(0.0, 2.0 * (1.0 - d.dot(map.axis))));
    if (sin_theta < 1e-15)  // on the axis (r = 0) or opposite it (r = 2R, any direction)
      map.xy.row(i) << r, 0.0;
    else
      map.xy.row(i) << r * x / sin_theta, r * y / sin_theta;
  }
  return map;
}

}  // namespace articula::report
