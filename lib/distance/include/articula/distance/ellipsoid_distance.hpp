#pragma once
// Closest point on an axis-aligned ellipsoid (Eberly, "Distance from a point
// to an ellipse, an ellipsoid, or a hyperellipsoid", robust version): the
// problem is reduced to the first octant and to sorted semi-axes, and the
// single root of a monotone function is bracketed and refined.
#include <Eigen/Core>

namespace articula::distance {

/// Closest point `closest` on x^2/e0^2 + y^2/e1^2 + z^2/e2^2 = 1 to `y`
/// (both in the ellipsoid's own frame, mm); returns the signed distance
/// (negative inside). Any radii order and any signs of y are accepted.
double ellipsoidClosestPoint(const Eigen::Vector3d& radii, const Eigen::Vector3d& y, Eigen::Vector3d& closest);

}  // namespace articula::distance
