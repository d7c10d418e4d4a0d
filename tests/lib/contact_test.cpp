// Contact module: common-normal Newton solver, closed forms, proximity, scenarios.
// Ground truth: analytic spheres and planes, and for ellipsoid pairs the
// support-function dual max_v [v.(cB - cA) - sqrt(v'M_A v) - sqrt(v'M_B v)]
// evaluated in long double by dense sampling plus a local ascent.
#include <cmath>
#include <random>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "articula/contact/common_normal.hpp"
#include "articula/contact/frame_derivatives.hpp"
#include "articula/contact/plane_contact.hpp"
#include "articula/contact/proximity.hpp"
#include "articula/testsupport/contact_reference.hpp"
#include "articula/contact/scenario.hpp"
#include "articula/core/error.hpp"
#include "articula/geometry/surfaces.hpp"

namespace {

using namespace articula::contact;
using articula::geometry::FrameMethod;
using Eigen::Matrix3d;
using Eigen::Vector3d;

Matrix3d randomRotation(std::mt19937_64& rng) {
  std::normal_distribution<double> g;
  return Eigen::Quaterniond(g(rng), g(rng), g(rng), g(rng)).normalized().toRotationMatrix();
}

ConvexShape randomShape(std::mt19937_64& rng, double r_min, double r_max, double g_max = 2.0) {
  std::uniform_real_distribution<double> r(r_min, r_max), g(2.0, g_max);
  const Vector3d exps = g_max > 2.0 ? Vector3d(g(rng), g(rng), g(rng)) : Vector3d::Constant(2.0);
  return makeConvexShape(Vector3d::Zero(), randomRotation(rng), Vector3d(r(rng), r(rng), r(rng)), exps);
}

double referenceDistance(const ConvexShape& a, const ConvexShape& b) { return referenceEllipsoidDistance(a, b); }

// ---------------------------------------------------------------- shape pieces

TEST(ConvexShape, MatchesGeometryModule) {
  std::mt19937_64 rng(1);
  for (double g_max : {2.0, 4.0}) {
    ConvexShape s = randomShape(rng, 0.5, 2.0, g_max);
    s.center = Vector3d(1, -2, 3);
    articula::geometry::Pose pose;
    pose.rotation = s.rotation, pose.translation = s.center, pose.scale = s.radii;
    const articula::geometry::Superellipsoid ref(pose, s.exponents);
    std::normal_distribution<double> g;
    for (int i = 0; i < 50; ++i) {
      const Vector3d u(g(rng), g(rng), g(rng));
      const auto e = evaluateCanonical(s, u);
      const auto r = ref.evaluateCanonical(u, 2);
      EXPECT_NEAR(e.value, r.value, 1e-12 * (1 + std::fabs(r.value)));
      EXPECT_LT((e.gradient - r.gradient).norm(), 1e-11 * (1 + r.gradient.norm()));
      EXPECT_LT((e.hessian_diagonal - r.hessian.diagonal()).norm(), 1e-11 * (1 + r.hessian.norm()));
      EXPECT_LT((toGlobal(s, u) - pose.toGlobal(u)).norm(), 1e-12);
    }
  }
}

TEST(ConvexShape, EvaluationFromANearbyPointMatchesTheDirectOne) {
  // The powers |u_i|^(g_i - 2) updated by series from a nearby point (ratios
  // within 1e-3 of 1), chained as a Newton solve chains them, or taken afresh
  // (farther, a zero coordinate, a sign change) agree with the direct evaluation to rounding.
  std::mt19937_64 rng(11);
  std::normal_distribution<double> g;
  std::uniform_real_distribution<double> relative(-2e-3, 2e-3);
  for (double g_max : {2.0, 4.0, 12.0}) {
    const ConvexShape s = randomShape(rng, 0.5, 2.0, g_max);
    for (int i = 0; i < 50; ++i) {
      Vector3d u(g(rng), g(rng), g(rng));
      if (i % 10 == 0) u[i % 3] = 0.0;
      CanonicalEvaluation chained = evaluateCanonical(s, u);
      for (int step = 0; step < 4; ++step) {
        Vector3d next = u;
        for (int k = 0; k < 3; ++k) next[k] *= 1.0 + relative(rng) * (step < 2 ? 1.0 : 1e-3);
        if (i % 10 == 5 && step == 1) next[1] = -next[1];
        chained = evaluateCanonical(s, next, u, chained);
        const auto direct = evaluateCanonical(s, next);
        EXPECT_NEAR(chained.value, direct.value, 4e-15 * (1 + std::fabs(direct.value)));
        for (int k = 0; k < 3; ++k) {
          // A few ulps for the chain, plus the direct evaluation's own error:
          // its log's rounding times (g/2 - 1).
          const double amplified = std::fabs((0.5 * s.exponents[k] - 1.0) * std::log(next[k] * next[k]));
          EXPECT_NEAR(chained.powers[k], direct.powers[k],
                      (2e-15 + 4.4e-16 * (std::isfinite(amplified) ? amplified : 0.0)) * direct.powers[k])
              << "g " << s.exponents[k] << " u " << next[k];
        }
        EXPECT_LT((chained.gradient - direct.gradient).norm(), 4e-15 * direct.gradient.norm() + 1e-300);
        u = next;
      }
    }
  }
}

TEST(ConvexShape, SupportPointHasTheGivenNormal) {
  std::mt19937_64 rng(2);
  std::normal_distribution<double> g;
  for (int i = 0; i < 200; ++i) {
    const ConvexShape s = randomShape(rng, 0.3, 3.0, 5.0);
    const Vector3d v = Vector3d(g(rng), g(rng), g(rng)).normalized();
    const Vector3d u = supportCanonical(s, v);
    const auto e = evaluateCanonical(s, u);
    EXPECT_NEAR(e.value, 0.0, 1e-13);
    const Vector3d n = (s.rotation * e.gradient.cwiseQuotient(s.radii)).normalized();
    EXPECT_GT(n.dot(v), 1.0 - 1e-13);
  }
}

TEST(ConvexShape, SupportPointOfANearlyAxialDirectionIsFinite) {
  // Components far below the largest (down to subnormal ratios) and exact
  // zeros: the support point stays on the surface with the given normal.
  const ConvexShape s = makeConvexShape(Vector3d::Zero(), Matrix3d::Identity(), Vector3d(1, 2, 3), Vector3d(40, 3, 2));
  for (const Vector3d& v : {Vector3d(1, 1e-310, 0), Vector3d(1e-320, -1, 1e-200), Vector3d(0, 0, -1)}) {
    const Vector3d u = supportCanonical(s, v);
    ASSERT_TRUE(u.allFinite()) << v.transpose();
    EXPECT_NEAR(evaluateCanonical(s, u).value, 0.0, 1e-13);
    const Vector3d n = (s.rotation * evaluateCanonical(s, u).gradient.cwiseQuotient(s.radii)).normalized();
    EXPECT_GT(n.dot(v.normalized()), 1.0 - 1e-13);
  }
}

// The least principal radius of curvature over the surface, from the shape
// operator at the support points of a dense set of directions.
double sampledLeastRadiusOfCurvature(const ConvexShape& s, int directions) {
  double least = INFINITY;
  for (int k = 0; k < directions; ++k) {
    const double z = 1.0 - (2.0 * k + 1.0) / directions, r = std::sqrt(1 - z * z), t = 2.399963229728653 * k;
    const Vector3d u = supportCanonical(s, Vector3d(r * std::cos(t), r * std::sin(t), z));
    const CanonicalEvaluation e = evaluateCanonical(s, u);
    const Vector3d gradient = s.rotation * e.gradient.cwiseQuotient(s.radii);
    const Matrix3d hessian = s.rotation * e.hessian_diagonal.cwiseQuotient(s.radii.cwiseProduct(s.radii)).asDiagonal() *
                             s.rotation.transpose();
    const Vector3d n = gradient.normalized();
    const Matrix3d tangent = Matrix3d::Identity() - n * n.transpose();
    const Matrix3d shape_operator = tangent * hessian * tangent / gradient.norm();
    least = std::min(least, 1.0 / Eigen::SelfAdjointEigenSolver<Matrix3d>(shape_operator).eigenvalues().maxCoeff());
  }
  return least;
}

TEST(ConvexShape, LeastRadiusOfCurvatureIsALowerBound) {
  // Exact for ellipsoids; below the sampled least radius for superellipsoids
  // (exponents up to 12, mixed with 2), and not far below it at exponents 2-4.
  std::mt19937_64 rng(14);
  for (int i = 0; i < 20; ++i) {
    const ConvexShape s = randomShape(rng, 0.2, 2.0);
    EXPECT_NEAR(leastRadiusOfCurvature(s), std::pow(s.radii.minCoeff(), 2) / s.radii.maxCoeff(), 1e-14);
  }
  for (double g_max : {4.0, 12.0}) {
    double worst_ratio = INFINITY;
    for (int i = 0; i < 60; ++i) {
      ConvexShape s = randomShape(rng, 0.2, 2.0, g_max);
      if (i % 4 == 0) s.exponents[i % 3] = 2.0;
      const double bound = leastRadiusOfCurvature(s), sampled = sampledLeastRadiusOfCurvature(s, 20000);
      EXPECT_GT(bound, 0.0);
      EXPECT_LE(bound, sampled) << "radii " << s.radii.transpose() << " exponents " << s.exponents.transpose();
      worst_ratio = std::min(worst_ratio, sampled / bound);
    }
    if (g_max == 4.0) {
      EXPECT_LT(worst_ratio, 2.0);
    }
  }
}

TEST(ConvexShape, RejectsBadParameters) {
  EXPECT_THROW(makeConvexShape(Vector3d::Zero(), Matrix3d::Identity(), Vector3d(1, 0, 1)), articula::InvalidParameter);
  EXPECT_THROW(makeConvexShape(Vector3d::Zero(), Matrix3d::Identity(), Vector3d(1, 1, 1), Vector3d(2, 1.5, 2)),
               articula::InvalidParameter);
  EXPECT_THROW(makeConvexShape(Vector3d(NAN, 0, 0), Matrix3d::Identity(), Vector3d(1, 1, 1)), articula::InvalidParameter);
  EXPECT_THROW(makeConvexShape(Vector3d::Zero(), 2.0 * Matrix3d::Identity(), Vector3d(1, 1, 1)), articula::InvalidParameter);
}

TEST(Frames, DerivativesMatchFiniteDifferences) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> g;
  for (FrameMethod m : {FrameMethod::Householder, FrameMethod::SquarePlate}) {
    for (int i = 0; i < 100; ++i) {
      const Vector3d n = Vector3d(g(rng), g(rng), g(rng)).normalized();
      const FrameWithDerivatives f = frameWithDerivatives(n, m);
      EXPECT_NEAR(f.t.dot(n), 0.0, 1e-14);
      EXPECT_NEAR(f.b.dot(n), 0.0, 1e-14);
      EXPECT_LT((f.t.cross(f.b) - n).norm(), 1e-14);
      // Along tangent directions of the sphere (where the formulas live).
      for (const Vector3d& dir : {f.t, f.b}) {
        const double h = 1e-6;
        const Vector3d np = (n + h * dir).normalized(), nm = (n - h * dir).normalized();
        const FrameWithDerivatives fp = frameWithDerivatives(np, m), fm = frameWithDerivatives(nm, m);
        if ((np.x() > 0) != (nm.x() > 0) || (np.x() * np.y() >= 0) != (nm.x() * nm.y() >= 0)) continue;  // branch
        EXPECT_LT(((fp.t - fm.t) / (2 * h) - f.dt_dn * dir).norm(), 1e-7);
        EXPECT_LT(((fp.b - fm.b) / (2 * h) - f.db_dn * dir).norm(), 1e-7);
      }
    }
  }
}

