#include "articula/contact/frame_derivatives.hpp"

#include <cmath>

#include <Eigen/Geometry>

#include "articula/core/error.hpp"

namespace articula::contact {

using Eigen::Matrix3d;
using Eigen::Vector3d;

namespace {

Matrix3d skew(const Vector3d& v) {
  Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

// Householder, right-handed, s = sign(n_x), k = 1 / (1 + |n_x|):
//   t = (-s n_y, 1 - k n_y^2, -k n_y n_z),  b = (-n_z, -s k n_y n_z, s (1 - k n_z^2)),
// with dk/dn_x = -s k^2 (the branch s is constant within each half space).
FrameWithDerivatives householder(const Vector3d& n) {
  const geometry::TangentFrame f = geometry::householderFrameUnit(n);
  const double s = std::copysign(1.0, n.x());
  const double k = 1.0 / (1.0 + std::fabs(n.x()));
  const double k2 = k * k, y = n.y(), z = n.z();
  FrameWithDerivatives r{f.t, f.b, Matrix3d::Zero(), Matrix3d::Zero()};
  // columns: d/dn_x, d/dn_y, d/dn_z
  r.dt_dn << 0.0, -s, 0.0,                    //
      s * k2 * y * y, -2.0 * k * y, 0.0,      //
      s * k2 * y * z, -k * z, -k * y;
  r.db_dn << 0.0, 0.0, -1.0,                  //
      k2 * y * z, -s * k * z, -s * k * y,     //
      k2 * z * z, 0.0, -2.0 * s * k * z;
  return r;
}

// Square plate: v = n + e with e = (-1, 1, 0) (v2) or (1, 1, 0) (v1), so
// n x v = n x e; t = (n x e) / |n x e|, b = n x t.
FrameWithDerivatives squarePlate(const Vector3d& n) {
  const geometry::TangentFrame f = geometry::squarePlateFrameUnit(n);
  const Vector3d e = n.x() * n.y() >= 0.0 ? Vector3d(-1.0, 1.0, 0.0) : Vector3d(1.0, 1.0, 0.0);
  const Vector3d w = n.cross(e);
  const double len = w.norm();
  const Vector3d t = w / len;
  const Matrix3d dw_dn = -skew(e);
  const Matrix3d dt_dn = (Matrix3d::Identity() - t * t.transpose()) * dw_dn / len;
  const Matrix3d db_dn = -skew(t) + skew(n) * dt_dn;
  return {f.t, f.b, dt_dn, db_dn};
}

}  // namespace

FrameWithDerivatives frameWithDerivatives(const Vector3d& n, geometry::FrameMethod method) {
  switch (method) {
    case geometry::FrameMethod::Householder: return householder(n);
    case geometry::FrameMethod::SquarePlate: return squarePlate(n);
    default:
      throw UsageError(std::string("contact: frame method ") + geometry::frameMethodName(method) +
                       " has no Jacobian here (expected Householder or SquarePlate)");
  }
}

}  // namespace articula::contact
