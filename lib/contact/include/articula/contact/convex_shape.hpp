#pragma once
// A centrally symmetric smooth convex body for contact: sphere, ellipsoid or
// superellipsoid in the thesis form (eq. 5.37), posed by a centre and a
// rotation. Evaluated in unit canonical coordinates u, with the global point
// x = R D u + c (D = diag(radii), mm, LPS):
//   F(u) = |u1|^g1 + |u2|^g2 + |u3|^g3 - 1   (g = 2 everywhere: ellipsoid).
// The Hessian is diagonal in u, which keeps the 6x6 Jacobian cheap. The
// geometry module's PosedSurface gives the same F (checked in the tests);
// this copy exists because the contact solver evaluates millions of times and
// needs the support mapping below, which the geometry module does not have.
#include <Eigen/Core>

#include "articula/geometry/shape.hpp"

namespace articula::contact {

struct ConvexShape {
  Eigen::Vector3d center = Eigen::Vector3d::Zero();            // c (mm)
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();      // R (columns: local axes)
  Eigen::Vector3d radii = Eigen::Vector3d::Ones();             // a, b, c (mm)
  Eigen::Vector3d exponents = Eigen::Vector3d::Constant(2.0);  // gamma1..3 (>= 2)
  bool quadric = true;                                         // all exponents == 2 (set by make)
};

/// Validates (radii finite > 0; exponents finite >= 2; rotation orthonormal
/// with det +1 to 1e-9; centre finite) and returns the shape; throws
/// InvalidParameter naming the first bad value.
ConvexShape makeConvexShape(const Eigen::Vector3d& center, const Eigen::Matrix3d& rotation,
                            const Eigen::Vector3d& radii,
                            const Eigen::Vector3d& exponents = Eigen::Vector3d::Constant(2.0));

/// From the fitting hierarchy's parameters: sphere, ellipsoid, superellipsoid.
/// Ovoid models are not centrally symmetric and throw UsageError.
ConvexShape shapeFromParameters(const geometry::ShapeParameters& p);

/// F, dF/du and the diagonal of d2F/du2 at canonical coordinates u.
struct CanonicalEvaluation {
  double value;
  Eigen::Vector3d gradient;
  Eigen::Vector3d hessian_diagonal;
  Eigen::Vector3d powers;  // |u_i|^(g_i - 2), from which the rest follows
};
CanonicalEvaluation evaluateCanonical(const ConvexShape& s, const Eigen::Vector3d& u);
/// The same, given the evaluation `near` at a nearby point u_near (a Newton
/// iterate's last): where u_i / u_near_i is within 1e-3 of 1, the power is
/// near's times (u_i / u_near_i)^(g_i - 2) by series, to rounding, without a
/// log and an exp (most of a superellipsoid evaluation's time).
CanonicalEvaluation evaluateCanonical(const ConvexShape& s, const Eigen::Vector3d& u, const Eigen::Vector3d& u_near,
                                      const CanonicalEvaluation& near);

/// x = R D u + c.
inline Eigen::Vector3d toGlobal(const ConvexShape& s, const Eigen::Vector3d& u) {
  return s.rotation * s.radii.cwiseProduct(u) + s.center;
}
/// u = D^-1 R^T (x - c).
inline Eigen::Vector3d toCanonical(const ConvexShape& s, const Eigen::Vector3d& x) {
  return (s.rotation.transpose() * (x - s.center)).cwiseQuotient(s.radii);
}

/// Support mapping: the canonical coordinates u of the surface point whose
/// outward normal is the global direction v (any non-zero length), i.e. the
/// maximiser of v . x over the body. Closed form for quadrics; for unequal
/// exponents a monotone one-dimensional Newton root find in log space
/// (converges from the right, to rounding, in a few steps).
Eigen::Vector3d supportCanonical(const ConvexShape& s, const Eigen::Vector3d& v);

/// A lower bound of the least principal radius of curvature of the surface
/// (exact for ellipsoids: r_min^2 / r_max). By Blaschke's rolling theorem the
/// body is then another convex body plus a ball of this radius, which is what
/// the overlap certificate of computeContact rests on.
double leastRadiusOfCurvature(const ConvexShape& s);

/// Radius of the smallest sphere about the centre holding the body
/// (for a superellipsoid with exponents >= 2: |radii|, a bound; exact for quadrics: max radius).
double boundingRadius(const ConvexShape& s);

}  // namespace articula::contact