TEST(CommonNormal, AnalyticJacobianMatchesFiniteDifferences) {
  std::mt19937_64 rng(4);
  std::normal_distribution<double> g;
  for (FrameMethod m : {FrameMethod::Householder, FrameMethod::SquarePlate}) {
    for (int i = 0; i < 40; ++i) {
      ConvexShape a = randomShape(rng, 0.5, 1.5, 4.0), b = randomShape(rng, 0.5, 1.5, 2.0);
      b.center = Vector3d(g(rng), g(rng), g(rng)) * 2.0;
      const Vector3d ua = Vector3d(g(rng), g(rng), g(rng)) * 0.6, ub = Vector3d(g(rng), g(rng), g(rng)) * 0.6;
      Vector6d phi, p1, p2;
      Matrix6d J, dummy;
      commonNormalSystem(a, b, ua, ub, m, 1.7, phi, J);
      for (int k = 0; k < 6; ++k) {
        const double h = 1e-6;
        Vector6d q;
        q << ua, ub;
        Vector6d qp = q, qm = q;
        qp[k] += h, qm[k] -= h;
        commonNormalSystem(a, b, qp.head<3>(), qp.tail<3>(), m, 1.7, p1, dummy);
        commonNormalSystem(a, b, qm.head<3>(), qm.tail<3>(), m, 1.7, p2, dummy);
        const Vector6d fd = (p1 - p2) / (2 * h);
        if ((p1 - p2).cwiseAbs().maxCoeff() > 0.5) continue;  // frame branch switched between samples
        EXPECT_LT((fd - J.col(k)).norm(), 2e-6 * (1 + J.col(k).norm())) << "column " << k;
      }
    }
  }
}

