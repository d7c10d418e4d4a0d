#pragma once
// |u|^g and its first two derivatives, evaluated as (u^2)^(g/2) (thesis
// section 2.3.3): no NaN for negative u, and exact values at u = 0 for g >= 2
// (the factor (u^2)^(g/2-1) is 1 for g = 2 and 0 for g > 2 there).
#include <cmath>

namespace articula::geometry {

struct AbsPower {
  double value;   // |u|^g
  double first;   // d/du  = g u |u|^(g-2)
  double second;  // d2/du2 = g (g-1) |u|^(g-2)
};

/// Requires g >= 2 (the shape models' validity checks guarantee it).
inline AbsPower absPower(double u, double g) {
  const double u2 = u * u;
  const double p = std::pow(u2, 0.5 * g - 1.0);  // |u|^(g-2)
  return {u2 * p, g * u * p, g * (g - 1.0) * p};
}

/// sign(u) |u|^e: the signed power of the parametric forms (eq. 2.16).
inline double signedPower(double u, double e) {
  return std::copysign(std::pow(std::fabs(u), e), u);
}

}  // namespace articula::geometry
