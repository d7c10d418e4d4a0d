// Shape models of lib/geometry against finite differences, their exact
// parametric samples, the nesting of the hierarchy, and parameter checks.
#include <cmath>
#include <functional>
#include <memory>
#include <random>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "articula/core/error.hpp"
#include "articula/geometry/fibonacci.hpp"
#include "articula/geometry/power.hpp"
#include "articula/geometry/surfaces.hpp"

namespace g = articula::geometry;
using Eigen::Matrix3d;
using Eigen::Vector3d;

namespace {

std::mt19937_64& rng() {
  static std::mt19937_64 r(12345);
  return r;
}
double uniform(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng()); }
Vector3d uniformVector(double lo, double hi) { return {uniform(lo, hi), uniform(lo, hi), uniform(lo, hi)}; }

g::Pose randomPose(const Vector3d& radii) {
  g::Pose pose;
  pose.rotation = g::rotationFromAngles(uniformVector(-M_PI, M_PI));
  pose.translation = uniformVector(-150.0, 150.0);
  pose.scale = radii;
  return pose;
}

// A random valid superovoid denominator: thesis bounds and positive on [-1, 1].
Eigen::Vector4d randomDenominator() {
  Eigen::Vector4d c;
  do c = {uniform(0.6, 1.0), uniform(0.0, 0.3), uniform(-0.1, 0.1), uniform(-0.1, 0.1)};
  while (g::minimumOnUnitInterval(c) < 0.2);
  return c;
}

struct NamedSurface {
  std::string label;
  std::shared_ptr<g::ImplicitSurface> surface;
  // Draws a point of the valid domain, away from the coordinate planes where
  // non-integer exponents make third derivatives (and so the FD error) blow up.
  std::function<Vector3d()> point;
};

std::function<Vector3d()> localBox(const g::Pose& pose, double z_limit = 1.5) {
  return [pose, z_limit] {
    Vector3d u;
    do u = {uniform(-1.5, 1.5), uniform(-1.5, 1.5), uniform(-z_limit, z_limit)};
    while (u.cwiseAbs().minCoeff() < 0.05);
    return pose.toGlobal(u);
  };
}

std::vector<NamedSurface> randomSurfaces() {
  std::vector<NamedSurface> out;
  for (int k = 0; k < 4; ++k) {
    const Vector3d radii = uniformVector(15.0, 35.0);
    const Vector3d exps = uniformVector(2.0, 4.0);
    const g::Pose pose = randomPose(radii);
    g::Pose sphere_pose;
    sphere_pose.translation = pose.translation;
    sphere_pose.scale.setConstant(radii[0]);
    out.push_back({"sphere", std::make_shared<g::Sphere>(radii[0], pose.translation), localBox(sphere_pose)});
    out.push_back({"ellipsoid", std::make_shared<g::Ellipsoid>(pose), localBox(pose)});
    out.push_back({"superellipsoid", std::make_shared<g::Superellipsoid>(pose, exps), localBox(pose)});
    out.push_back({"barr", std::make_shared<g::BarrSuperellipsoid>(pose, uniform(0.3, 1.0), uniform(0.3, 1.0)),
                   localBox(pose)});
    // Inside the closed component's slab |z_l| < 1 (F is smooth there).
    out.push_back({"ovoid",
                   std::make_shared<g::Superovoid>(pose, Vector3d::Constant(2.0), randomDenominator(),
                                                   randomDenominator(), true),
                   localBox(pose, 0.95)});
    out.push_back({"superovoid",
                   std::make_shared<g::Superovoid>(pose, exps, randomDenominator(), randomDenominator()),
                   localBox(pose, 0.95)});
    const Matrix3d R = g::rotationFromAngles(uniformVector(-M_PI, M_PI));
    const Vector3d t = uniformVector(-50, 50);
    auto near = [t] { return Vector3d(t + uniformVector(-30.0, 30.0)); };
    out.push_back({"hyperboloid1", std::make_shared<g::Quadric>(Vector3d(1e-3, 2e-3, -1e-3), Vector3d::Zero(), R, t), near});
    out.push_back({"paraboloid", std::make_shared<g::Quadric>(Vector3d(1e-3, 2e-3, 0), Vector3d(0, 0, -1), R, t), near});
    out.push_back({"plane", std::make_shared<g::Plane>(uniformVector(-1, 1), t), near});
  }
  return out;
}