// ---------------------------------------------------------------- spheres and planes

TEST(Contact, SpheresAnalytic) {
  const Matrix3d I = Matrix3d::Identity();
  const ConvexShape a = makeConvexShape(Vector3d(1, 2, 3), I, Vector3d::Constant(2.0));
  const Vector3d dir = Vector3d(1, -2, 0.5).normalized();
  for (double gap : {3.0, 0.1, 1e-6, 0.0, -1e-6, -0.3, -2.5}) {
    const ConvexShape b = makeConvexShape(a.center + dir * (3.0 + gap), I, Vector3d::Constant(1.0));
    const ContactResult r = computeContact(a, b);
    EXPECT_EQ(r.summary.status, ContactStatus::Converged) << r.summary.briefReport();
    EXPECT_NEAR(r.distance, gap, 1e-12) << "gap " << gap;
    EXPECT_LT((r.normal - dir).norm(), 1e-9);
    EXPECT_LT((r.point_a - (a.center + 2.0 * dir)).norm(), 1e-9);
    EXPECT_LT((r.point_b - (b.center - 1.0 * dir)).norm(), 1e-9);
  }
}

TEST(Contact, PointPlane) {
  EXPECT_DOUBLE_EQ(pointPlaneDistance(Vector3d(1, 2, 5), Vector3d(0, 0, 2), Vector3d(0, 0, 3)), 3.0);
  EXPECT_DOUBLE_EQ(pointPlaneDistance(Vector3d(1, 2, -1), Vector3d(0, 0, 2), Vector3d(0, 0, 1)), -3.0);
}

TEST(Contact, AxisAlignedEllipsoidAndPlane) {
  // Ellipsoid radii (3, 2, 1) at height h over the plane z = 0: distance h - 1.
  for (double h : {5.0, 1.0, 0.5, -0.5}) {
    const ConvexShape e = makeConvexShape(Vector3d(1, 1, h), Matrix3d::Identity(), Vector3d(3, 2, 1));
    const ContactResult r = shapePlaneContact(e, Vector3d(7, -3, 0), Vector3d(0, 0, 2));
    EXPECT_NEAR(r.distance, h - 1.0, 1e-14);
    EXPECT_LT((r.point_a - Vector3d(1, 1, h - 1)).norm(), 1e-14);
    EXPECT_LT((r.point_b - Vector3d(1, 1, 0)).norm(), 1e-14);
  }
  // Tilted plane z = x: distance of an ellipsoid at the origin is -support along n.
  const ConvexShape e = makeConvexShape(Vector3d::Zero(), Matrix3d::Identity(), Vector3d(3, 2, 1));
  const Vector3d n = Vector3d(-1, 0, 1).normalized();
  const double h = std::sqrt(9 * n.x() * n.x() + n.z() * n.z());
  EXPECT_NEAR(shapePlaneContact(e, Vector3d::Zero(), n).distance, -h, 1e-14);
}

