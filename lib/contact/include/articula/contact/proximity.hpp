#pragma once
// Broad-phase proximity queries (thesis section 5.2.4): yes/no answers that
// let the narrow phase (computeContact) run only for pairs that may touch.
#include <Eigen/Core>

#include "articula/contact/convex_shape.hpp"

namespace articula::contact {

/// Bounding-sphere test: true if the spheres about the centres holding each
/// body overlap (|c_B - c_A| <= R_A + R_B), i.e. the bodies MAY touch.
bool boundingSpheresOverlap(const ConvexShape& a, const ConvexShape& b);

enum class EllipsoidRelation { Separated, Touching, Overlapping };
const char* relationName(EllipsoidRelation relation);  // "separated", "touching", "overlapping"

/// Exact separation test for two ellipsoids (Wang, Wang & Kim 2001, as used by
/// Choi et al. 2009): with X^T A X < 0 the interiors in homogeneous
/// coordinates, the ellipsoids are separated iff det(lambda A + B) = 0 has two
/// distinct positive roots, and touch externally iff it has a positive double
/// root (roots closer than `relative_tolerance` count as double). Throws
/// UsageError unless both shapes are quadrics (exponents 2).
EllipsoidRelation ellipsoidRelation(const ConvexShape& a, const ConvexShape& b, double relative_tolerance = 1e-9);

/// The 4x4 homogeneous matrix of an ellipsoid, X^T A X = F(x) with X = [x; 1].
Eigen::Matrix4d homogeneousMatrix(const ConvexShape& ellipsoid);

}  // namespace articula::contact
