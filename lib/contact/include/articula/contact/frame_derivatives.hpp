#pragma once
// Tangent and binormal of a unit normal with their 3x3 Jacobians d t / d n and
// d b / d n (thesis eq. 5.27, 5.34): the pieces of the common-normal
// Jacobian that depend on the frame method. The frames are exactly those of
// articula/geometry/frames.hpp (Householder, right-handed; square plate,
// table 5.1); the Jacobians are taken along the unit sphere's extension used
// by those formulas, so chain them with d n / d x of the normalised normal.
#include <Eigen/Core>

#include "articula/geometry/frames.hpp"

namespace articula::contact {

struct FrameWithDerivatives {
  Eigen::Vector3d t, b;   // unit tangent and binormal, t x b = n
  Eigen::Matrix3d dt_dn;  // d t / d n
  Eigen::Matrix3d db_dn;  // d b / d n
};

/// Householder (table 4.2 / C.1, geometry::householderFrameUnit) or square
/// plate (table 5.1, geometry::squarePlateFrameUnit) for unit n; other methods
/// throw UsageError.
FrameWithDerivatives frameWithDerivatives(const Eigen::Vector3d& n, geometry::FrameMethod method);

}  // namespace articula::contact