TEST(Contact, SuperellipsoidPlaneMatchesDenseSearch) {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> g;
  for (int i = 0; i < 20; ++i) {
    ConvexShape s = randomShape(rng, 0.5, 2.0, 4.0);
    s.center = Vector3d(g(rng), g(rng), g(rng));
    const Vector3d n = Vector3d(g(rng), g(rng), g(rng)).normalized(), p(g(rng), g(rng), g(rng));
    const ContactResult r = shapePlaneContact(s, p, n);
    // On the surface, on the plane, normal -n.
    EXPECT_NEAR(evaluateCanonical(s, toCanonical(s, r.point_a)).value, 0.0, 1e-12);
    EXPECT_NEAR(n.dot(r.point_b - p), 0.0, 1e-12);
    // Dense parametric sample (geometry module) never goes lower.
    articula::geometry::Pose pose;
    pose.rotation = s.rotation, pose.translation = s.center, pose.scale = s.radii;
    const articula::geometry::Superellipsoid ref(pose, s.exponents);
    double lowest = 1e300;
    for (int ia = 0; ia < 400; ++ia)
      for (int il = 0; il <= 200; ++il)
        lowest = std::min(lowest, n.dot(pose.toGlobal(ref.canonicalPoint(-M_PI + 2 * M_PI * ia / 400.0,
                                                                          -M_PI / 2 + M_PI * il / 200.0)) - p));
    EXPECT_LE(r.distance, lowest + 1e-12);
    EXPECT_GT(r.distance, lowest - 2e-3);
  }
}

TEST(Contact, BarrPlaneClosedForm) {
  std::mt19937_64 rng(6);
  std::normal_distribution<double> g;
  std::uniform_real_distribution<double> e(0.3, 1.0);
  for (int i = 0; i < 50; ++i) {
    const double e1 = e(rng), e2 = e(rng);
    const Vector3d radii(0.5 + std::fabs(g(rng)), 0.5 + std::fabs(g(rng)), 0.5 + std::fabs(g(rng)));
    const Matrix3d R = randomRotation(rng);
    const Vector3d c(g(rng), g(rng), g(rng)), n = Vector3d(g(rng), g(rng), g(rng)).normalized(), p(g(rng), g(rng), g(rng));
    const ContactResult r = barrPlaneContact(c, R, radii, e1, e2, p, n);
    articula::geometry::Pose pose;
    pose.rotation = R, pose.translation = c, pose.scale = radii;
    const articula::geometry::BarrSuperellipsoid barr(pose, e1, e2);
    const auto ev = barr.evaluate(r.point_a, 1);
    EXPECT_NEAR(ev.value, 0.0, 1e-10);
    EXPECT_GT(ev.gradient.normalized().dot(-n), 1.0 - 1e-10) << "e1 " << e1 << " e2 " << e2;
    EXPECT_NEAR(r.distance, n.dot(r.point_a - p), 1e-12);
  }
  // e1 = e2 = 1 is the ellipsoid.
  const ConvexShape ell = makeConvexShape(Vector3d(1, 2, 3), Matrix3d::Identity(), Vector3d(3, 2, 1));
  const Vector3d n = Vector3d(1, 2, -2).normalized();
  EXPECT_NEAR(barrPlaneContact(ell.center, ell.rotation, ell.radii, 1, 1, Vector3d::Zero(), n).distance,
              shapePlaneContact(ell, Vector3d::Zero(), n).distance, 1e-13);
  // The pole (0, 0, c): 0/0 in eq. 5.14.
  EXPECT_NEAR(barrPlaneContact(Vector3d::Zero(), Matrix3d::Identity(), Vector3d(1, 1, 2), 0.5, 0.7,
                               Vector3d(0, 0, -3), Vector3d(0, 0, 1)).distance, 1.0, 1e-14);
}

// ---------------------------------------------------------------- ellipsoid pairs

// Places b so that the reference distance lands near `target` (separated > 0, overlap < 0).
void placeAt(ConvexShape& a, ConvexShape& b, std::mt19937_64& rng, double target) {
  std::normal_distribution<double> g;
  const Vector3d dir = Vector3d(g(rng), g(rng), g(rng)).normalized();
  // Centre distance where the extents along dir sum to the target gap.
  const double ea = dir.dot(toGlobal(a, supportCanonical(a, dir)) - a.center);
  const double eb = -dir.dot(toGlobal(b, supportCanonical(b, -dir)) - b.center);
  b.center = a.center + dir * (ea + eb + target);
}

// b one motion step earlier: `step` mm away and turned by `step` rad, both
// along random directions (drawn with g on rng), as the bench's warm starts.
ConvexShape stepBack(const ConvexShape& b, std::mt19937_64& rng, std::normal_distribution<double>& g, double step) {
  ConvexShape before = b;
  before.center += step * Vector3d(g(rng), g(rng), g(rng)).normalized();
  before.rotation = Eigen::AngleAxisd(step, Vector3d(g(rng), g(rng), g(rng)).normalized()) * before.rotation;
  return before;
}

struct PairClass {
  const char* name;
  double gap_min, gap_max;
};

TEST(Contact, EllipsoidPairsAgainstReference) {
  std::mt19937_64 rng(7);
  for (const PairClass& c : {PairClass{"separated", 0.05, 1.0}, PairClass{"shallow", -0.05, 0.0},
                             PairClass{"deep", -1.0, -0.2}}) {
    std::uniform_real_distribution<double> gap(c.gap_min, c.gap_max);
    double worst = 0.0;
    for (int i = 0; i < 60; ++i) {
      ConvexShape a = randomShape(rng, 0.5, 1.5), b = randomShape(rng, 0.5, 1.5);
      placeAt(a, b, rng, gap(rng));
      const double ref = referenceDistance(a, b);
      const ContactResult r = computeContact(a, b);
      EXPECT_EQ(r.summary.status, ContactStatus::Converged) << c.name << " " << r.summary.briefReport();
      worst = std::max(worst, std::fabs(r.distance - ref));
      EXPECT_NEAR(r.distance, ref, 1e-10) << c.name << " pair " << i << ": " << r.summary.briefReport();
      // The pair is a common-normal pair: both points on the surfaces, normals opposite, d along n.
      EXPECT_NEAR(evaluateCanonical(a, toCanonical(a, r.point_a)).value, 0.0, 1e-10);
      EXPECT_NEAR(evaluateCanonical(b, toCanonical(b, r.point_b)).value, 0.0, 1e-10);
      EXPECT_LT(((r.point_b - r.point_a) - r.distance * r.normal).norm(), 1e-9);
      // Swapping A and B: same distance, points swapped, normal reversed.
      const ContactResult s = computeContact(b, a);
      EXPECT_NEAR(s.distance, r.distance, 1e-10);
      if (c.gap_min >= 0.0) {  // unique answer when separated
        EXPECT_LT((s.point_a - r.point_b).norm(), 1e-7);
        EXPECT_LT((s.normal + r.normal).norm(), 1e-7);
      }
    }
    std::printf("  %s: worst |error| %.3g mm\n", c.name, worst);
  }
}

