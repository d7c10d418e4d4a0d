#pragma once
// Pose of a shape model (thesis eq. 2.20-2.21): x_g = R D x_l + t, with the
// scaling D = diag(a, b, c), R = Rx(phi) Ry(theta) Rz(psi), translation t.
// Global coordinates are LPS millimetres.
#include <Eigen/Core>

namespace articula::geometry {

/// R = Rx(phi) Ry(theta) Rz(psi); angles in radians.
Eigen::Matrix3d rotationFromAngles(const Eigen::Vector3d& phi_theta_psi);

/// Inverse of rotationFromAngles: phi, theta in [-pi/2, pi/2], psi in (-pi, pi].
/// At gimbal lock (|theta| = pi/2) psi is set to 0.
Eigen::Vector3d anglesFromRotation(const Eigen::Matrix3d& R);

/// Wraps an angle to (-pi, pi].
double wrapAngle(double radians);

struct Pose {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();  // R
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();   // t (mm)
  Eigen::Vector3d scale = Eigen::Vector3d::Ones();         // diagonal of D (mm)

  /// x_l = D^-1 R^T (x_g - t)   (eq. 2.20)
  Eigen::Vector3d toLocal(const Eigen::Vector3d& x_global) const;
  /// x_g = R D x_l + t          (eq. 2.21)
  Eigen::Vector3d toGlobal(const Eigen::Vector3d& x_local) const;
  /// A = R D^-1: global gradient = A * local gradient, global Hessian = A H_l A^T.
  Eigen::Matrix3d gradientMap() const;
};

}  // namespace articula::geometry
