#pragma once
// Directions spread evenly over the unit sphere, or over its cap z >= z_min:
// the Fibonacci (golden-angle) lattice, with point i at height
// z_i = 1 - (1 - z_min)(i + 1/2) / count (equal areas) and azimuth i times
// the golden angle. The contact search's samples, its common-normal starts
// and the synthetic articular caps of the fit tests.
#include <algorithm>
#include <cmath>

#include <Eigen/Core>

namespace articula::geometry {

/// Direction i (0 <= i < count) of the lattice of `count` on the cap
/// z >= z_min (z_min = -1: the whole sphere; 0: the upper half).
inline Eigen::Vector3d fibonacciDirection(int i, int count, double z_min = -1.0) {
  const double golden_angle = M_PI * (3.0 - std::sqrt(5.0));
  const double z = 1.0 - (1.0 - z_min) * (i + 0.5) / count;
  const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
  return {r * std::cos(golden_angle * i), r * std::sin(golden_angle * i), z};
}

}  // namespace articula::geometry