TEST(Contact, HighAspectEllipsoidsAgainstReference) {
  std::mt19937_64 rng(8);
  std::uniform_real_distribution<double> gap(-0.5, 0.5);
  for (int i = 0; i < 60; ++i) {
    ConvexShape a = randomShape(rng, 0.15, 1.5), b = randomShape(rng, 0.15, 1.5);
    placeAt(a, b, rng, gap(rng));
    const double ref = referenceDistance(a, b);
    const ContactResult r = computeContact(a, b);
    EXPECT_NEAR(r.distance, ref, 1e-10) << "pair " << i << ": " << r.summary.briefReport();
  }
}

TEST(Contact, SuperellipsoidPairsAreGlobalCommonNormalPairs) {
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> gap(-0.4, 0.4);
  for (int i = 0; i < 60; ++i) {
    ConvexShape a = randomShape(rng, 0.5, 1.5, 4.0), b = randomShape(rng, 0.5, 1.5, 4.0);
    placeAt(a, b, rng, gap(rng));
    const ContactResult r = computeContact(a, b);
    EXPECT_EQ(r.summary.status, ContactStatus::Converged) << r.summary.briefReport();
    EXPECT_NEAR(evaluateCanonical(a, toCanonical(a, r.point_a)).value, 0.0, 1e-9);
    EXPECT_NEAR(evaluateCanonical(b, toCanonical(b, r.point_b)).value, 0.0, 1e-9);
    EXPECT_LT(((r.point_b - r.point_a) - r.distance * r.normal).norm(), 1e-8);
    // The dual is a lower bound everywhere, and reaches the answer at the normal.
    double sampled = -1e300;
    for (int k = 0; k < 3000; ++k) {
      const double z = 1.0 - (2.0 * k + 1.0) / 3000, rr = std::sqrt(1 - z * z), t = 2.399963229728653 * k;
      sampled = std::max(sampled, dualSeparation(a, b, Vector3d(rr * std::cos(t), rr * std::sin(t), z)));
    }
    EXPECT_GE(r.distance, sampled - 1e-10) << "pair " << i << ": " << r.summary.briefReport();
    EXPECT_NEAR(dualSeparation(a, b, r.normal), r.distance, 1e-9);
  }
}

// About 100 superellipsoid pairs (exponents 2-4) against the long-double
// reference, cold and warm-started from one small motion step earlier (a
// smaller version of bench-contact's superellipsoid classes).
TEST(Contact, SuperellipsoidPairsAgainstReference) {
  std::mt19937_64 rng(10);
  std::normal_distribution<double> g;
  for (const PairClass& c : {PairClass{"separated", 0.01, 1.0}, PairClass{"shallow", -0.05, 0.0},
                             PairClass{"deep", -1.0, -0.1}}) {
    std::uniform_real_distribution<double> gap(c.gap_min, c.gap_max);
    double worst_cold = 0.0, worst_warm = 0.0;
    for (int i = 0; i < 34; ++i) {
      ConvexShape a = randomShape(rng, 0.5, 1.5, 4.0), b = randomShape(rng, 0.5, 1.5, 4.0);
      placeAt(a, b, rng, gap(rng));
      const double ref = referenceConvexDistance(a, b, 1500, 4);
      const ConvexShape before = stepBack(b, rng, g, 0.01);
      const ContactResult previous = computeContact(a, before);
      const ContactResult cold = computeContact(a, b), warm = computeContact(a, b, {}, &previous);
      EXPECT_EQ(cold.summary.status, ContactStatus::Converged) << c.name << " " << cold.summary.briefReport();
      EXPECT_NEAR(cold.distance, ref, 1e-9) << c.name << " pair " << i << ": " << cold.summary.briefReport();
      EXPECT_NEAR(warm.distance, ref, 1e-9) << c.name << " pair " << i << ": " << warm.summary.briefReport();
      worst_cold = std::max(worst_cold, std::fabs(cold.distance - ref));
      worst_warm = std::max(worst_warm, std::fabs(warm.distance - ref));
    }
    std::printf("  %s: worst |error| cold %.3g mm, warm %.3g mm\n", c.name, worst_cold, worst_warm);
  }
}

TEST(Contact, SymmetricConfigurationsWithSeveralSolutions) {
  // Fig. 5.13: a sphere and an aligned ellipsoid along a symmetry axis; the
  // centre start sits exactly on a common-normal solution.
  const Matrix3d I = Matrix3d::Identity();
  const ConvexShape sphere = makeConvexShape(Vector3d::Zero(), I, Vector3d::Constant(1.0));
  for (double gap : {0.5, -0.2}) {
    const ConvexShape ell = makeConvexShape(Vector3d(0, 0, 1 + 2 + gap), I, Vector3d(1, 1, 2));
    EXPECT_NEAR(computeContact(sphere, ell).distance, gap, 1e-12);
  }
  // Side by side along x: nearest points at x = 1 and x = 3 - 1.
  const ConvexShape ell = makeConvexShape(Vector3d(3.0, 0, 0), I, Vector3d(1, 1, 2));
  EXPECT_NEAR(computeContact(sphere, ell).distance, 1.0, 1e-12);
  // Concentric bodies: the depth is the smallest sum of extents, -(1 + 1).
  const ConvexShape inner = makeConvexShape(Vector3d::Zero(), I, Vector3d(1, 3, 2));
  EXPECT_NEAR(computeContact(sphere, inner).distance, -2.0, 1e-12);
}

