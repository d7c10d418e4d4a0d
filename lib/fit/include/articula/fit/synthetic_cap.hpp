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

}  // namespace articula::fit
