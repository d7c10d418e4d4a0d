#pragma once
// A slow, independent reference for ellipsoid pairs (tests and benchmarks):
// the support-function dual
//   d = max_|v|=1 [ v . (c_B - c_A) - sqrt(v' M_A v) - sqrt(v' M_B v) ],  M = R D^2 R^T,
// which is the signed distance (minus the penetration depth on overlap), in
// long double: a dense Fibonacci sample of v, then an adaptive hill climb
// from the best `starts` samples. Shares no code with the Newton solver.
#include "articula/contact/convex_shape.hpp"

namespace articula::contact {

/// Signed distance of two ellipsoids (exponents 2; UsageError otherwise), mm.
double referenceEllipsoidDistance(const ConvexShape& a, const ConvexShape& b, int samples = 4000, int starts = 6);

}  // namespace articula::contact