// Random pairs placed with a gap in [gap_min, gap_max]: `other` gives the same
// answers as the default options (and both match the reference for ellipsoids).
void expectSameAnswers(const ContactOptions& other, unsigned seed, double r_min, double g_max, double gap_min,
                       double gap_max) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> gap(gap_min, gap_max);
  for (int i = 0; i < 40; ++i) {
    ConvexShape a = randomShape(rng, r_min, 1.5, g_max), b = randomShape(rng, r_min, 1.5, g_max);
    placeAt(a, b, rng, gap(rng));
    const ContactResult d = computeContact(a, b), o = computeContact(a, b, other);
    EXPECT_NEAR(d.distance, o.distance, 1e-10) << "pair " << i << ": " << o.summary.briefReport();
    if (d.distance > 0.0 || g_max > 2.0) {  // unique points when separated (and on these superellipsoid pairs)
      EXPECT_LT((d.point_a - o.point_a).norm(), 1e-6);
    }
    if (g_max == 2.0) {
      EXPECT_NEAR(d.distance, referenceDistance(a, b), 1e-10) << "pair " << i;
    }
  }
}

TEST(Contact, HouseholderAndSquarePlateAgree) {
  ContactOptions square_plate;
  square_plate.frame = FrameMethod::SquarePlate;
  expectSameAnswers(square_plate, 10, 0.5, 3.0, -0.3, 0.5);
}

TEST(Contact, WarmStartsFollowAMotion) {
  // Table 5.3-3 motion: warm starts agree with cold solves and need few iterations.
  ContactResult previous;
  int total_iterations = 0;
  for (int k = 0; k < 200; ++k) {
    const ScenarioPair p = scenarioPair("table5.3-3", k);
    const ContactResult cold = computeContact(p.i, p.j);
    const ContactResult warm = computeContact(p.i, p.j, {}, k ? &previous : nullptr);
    EXPECT_NEAR(warm.distance, cold.distance, 1e-10) << "step " << k;
    EXPECT_NEAR(warm.distance, referenceDistance(p.i, p.j), 1e-10) << "step " << k;
    if (k) {
      EXPECT_LT((warm.point_a - previous.point_a).norm(), 0.5) << "the contact point jumps at step " << k;
      total_iterations += warm.summary.iterations;
    }
    previous = warm;
  }
  EXPECT_LT(total_iterations / 199.0, 6.0);
}

TEST(Contact, CommonNormalSolverAgreesOnEllipsoids) {
  // Ellipsoid pairs normally take the dual Newton path; the thesis'
  // common-normal system of eq. 5.23 must give the same answers.
  ContactOptions common_normal;
  common_normal.solver = ContactSolver::CommonNormal;
  expectSameAnswers(common_normal, 12, 0.3, 2.0, -0.5, 0.5);
  const ConvexShape a = makeConvexShape(Vector3d::Zero(), Matrix3d::Identity(), Vector3d(1, 2, 3));
  const ConvexShape b = makeConvexShape(Vector3d(0.5, 0, 0), Matrix3d::Identity(), Vector3d(1, 1, 1));
  // An overlap of 1.5, deeper than the least radii of curvature (1/3 + 1):
  // only the dual path searches globally and tracks rivals.
  EXPECT_EQ(computeContact(a, b, common_normal).search, nullptr);
  EXPECT_NE(computeContact(a, b).search, nullptr);
  EXPECT_NEAR(computeContact(a, b).distance, -1.5, 1e-12);
  EXPECT_NEAR(computeContact(a, b, common_normal).distance, -1.5, 1e-12);
}

TEST(Contact, ShallowEllipsoidOverlapsAreCertifiedByCurvature) {
  // An overlap shallower than k = r_min^2 / r_max of A plus that of B has a
  // single maximum of the dual (ellipsoid_contact.hpp): certified without
  // sampling. The analytic case: a sphere of radius 1 against the side of an
  // ellipsoid (1, 2, 3) (k = 4/3), 0.5 deep.
  const ConvexShape ellipsoid = makeConvexShape(Vector3d::Zero(), Matrix3d::Identity(), Vector3d(1, 2, 3));
  const ConvexShape sphere = makeConvexShape(Vector3d(1.5, 0, 0), Matrix3d::Identity(), Vector3d(1, 1, 1));
  const ContactResult analytic = computeContact(ellipsoid, sphere);
  EXPECT_NEAR(analytic.distance, -0.5, 1e-12);
  EXPECT_TRUE(analytic.summary.certified);
  EXPECT_FALSE(analytic.summary.global_search);
  EXPECT_EQ(analytic.search, nullptr);
  // Random pairs, aspect up to 10, from just apart to twice k deep, cold and
  // warm, against the sampled search with the certificate switched off. A
  // certificate taken too far (k overestimated) keeps a local maximum that
  // is not the global one on the deeper of these pairs.
  std::mt19937_64 rng(21);
  std::normal_distribution<double> g;
  std::uniform_real_distribution<double> fraction(-2.0, 0.05);
  ContactOptions searched;
  searched.curvature_certificate = false;
  int certified = 0, misses = 0;
  for (int i = 0; i < 4000; ++i) {
    ConvexShape a = randomShape(rng, 0.15, 1.5), b = randomShape(rng, 0.15, 1.5);
    const double k = std::pow(a.radii.minCoeff(), 2) / a.radii.maxCoeff() +
                     std::pow(b.radii.minCoeff(), 2) / b.radii.maxCoeff();
    placeAt(a, b, rng, fraction(rng) * k);
    const ConvexShape before = stepBack(b, rng, g, 0.01);
    const double expected = computeContact(a, b, searched).distance;
    const ContactResult previous = computeContact(a, before);
    const ContactResult cold = computeContact(a, b), warm = computeContact(a, b, {}, &previous);
    for (const ContactResult* r : {&cold, &warm}) {
      certified += r->summary.certified && r->distance < 0.0;
      if (std::fabs(r->distance - expected) > 1e-10 && ++misses <= 3)
        ADD_FAILURE() << "pair " << i << (r == &cold ? " cold: " : " warm: ") << r->distance << " against "
                      << expected << " (k " << k << "), " << r->summary.briefReport();
      const double length = std::max(a.radii.maxCoeff(), b.radii.maxCoeff());
      if (r->distance < 0.0) {
        EXPECT_EQ(r->summary.certified, r->distance > 1e-4 * length - k) << "pair " << i;
      }
    }
  }
  EXPECT_EQ(misses, 0);
  EXPECT_GT(certified, 2000);  // most overlaps above -k, cold and warm
}

