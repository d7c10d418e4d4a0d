#pragma once
// Closed-form contact with a plane (thesis section 5.3). The plane is the
// boundary of the half-space body {x : n . (x - p) <= 0}: its outward normal
// is n, so a shape above the plane (on the side n points to) is separated.
#include <Eigen/Core>

#include "articula/contact/common_normal.hpp"
#include "articula/contact/convex_shape.hpp"

namespace articula::contact {

/// Eq. 5.8: signed distance from `point` to the plane through `plane_point`
/// with normal `plane_normal` (any non-zero length), positive on the side the
/// normal points to.
double pointPlaneDistance(const Eigen::Vector3d& point, const Eigen::Vector3d& plane_point,
                          const Eigen::Vector3d& plane_normal);

/// Sphere / ellipsoid / superellipsoid (thesis form) against a plane. The two
/// common-normal candidates are the points with outward normal -n and +n
/// (u and -u by central symmetry, eq. 5.15); the answer is the one with the
/// smaller signed distance. For unequal exponents the point comes from the
/// support mapping's monotone 1-D root find. point_a is on the shape,
/// point_b its projection on the plane, normal = -n (outward of the shape).
/// Throws InvalidParameter for a zero or non-finite normal.
ContactResult shapePlaneContact(const ConvexShape& shape, const Eigen::Vector3d& plane_point,
                                const Eigen::Vector3d& plane_normal);

/// Barr's superellipsoid (eq. 2.14, 0 < epsilon1, epsilon2 <= 1) against a
/// plane by the explicit angles of eq. 5.13-5.14 and the two candidates of
/// eq. 5.15. canonical_a holds the unit canonical point of the answer.
ContactResult barrPlaneContact(const Eigen::Vector3d& center, const Eigen::Matrix3d& rotation,
                               const Eigen::Vector3d& radii, double epsilon1, double epsilon2,
                               const Eigen::Vector3d& plane_point, const Eigen::Vector3d& plane_normal);

}  // namespace articula::contact
