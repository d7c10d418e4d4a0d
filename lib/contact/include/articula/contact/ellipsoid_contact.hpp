#pragma once
// Minimum signed distance between two ellipsoids by Newton on the
// support-function dual (the fast path computeContact takes for ellipsoid
// pairs unless ContactOptions::solver asks for the common-normal system):
//   s(v) = v . (c_B - c_A) - sqrt(v' M_A v) - sqrt(v' M_B v),  M = R D^2 R^T,
//   signed distance = max over unit v of s(v).
// s is concave and 1-homogeneous on R^3, so s(v) <= grad s(w) . v for every
// v and w. A stationary point on the unit sphere with s > 0 is therefore the
// global maximum (a certificate for separated pairs). At a stationary unit v,
// the support points x_A(v), x_B(-v) are the common-normal pair of eq. 5.23
// with n_A = v.
//
// Ascent: Riemannian Newton on the sphere. s's Hessian in R^3 annihilates v,
// so H - s I + (s - L) v v' is the tangent Hessian plus a fixed eigenvalue
// -L along v, and one 3x3 solve gives the tangent step without a tangent
// frame; it is shifted to negative definite where the sphere's curvature
// makes it indefinite (overlap), with backtracking on s. Stopped when the
// tangential gradient |(I - v v^T) grad s| falls below 1e-11 of the length
// scale; the distance error is quadratic in it.
//
// Curvature certificate (overlap): along every great circle s'' + s is
// minus the sum of the two bodies' radii of curvature there (of their
// projections on the circle's plane), at most -k with k = r_min^2 / r_max of
// A plus that of B. From a stationary point v*, s(phi) <= (s* + k) cos phi - k
// (Sturm comparison), below s* everywhere else when s* > -k: an overlap
// shallower than k has a single local maximum, the global one.
//
// Cold: ascend from the centre direction when s > 0 there (separated), or
// s > -k (the ascent only climbs, so it ends above -k: certified).
// Deeper overlap: the dual is bounded on the cap (covering radius rho) of each of
// `sample_directions` antipodal samples: along a great circle s'' = -s - k_A
// - k_B, with k the support functions' curvature, at least
// (r_min r_mid)^2 / |L v|^3 (L = D R^T), so s <= (s_0 + K) cos phi + G sin phi
// - K (Sturm comparison). Newton ascends from the best sample, then from the
// sample of the highest bound while any bound beats the best maximum found;
// samples within 2 rho of a maximum reached are taken to lie in its basin
// (the search's one assumption). Ascents give up early when heading for a
// known maximum or when their Newton model cannot beat the best.
// Warm: one ascent from the previous normal. Separated or above -k: certified as above.
// Deeper overlap: the answer stands while what the last global search saw, moved
// since by at most |delta c| + |delta L_A|_F + |delta L_B|_F, stays below it
// (its rivals, 8 watched caps, bounded again and split into 7 smaller caps
// twice where needed, and one bound for the rest: DualSearchState);
// otherwise the global search runs again.
#include "articula/contact/common_normal.hpp"

namespace articula::contact {

/// As computeContact for two quadrics (throws UsageError otherwise);
/// `warm_start` seeds the ascent with its normal.
ContactResult ellipsoidContact(const ConvexShape& a, const ConvexShape& b, const ContactOptions& options = {},
                               const ContactResult* warm_start = nullptr);

}  // namespace articula::contact