// Relative agreement scaled by the magnitude of the quantities involved.
void expectClose(double fd, double exact, double scale, double rel, const std::string& what) {
  EXPECT_LE(std::fabs(fd - exact), rel * (std::fabs(exact) + scale)) << what << ": fd " << fd << " exact " << exact;
}

}  // namespace

TEST(FibonacciLattice, CoversItsCapEvenly) {
  std::mt19937_64 rng(9);
  std::normal_distribution<double> normal;
  const int count = 500;
  for (double z_min : {-1.0, 0.0, 0.5}) {
    std::vector<Eigen::Vector3d> lattice;
    int upper_half = 0;  // of the cap's area: above z = (1 + z_min) / 2
    for (int i = 0; i < count; ++i) {
      const Eigen::Vector3d v = g::fibonacciDirection(i, count, z_min);
      EXPECT_NEAR(v.norm(), 1.0, 1e-15);
      EXPECT_GE(v.z(), z_min);
      upper_half += v.z() > 0.5 * (1.0 + z_min);
      lattice.push_back(v);
    }
    EXPECT_NEAR(upper_half, count / 2, 1) << z_min;  // equal areas
    // Every direction of the cap lies within about the spacing of a lattice point.
    const double spacing = std::sqrt(2.0 * M_PI * (1.0 - z_min) / count);
    for (int probe = 0; probe < 2000; ++probe) {
      Eigen::Vector3d w(normal(rng), normal(rng), normal(rng));
      w.normalize();
      if (w.z() < z_min) w.z() = 2.0 * z_min - w.z();  // reflected into the cap (renormalised below)
      w.normalize();
      if (w.z() < z_min) continue;
      double nearest = -1.0;
      for (const auto& v : lattice) nearest = std::max(nearest, v.dot(w));
      EXPECT_LT(std::acos(std::min(1.0, nearest)), spacing) << z_min << " at " << w.transpose();
    }
  }
}

TEST(AbsPower, FiniteAtZeroAndForNegativeArguments) {
  for (double gamma : {2.0, 2.5, 3.0, 3.7, 4.0}) {
    const g::AbsPower at0 = g::absPower(0.0, gamma);
    EXPECT_EQ(at0.value, 0.0);
    EXPECT_EQ(at0.first, 0.0);
    EXPECT_EQ(at0.second, gamma == 2.0 ? 2.0 : 0.0) << gamma;
    for (double u : {-1.7, -0.3, -1e-8}) {
      const g::AbsPower p = g::absPower(u, gamma), q = g::absPower(-u, gamma);
      EXPECT_TRUE(std::isfinite(p.value) && std::isfinite(p.first) && std::isfinite(p.second));
      EXPECT_NEAR(p.value, std::pow(std::fabs(u), gamma), 1e-15 * std::pow(std::fabs(u), gamma));
      EXPECT_EQ(p.value, q.value);
      EXPECT_EQ(p.first, -q.first);
      EXPECT_EQ(p.second, q.second);
    }
  }
}

TEST(Surfaces, DerivativesMatchFiniteDifferences) {
  for (const NamedSurface& s : randomSurfaces()) {
    for (int trial = 0; trial < 200; ++trial) {
      const Vector3d x = s.point();
      const g::Evaluation e = s.surface->evaluate(x, 2);
      const double h = 1e-4;  // mm; central differences, error O(h^2)
      const double gscale = e.gradient.norm(), hscale = e.hessian.norm() + 1e-12;
      for (int i = 0; i < 3; ++i) {
        Vector3d xp = x, xm = x;
        xp[i] += h;
        xm[i] -= h;
        const g::Evaluation ep = s.surface->evaluate(xp, 2), em = s.surface->evaluate(xm, 2);
        expectClose((ep.value - em.value) / (2 * h), e.gradient[i], gscale, 1e-7, s.label + " gradient");
        const Vector3d column = (ep.gradient - em.gradient) / (2 * h);
        for (int j = 0; j < 3; ++j) expectClose(column[j], e.hessian(j, i), hscale, 1e-7, s.label + " Hessian");
      }
      EXPECT_TRUE(e.hessian.isApprox(e.hessian.transpose(), 1e-14)) << s.label;
      EXPECT_EQ(s.surface->value(x), e.value);
    }
  }
}

TEST(Surfaces, ParametricSamplesLieOnTheSurface) {
  for (const NamedSurface& s : randomSurfaces()) {
    const g::SurfaceMesh mesh = s.surface->sample(48, 24, 80.0);
    ASSERT_GT(mesh.vertices.rows(), 100) << s.label;
    double worst = 0.0;
    for (Eigen::Index i = 0; i < mesh.vertices.rows(); ++i)
      worst = std::max(worst, std::fabs(s.surface->value(mesh.vertices.row(i).transpose())));
    EXPECT_LE(worst, 1e-12) << s.label;
  }
}

