#pragma once
// A slow, independent reference for convex pairs (tests and benchmarks):
// the support-function dual
//   d = max_|v|=1 [ v . (c_B - c_A) - h_A(v) - h_B(-v) ]
// (for ellipsoids h(v) = v . c + sqrt(v' M v), M = R D^2 R^T), which is the
// signed distance (minus the penetration depth on overlap), in long double: a
// dense Fibonacci sample of v, then an adaptive hill climb from the best
// `starts` samples, each polished by Gauss-Newton on the common-normal
// conditions in canonical coordinates (central differences; kept only when it
// reaches a contact pair, whose distance is a value of the dual). Superellipsoid
// support points come from plain Newton on the convex Lagrange equation in
// long double. Shares no code with the solvers.
#include "articula/contact/convex_shape.hpp"

namespace articula::contact {

/// Signed distance of two spheres / ellipsoids / superellipsoids (thesis form), mm.
double referenceConvexDistance(const ConvexShape& a, const ConvexShape& b, int samples = 4000, int starts = 6);

/// Signed distance of two ellipsoids (exponents 2; UsageError otherwise), mm.
double referenceEllipsoidDistance(const ConvexShape& a, const ConvexShape& b, int samples = 4000, int starts = 6);

}  // namespace articula::contact
