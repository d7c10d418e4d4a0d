#pragma once
// Minimum signed distance between two ellipsoids by Newton on the
// support-function dual (the fast path computeContact takes for ellipsoid
// pairs unless ContactOptions::solver asks for the common-normal system):
//   s(v) = v . (c_B - c_A) - sqrt(v' M_A v) - sqrt(v' M_B v),  M = R D^2 R^T,
//   signed distance = max over unit v of s(v).
// s is concave and 1-homogeneous on R^3, so s(v) <= grad s(w) . v for every
// v and w. A stationary point on the unit sphere with s > 0 is therefore the
// global maximum (a certificate for separated pairs), and grad s(w) bounds s
// on a cap around w, which discards most of the sphere for overlapping pairs.
// At a stationary unit v, the support points x_A(v), x_B(-v) are the
// common-normal pair of eq. 5.23 with n_A = v.
//
// Ascent: Riemannian Newton on the sphere (2x2 system in the Householder
// tangent frame of v, Hessian shifted to negative definite where the sphere's
// curvature makes it indefinite, backtracking on s), stopped when the
// tangential gradient |(I - v v^T) grad s| falls below 1e-11 of the length
// scale; the distance error is quadratic in it.
// Cold: ascend from the centre direction when s > 0 there (separated).
// Otherwise (and for warm starts that end in overlap) the dual is sampled on
// `sample_directions` antipodal directions; Newton ascends from the sampled
// local maxima whose cap bound can beat the best maximum found, best first.
#include "articula/contact/common_normal.hpp"

namespace articula::contact {

/// As computeContact for two quadrics (throws UsageError otherwise);
/// `warm_start` seeds the ascent with its normal.
ContactResult ellipsoidContact(const ConvexShape& a, const ConvexShape& b, const ContactOptions& options = {},
                               const ContactResult* warm_start = nullptr);

}  // namespace articula::contact