TEST(Surfaces, ClosedMeshesAreOutwardAndHaveTheRightVolume) {
  const Vector3d radii(22.0, 25.0, 19.0);
  const g::Ellipsoid ellipsoid(randomPose(radii));
  const g::SurfaceMesh mesh = ellipsoid.sample(256, 128);
  double volume = 0.0;  // divergence theorem: sum of signed tetrahedra
  for (Eigen::Index f = 0; f < mesh.triangles.rows(); ++f) {
    const Vector3d a = mesh.vertices.row(mesh.triangles(f, 0)), b = mesh.vertices.row(mesh.triangles(f, 1)),
                   c = mesh.vertices.row(mesh.triangles(f, 2));
    volume += a.dot(b.cross(c)) / 6.0;
  }
  const double exact = 4.0 / 3.0 * M_PI * radii.prod();
  EXPECT_GT(volume, 0.0);
  EXPECT_NEAR(volume, exact, 1e-3 * exact);
  EXPECT_EQ(mesh.vertices.rows(), 2 + 127 * 256);
  EXPECT_EQ(mesh.triangles.rows(), 2 * 256 * 127);
}

TEST(Hierarchy, NestsExactly) {
  for (int trial = 0; trial < 20; ++trial) {
    const Vector3d radii = uniformVector(15.0, 35.0), exps = uniformVector(2.0, 4.0);
    const g::Pose pose = randomPose(radii);
    const g::Superovoid so(pose, exps, Eigen::Vector4d(1, 0, 0, 0), Eigen::Vector4d(1, 0, 0, 0));
    const g::Superellipsoid se(pose, exps), se2(pose, Vector3d::Constant(2.0));
    const g::Ellipsoid el(pose);
    const g::BarrSuperellipsoid barr_ellipsoid(pose, 1.0, 1.0);
    const double eps = uniform(0.3, 1.0);
    const g::BarrSuperellipsoid barr(pose, eps, eps);
    const g::Superellipsoid thesis_equal(pose, Vector3d::Constant(2.0 / eps));
    g::Pose round = pose;
    round.scale.setConstant(radii[0]);
    const g::Ellipsoid round_ellipsoid(round);
    const g::Sphere sphere(radii[0], pose.translation);
    auto same = [](const g::ImplicitSurface& a, const g::ImplicitSurface& b, const Vector3d& x) {
      const g::Evaluation ea = a.evaluate(x), eb = b.evaluate(x);
      EXPECT_NEAR(ea.value, eb.value, 1e-12 * (1 + std::fabs(eb.value))) << a.name() << " vs " << b.name();
      EXPECT_LE((ea.gradient - eb.gradient).norm(), 1e-12 * (1 + eb.gradient.norm())) << a.name() << " vs " << b.name();
      EXPECT_LE((ea.hessian - eb.hessian).norm(), 1e-12 * (1 + eb.hessian.norm())) << a.name() << " vs " << b.name();
    };
    for (int k = 0; k < 50; ++k) {
      const Vector3d inside_slab = pose.toGlobal(Vector3d(uniform(-1.4, 1.4), uniform(-1.4, 1.4), uniform(-0.99, 0.99)));
      same(so, se, inside_slab);
      same(se2, el, inside_slab);
      same(barr_ellipsoid, el, inside_slab);
      same(barr, thesis_equal, inside_slab);
      same(round_ellipsoid, sphere, round.toGlobal(uniformVector(-1.5, 1.5)));
    }
  }
}

TEST(Superovoid, RestrictedToItsClosedComponent) {
  const Vector3d radii(24, 22, 20);
  const g::Pose pose = randomPose(radii);
  const Eigen::Vector4d c(0.8, 0.3, -0.1, 0.1);
  const g::Superovoid so(pose, Vector3d(2.5, 3.0, 2.2), c, c);
  // Beyond the vertices there is no second sheet: F > 0 for every |z_l| >= 1.
  for (int k = 0; k < 10000; ++k) {
    Vector3d u(uniform(-5, 5), uniform(-5, 5), uniform(1.0, 6.0));
    if (k % 2) u.z() = -u.z();
    EXPECT_GT(so.value(pose.toGlobal(u)), 0.0);
  }
  // F is continuous across the slab boundary.
  for (double z : {-1.0, 1.0}) {
    const Vector3d below = pose.toGlobal(Vector3d(0.3, -0.2, z * (1 - 1e-12)));
    const Vector3d above = pose.toGlobal(Vector3d(0.3, -0.2, z * (1 + 1e-12)));
    EXPECT_NEAR(so.value(below), so.value(above), 1e-9);
  }
  // The superovoid with a denominator that vanishes in the slab (the spurious sheet) is rejected.
  g::ShapeParameters p;
  p.model = g::ShapeModel::Superovoid;
  p.radii = radii;
  p.cx = Eigen::Vector4d(0.2, 0.5, 0.0, 0.0);  // 0.2 - 0.5 < 0 at z = -1
  try {
    g::validate(p);
    FAIL() << "expected InvalidParameter";
  } catch (const articula::InvalidParameter& e) {
    EXPECT_NE(std::string(e.what()).find("c0x..c3x"), std::string::npos) << e.what();
  }
}