TEST(Contact, SuperellipsoidOverlapsAreCertifiedByCurvature) {
  // As for ellipsoids, with k the sum of leastRadiusOfCurvature: a cold
  // overlap above -k ends after the first Newton start. Random pairs,
  // exponents 2-4, from just apart to twice k deep: against the long-double
  // reference, and (more pairs) against the global search with the
  // certificate switched off, which an overestimated k would contradict on
  // the deeper pairs.
  std::mt19937_64 rng(22);
  std::uniform_real_distribution<double> fraction(-2.0, 0.05);
  ContactOptions searched;
  searched.curvature_certificate = false;
  int certified = 0, misses = 0;
  double worst = 0.0;
  for (int i = 0; i < 1000; ++i) {
    ConvexShape a = randomShape(rng, 0.5, 1.5, 4.0), b = randomShape(rng, 0.5, 1.5, 4.0);
    const double k = leastRadiusOfCurvature(a) + leastRadiusOfCurvature(b);
    placeAt(a, b, rng, fraction(rng) * k);
    const ContactResult cold = computeContact(a, b);
    const double expected = i < 60 ? referenceConvexDistance(a, b, 1500, 4) : computeContact(a, b, searched).distance;
    if (i < 60) worst = std::max(worst, std::fabs(cold.distance - expected));
    if (std::fabs(cold.distance - expected) > 1e-12 && ++misses <= 3)
      ADD_FAILURE() << "pair " << i << ": " << cold.distance << " against " << expected << " (k " << k << "), "
                    << cold.summary.briefReport();
    EXPECT_EQ(cold.summary.status, ContactStatus::Converged) << "pair " << i;
    if (cold.distance < 0.0) {
      const double length = std::max(a.radii.norm(), b.radii.norm());
      EXPECT_EQ(cold.summary.certified, cold.distance > 1e-4 * length - k) << "pair " << i;
      EXPECT_EQ(cold.summary.global_search, !cold.summary.certified) << "pair " << i;
      certified += cold.summary.certified;
    }
  }
  EXPECT_EQ(misses, 0);
  EXPECT_GT(certified, 300);
  std::printf("  certified overlaps %d of 1000 pairs; worst |error| against the reference %.3g mm\n", certified, worst);
}

TEST(Contact, WarmStartsOnDeepOverlapsFindTheGlobalAnswer) {
  // Deep, high-aspect pairs: several local maxima of the dual. A warm start
  // from the pair one small step earlier must still end at the global answer.
  std::mt19937_64 rng(13);
  std::normal_distribution<double> g;
  std::uniform_real_distribution<double> gap(-1.0, -0.1);
  for (int i = 0; i < 60; ++i) {
    ConvexShape a = randomShape(rng, 0.15, 1.5), b = randomShape(rng, 0.15, 1.5);
    placeAt(a, b, rng, gap(rng));
    const ConvexShape before = stepBack(b, rng, g, 0.02);
    const ContactResult previous = computeContact(a, before);
    const ContactResult warm = computeContact(a, b, {}, &previous);
    EXPECT_NEAR(warm.distance, referenceDistance(a, b), 1e-10) << "pair " << i << ": " << warm.summary.briefReport();
  }
}

