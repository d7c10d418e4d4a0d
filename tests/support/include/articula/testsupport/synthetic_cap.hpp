#pragma once
// Synthetic articular caps of known shapes, for tests and benchmarks.
#include <Eigen/Core>

#include "articula/geometry/shape.hpp"

namespace articula::fit {

/// `n` points (#n x 3, mm) on the cap of `shape` within `half_angle` (rad)
/// of its local +z axis: a golden-angle spiral of directions from the local
/// origin, each projected onto the surface by bisection, then moved along
/// the surface normal by Gaussian noise of `sigma` mm (seeded by `seed`).
Eigen::MatrixX3d syntheticCap(const geometry::ShapeParameters& shape, double half_angle, int n, double sigma,
                              unsigned seed);

/// A Gaussian random field over `points` (#P x 3, mm) of covariance
/// sigma^2 exp(-h / length_mm) for points h apart (the Cholesky factor of the
/// covariance times seeded standard normals; a few thousand points at most).
Eigen::VectorXd exponentialField(const Eigen::MatrixX3d& points, double sigma, double length_mm, unsigned seed);

/// syntheticCap's exact points moved along the surface normal by such a
/// field: errors that neighbouring points share, as on a CT surface.
Eigen::MatrixX3d correlatedCap(const geometry::ShapeParameters& shape, double half_angle, int n, double sigma,
                               double length_mm, unsigned seed);

/// A random head-like shape of `model` for oracle benchmarks and tests
/// (deterministic for `seed`): radii r0 (18-28 mm) times factors within
/// `radius_spread` of each other (0.03: as near-spherical as real femoral
/// heads), exponents 2-3, ovoid coefficients c1 0-0.1 and c2, c3 within
/// +-0.03, a uniformly random orientation, a centre within 50 mm of the origin.
geometry::ShapeParameters randomHeadShape(geometry::ShapeModel model, double radius_spread, unsigned seed);

}  // namespace articula::fit