TEST(Superovoid, MinimumOfTheDenominatorMatchesDenseSampling) {
  for (int trial = 0; trial < 1000; ++trial) {
    const Eigen::Vector4d c(uniform(0, 1), uniform(0, 1), uniform(-0.1, 0.1), uniform(-0.1, 0.1));
    double dense = 1e300;
    for (int k = 0; k <= 20000; ++k) {
      const double z = -1.0 + 2.0 * k / 20000.0;
      dense = std::min(dense, c[0] + z * (c[1] + z * (c[2] + z * c[3])));
    }
    const double exact = g::minimumOnUnitInterval(c);
    EXPECT_LE(exact, dense + 1e-15);
    EXPECT_GE(exact, dense - 1e-7);
  }
}

TEST(Parameters, VectorsFollowTable32) {
  using M = g::ShapeModel;
  EXPECT_EQ(g::parameterCount(M::Sphere), 4);
  EXPECT_EQ(g::parameterCount(M::Ellipsoid), 9);
  EXPECT_EQ(g::parameterCount(M::Superellipsoid), 12);
  EXPECT_EQ(g::parameterCount(M::Ovoid), 17);
  EXPECT_EQ(g::parameterCount(M::Superovoid), 20);
  const std::vector<std::string> so = {"a", "b", "c", "gamma1", "gamma2", "gamma3", "c0x", "c1x", "c2x", "c3x",
                                       "c0y", "c1y", "c2y", "c3y", "t1", "t2", "t3", "phi", "theta", "psi"};
  EXPECT_EQ(g::parameterNames(M::Superovoid), so);
  EXPECT_EQ(g::parameterNames(M::Sphere), (std::vector<std::string>{"a", "t1", "t2", "t3"}));
  for (M m : g::allModels()) {
    Eigen::VectorXd lambda = Eigen::VectorXd::LinSpaced(g::parameterCount(m), 0.1, 0.9);
    EXPECT_TRUE(g::toVector(g::fromVector(m, lambda)).isApprox(lambda)) << g::modelName(m);
    EXPECT_EQ(g::modelFromName(g::modelName(m)), m);
  }
  EXPECT_THROW(g::fromVector(M::Ellipsoid, Eigen::VectorXd::Zero(4)), articula::UsageError);
  EXPECT_THROW(g::modelFromName("cube"), articula::UsageError);
}

TEST(Parameters, PromotionKeepsTheShape) {
  g::ShapeParameters e;
  e.model = g::ShapeModel::Ellipsoid;
  e.radii = {25, 22, 20};
  e.center = {1, 2, 3};
  e.angles = {0.1, -0.2, 0.3};
  const auto el = g::makeSurface(e);
  const auto so = g::makeSurface(g::promote(e, g::ShapeModel::Superovoid));
  for (int k = 0; k < 100; ++k) {
    const Vector3d x = e.center + uniformVector(-20, 20);
    EXPECT_NEAR(el->value(x), so->value(x), 1e-12);
  }
  EXPECT_THROW(g::promote(g::promote(e, g::ShapeModel::Ovoid), g::ShapeModel::Superellipsoid), articula::UsageError);
}

