#pragma once
// Algebraic (linear least-squares) sphere and ellipsoid fits: the starts of
// the fitting hierarchy (thesis section 3.2.4) and the articular selection's
// quick shapes.
#include <Eigen/Core>

#include "articula/geometry/shape.hpp"

namespace articula::geometry {

/// Algebraic sphere fit (Kasa): |x|^2 = 2 c.x + (r^2 - |c|^2) in the least-squares
/// sense over `points` (#P x 3, mm). Throws ProcessingError if degenerate.
ShapeParameters algebraicSphere(const Eigen::MatrixX3d& points);

/// Ellipsoid-specific algebraic fit (Li & Griffiths 2004, k = 4): the quadric
/// minimising the algebraic error under 4J - I^2 = 1, which is always an
/// ellipsoid when the axis ratio is >= 1/2. The local z axis is the principal
/// axis nearest the direction from the centre to the points' centroid, pointing
/// towards it (the axis of a cap; the ovoid's asymmetry runs along it).
/// Throws ProcessingError if the result is not an ellipsoid.
ShapeParameters algebraicEllipsoid(const Eigen::MatrixX3d& points);

}  // namespace articula::geometry
