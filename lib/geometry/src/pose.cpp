#include "articula/geometry/pose.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

namespace articula::geometry {

Eigen::Matrix3d rotationFromAngles(const Eigen::Vector3d& a) {
  using Eigen::AngleAxisd;
  using Eigen::Vector3d;
  return (AngleAxisd(a[0], Vector3d::UnitX()) * AngleAxisd(a[1], Vector3d::UnitY()) *
          AngleAxisd(a[2], Vector3d::UnitZ()))
      .toRotationMatrix();
}

Eigen::Vector3d anglesFromRotation(const Eigen::Matrix3d& R) {
  // R(0,2) = sin(theta), R(0,0) = cos(theta)cos(psi), R(0,1) = -cos(theta)sin(psi),
  // R(1,2) = -sin(phi)cos(theta), R(2,2) = cos(phi)cos(theta).
  const double s = std::clamp(R(0, 2), -1.0, 1.0);
  const double theta = std::asin(s);
  if (std::fabs(s) > 1.0 - 1e-12) {
    // Gimbal lock: only phi +- psi is defined; put it all in phi.
    // asin near +-1 loses half the digits; the exact angle is +-pi/2.
    const double phi = std::atan2(R(2, 1), R(1, 1));
    return {phi, std::copysign(M_PI / 2, s), 0.0};
  }
  return {std::atan2(-R(1, 2), R(2, 2)), theta, std::atan2(-R(0, 1), R(0, 0))};
}

double wrapAngle(double r) {
  double w = std::remainder(r, 2.0 * M_PI);  // in [-pi, pi]
  return w <= -M_PI ? w + 2.0 * M_PI : w;
}

Eigen::Vector3d Pose::toLocal(const Eigen::Vector3d& x) const {
  return (rotation.transpose() * (x - translation)).cwiseQuotient(scale);
}

Eigen::Vector3d Pose::toGlobal(const Eigen::Vector3d& x) const {
  return rotation * x.cwiseProduct(scale) + translation;
}

Eigen::Matrix3d Pose::gradientMap() const { return rotation * scale.cwiseInverse().asDiagonal(); }

}  // namespace articula::geometry