TEST(Parameters, InvalidValuesAreRejectedByName) {
  auto expectRejected = [](g::ShapeParameters p, const std::string& name) {
    try {
      g::validate(p);
      ADD_FAILURE() << "accepted invalid " << name;
    } catch (const articula::InvalidParameter& e) {
      EXPECT_EQ(e.parameter, name);
      EXPECT_NE(std::string(e.what()).find("'" + name + "'"), std::string::npos) << e.what();
      EXPECT_EQ(e.code(), articula::ExitCode::InvalidInput);
    }
  };
  g::ShapeParameters p;
  p.model = g::ShapeModel::Superovoid;
  p.radii = {20, 21, 22};
  EXPECT_NO_THROW(g::validate(p));
  auto q = p;
  q.radii[1] = 0.0;
  expectRejected(q, "b");
  q = p;
  q.radii[2] = -3.0;
  expectRejected(q, "c");
  q = p;
  q.exponents[1] = 1.9;
  expectRejected(q, "gamma2");
  q = p;
  q.exponents[0] = std::nan("");
  expectRejected(q, "gamma1");
  q = p;
  q.center[2] = std::numeric_limits<double>::infinity();
  expectRejected(q, "t3");
  q = p;
  q.angles[1] = std::nan("");
  expectRejected(q, "theta");
  q = p;
  q.cy[2] = 0.5;
  expectRejected(q, "c2y");
  q = p;
  q.model = g::ShapeModel::Sphere;
  q.radii[0] = std::nan("");
  expectRejected(q, "a");
  EXPECT_THROW(g::Sphere(-1.0, Vector3d::Zero()), articula::InvalidParameter);
  EXPECT_THROW(g::BarrSuperellipsoid(g::Pose(), 1.5, 1.0), articula::InvalidParameter);
  EXPECT_THROW(g::Plane(Vector3d::Zero(), Vector3d::Zero()), articula::InvalidParameter);
  EXPECT_THROW(g::Quadric(Vector3d(1, 1, 1), Vector3d(1, 0, 0), Matrix3d::Identity(), Vector3d::Zero()),
               articula::InvalidParameter);
}

TEST(Pose, AnglesAndTransformsRoundTrip) {
  for (int k = 0; k < 1000; ++k) {
    const Vector3d a(uniform(-M_PI, M_PI), uniform(-M_PI / 2 + 1e-3, M_PI / 2 - 1e-3), uniform(-M_PI, M_PI));
    const Matrix3d R = g::rotationFromAngles(a);
    const Matrix3d explicit_R = Eigen::AngleAxisd(a[0], Vector3d::UnitX()).toRotationMatrix() *
                                Eigen::AngleAxisd(a[1], Vector3d::UnitY()).toRotationMatrix() *
                                Eigen::AngleAxisd(a[2], Vector3d::UnitZ()).toRotationMatrix();
    EXPECT_TRUE(R.isApprox(explicit_R, 1e-14));
    EXPECT_TRUE(g::anglesFromRotation(R).isApprox(a, 1e-9));
    g::Pose pose;
    pose.rotation = R;
    pose.translation = uniformVector(-100, 100);
    pose.scale = uniformVector(5, 40);
    const Vector3d x = uniformVector(-200, 200);
    EXPECT_TRUE(pose.toGlobal(pose.toLocal(x)).isApprox(x, 1e-13));
  }
  // Gimbal lock still gives a rotation that reproduces R.
  const Matrix3d locked = g::rotationFromAngles(Vector3d(0.4, M_PI / 2, 0.3));
  EXPECT_TRUE(g::rotationFromAngles(g::anglesFromRotation(locked)).isApprox(locked, 1e-12));
  EXPECT_NEAR(g::wrapAngle(3 * M_PI), M_PI, 1e-15);
  EXPECT_NEAR(g::wrapAngle(-M_PI), M_PI, 1e-15);
}

TEST(Quadric, ClassifiesTable23) {
  const Matrix3d I = Matrix3d::Identity();
  const Vector3d zero = Vector3d::Zero();
  EXPECT_EQ(g::Quadric(Vector3d(1, 2, 3), zero, I, zero).type(), g::Quadric::Type::Ellipsoid);
  EXPECT_EQ(g::Quadric(Vector3d(1, 2, -3), zero, I, zero).type(), g::Quadric::Type::Hyperboloid1);
  EXPECT_EQ(g::Quadric(Vector3d(-1, -2, 3), zero, I, zero).type(), g::Quadric::Type::Hyperboloid2);
  EXPECT_EQ(g::Quadric(Vector3d(1, 2, 0), Vector3d(0, 0, -1), I, zero).type(), g::Quadric::Type::EllipticParaboloid);
  EXPECT_EQ(g::Quadric(Vector3d(1, -2, 0), Vector3d(0, 0, -1), I, zero).type(),
            g::Quadric::Type::HyperbolicParaboloid);
  EXPECT_TRUE(g::Quadric(Vector3d(0.25, 4, 1), zero, I, zero).dimensions().isApprox(Vector3d(2, 0.5, 1)));
}
