#pragma once
// Algebraic (Kasa) least-squares sphere: |x|^2 = 2 c . x + (r^2 - |c|^2) is
// linear in the centre c and the constant, solved by column-pivoting QR on
// points centred on their centroid and scaled to unit RMS (for conditioning).
// The start of the fitting hierarchy (thesis section 3.2.4), the sample
// stage's articular sphere and the segment stage's head refinement.
#include <Eigen/Core>

namespace articula::geometry {

struct Sphere {
  Eigen::Vector3d center = Eigen::Vector3d::Zero();  // mm
  double radius = 0.0;                               // mm
};

/// The least-squares algebraic sphere through the rows of `points` (#P x 3,
/// mm). Throws ProcessingError for fewer than 4 points, coincident points or
/// a degenerate system (no real sphere).
Sphere fitSphere(const Eigen::MatrixX3d& points);

}  // namespace articula::geometry