TEST(Contact, ElongatedDeepOverlapsAgainstADenseSearch) {
  // The overlap search's one assumption is that samples within 2 rho of a
  // maximum reached lie in its basin; elongated bodies in deep overlap have
  // several close maxima, which is where it would fail. 20,000 random pairs,
  // aspect up to 30 (semi-axes log-uniform in 0.05-1.5 mm), against the same
  // dual searched on 2,048 directions (caps 32 times smaller), cold and warm
  // (from the pair 0.02 mm and 0.02 rad earlier). The search before this test
  // existed (sampled local maxima plus the best 3 distinct samples) missed
  // 1-4 pairs and 4-26 warm starts in 40,000 here, by up to 0.01 mm.
  std::mt19937_64 rng(7);
  std::normal_distribution<double> g;
  std::uniform_real_distribution<double> log_radius(std::log(0.05), std::log(1.5)), depth(-0.3, 0.01), along(0.0, 1.0);
  ContactOptions dense;
  dense.sample_directions = 2048;
  dense.curvature_certificate = false;  // the shallower pairs also check the curvature certificate
  int cold_misses = 0, warm_misses = 0;
  for (int i = 0; i < 20000; ++i) {
    auto shape = [&] {
      return makeConvexShape(Vector3d::Zero(), randomRotation(rng),
                             Vector3d(std::exp(log_radius(rng)), std::exp(log_radius(rng)), std::exp(log_radius(rng))));
    };
    ConvexShape a = shape(), b = shape();
    const Vector3d dir = Vector3d(g(rng), g(rng), g(rng)).normalized();
    const double reach = dir.dot(toGlobal(a, supportCanonical(a, dir))) - dir.dot(toGlobal(b, supportCanonical(b, -dir)));
    b.center = dir * (reach * along(rng) + depth(rng));
    const ConvexShape before = stepBack(b, rng, g, 0.02);
    const double expected = computeContact(a, b, dense).distance;
    const ContactResult previous = computeContact(a, before);
    const ContactResult cold = computeContact(a, b), warm = computeContact(a, b, {}, &previous);
    if (std::fabs(cold.distance - expected) > 1e-10 && ++cold_misses <= 3)
      ADD_FAILURE() << "pair " << i << " cold: " << cold.distance << " against " << expected << ", "
                    << cold.summary.briefReport();
    if (std::fabs(warm.distance - expected) > 1e-10 && ++warm_misses <= 3)
      ADD_FAILURE() << "pair " << i << " warm: " << warm.distance << " against " << expected << ", "
                    << warm.summary.briefReport();
  }
  EXPECT_EQ(cold_misses, 0);
  EXPECT_EQ(warm_misses, 0);
}

TEST(Frames, VaryContinuouslyAlongASmoothMotion) {
  // Table 5.3-3 motion, 2,000 steps: the contact normal moves a little per
  // step, and each tangent frame moves no more than its derivative allows
  // (|dt| <= |dt/dn| |dn|), except where the normal crosses the frame's
  // branch plane (Householder: n_x = 0; square plate: n_x n_y = 0).
  const int steps = 2000;
  ContactResult previous;
  Vector3d n_prev = Vector3d::Zero();
  int checked = 0;
  for (int k = 0; k < steps; ++k) {
    const ScenarioPair p = scenarioPair("table5.3-3", k, steps);
    const ContactResult r = computeContact(p.i, p.j, {}, k ? &previous : nullptr);
    const Vector3d n = r.normal;
    if (k) {
      const double dn = (n - n_prev).norm();
      EXPECT_LT(dn, 0.05) << "the normal jumps at step " << k;
      for (FrameMethod m : {FrameMethod::Householder, FrameMethod::SquarePlate}) {
        const bool householder = m == FrameMethod::Householder;
        const bool crossed = householder ? (n.x() > 0) != (n_prev.x() > 0)
                                         : (n.x() * n.y() >= 0) != (n_prev.x() * n_prev.y() >= 0);
        if (crossed) continue;
        const FrameWithDerivatives f = frameWithDerivatives(n, m), f_prev = frameWithDerivatives(n_prev, m);
        const double slope_t = std::max(f.dt_dn.norm(), f_prev.dt_dn.norm());
        const double slope_b = std::max(f.db_dn.norm(), f_prev.db_dn.norm());
        EXPECT_LE((f.t - f_prev.t).norm(), 1.1 * slope_t * dn + 1e-12) << "step " << k;
        EXPECT_LE((f.b - f_prev.b).norm(), 1.1 * slope_b * dn + 1e-12) << "step " << k;
        EXPECT_NEAR(f.t.cross(f.b).dot(n), 1.0, 1e-12);
        ++checked;
      }
    }
    previous = r;
    n_prev = n;
  }
  EXPECT_GT(checked, 3 * steps / 2);
}

TEST(Contact, OptionsAreValidated) {
  ContactOptions o;
  o.max_iterations = 0;
  EXPECT_THROW(o.validate(), articula::UsageError);
  o = {};
  o.frame = FrameMethod::Duff;
  EXPECT_THROW(o.validate(), articula::UsageError);
  o = {};
  o.step_tolerance = -1;
  EXPECT_THROW(o.validate(), articula::UsageError);
  o = {};
  o.global_starts = 1000;
  EXPECT_THROW(o.validate(), articula::UsageError);
}

// ---------------------------------------------------------------- proximity

TEST(Proximity, BoundingSpheresAndExactSeparation) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> gap(-0.5, 0.5);
  int checked = 0;
  for (int i = 0; i < 200; ++i) {
    ConvexShape a = randomShape(rng, 0.5, 1.5), b = randomShape(rng, 0.5, 1.5);
    placeAt(a, b, rng, gap(rng));
    const double d = referenceDistance(a, b);
    if (d <= 0.0) {
      EXPECT_TRUE(boundingSpheresOverlap(a, b));
    }
    if (std::fabs(d) < 1e-6) continue;
    ++checked;
    EXPECT_EQ(ellipsoidRelation(a, b), d > 0 ? EllipsoidRelation::Separated : EllipsoidRelation::Overlapping)
        << "distance " << d;
  }
  EXPECT_GT(checked, 190);
  const Matrix3d I = Matrix3d::Identity();
  const ConvexShape s1 = makeConvexShape(Vector3d::Zero(), I, Vector3d::Constant(1.0));
  const ConvexShape s2 = makeConvexShape(Vector3d(2.0, 0, 0), I, Vector3d::Constant(1.0));
  EXPECT_EQ(ellipsoidRelation(s1, s2), EllipsoidRelation::Touching);
  const ConvexShape far = makeConvexShape(Vector3d(10.0, 0, 0), I, Vector3d::Constant(1.0));
  EXPECT_FALSE(boundingSpheresOverlap(s1, far));
}

}  // namespace
