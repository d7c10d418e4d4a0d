// Tangent frames: orthonormal and right-handed for 10^6 random normals and
// for normals at and near the axes, unit or not; and curvature.
#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "articula/core/error.hpp"
#include "articula/geometry/curvature.hpp"
#include "articula/geometry/frames.hpp"
#include "articula/geometry/surfaces.hpp"

namespace g = articula::geometry;
using Eigen::Vector3d;

namespace {

const g::FrameMethod kMethods[] = {g::FrameMethod::Householder, g::FrameMethod::Duff, g::FrameMethod::Eberly,
                                   g::FrameMethod::SquarePlate, g::FrameMethod::ProjectionMatrix};

// Worst deviation from an orthonormal right-handed frame with t x b = n/|n|.
double frameError(const Vector3d& n, const g::TangentFrame& f) {
  const Vector3d u = n.normalized();
  return std::max({std::fabs(u.dot(f.t)), std::fabs(u.dot(f.b)), std::fabs(f.t.dot(f.b)),
                   std::fabs(f.t.norm() - 1.0), std::fabs(f.b.norm() - 1.0), (f.t.cross(f.b) - u).norm()});
}

std::vector<Vector3d> randomUnitNormals(size_t count) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> gauss;
  std::vector<Vector3d> v(count);
  for (auto& n : v) {
    do n = Vector3d(gauss(rng), gauss(rng), gauss(rng));
    while (n.norm() < 1e-3);
    n.normalize();
  }
  return v;
}

// The axes, and normals within 1e-12 of them on every side.
std::vector<Vector3d> nearAxisNormals() {
  std::vector<Vector3d> out;
  for (int axis = 0; axis < 3; ++axis)
    for (double sign : {1.0, -1.0}) {
      Vector3d e = Vector3d::Zero();
      e[axis] = sign;
      out.push_back(e);
      for (double d : {1e-12, -1e-12, 1e-300, -1e-300, 4e-16})
        for (int other = 0; other < 3; ++other) {
          if (other == axis) continue;
          Vector3d n = e;
          n[other] = d;
          out.push_back(n.normalized());
          n[3 - axis - other] = -d;
          out.push_back(n.normalized());
        }
      Vector3d signed_zero = e;
      signed_zero[(axis + 1) % 3] = -0.0;
      out.push_back(signed_zero);
    }
  return out;
}

}  // namespace

TEST(Frames, UnitFormulasAreOrthonormalAndRightHandedForAMillionNormals) {
  const auto normals = randomUnitNormals(1000000);
  struct Case {
    const char* name;
    g::TangentFrame (*fn)(const Vector3d&);
    double tolerance;
  };
  const Case cases[] = {{"Householder", g::householderFrameUnit, 1e-15},
                        {"Duff", g::duffFrameUnit, 1e-15},
                        {"Eberly", g::eberlyFrameUnit, 2e-15},
                        {"SquarePlate", g::squarePlateFrameUnit, 2e-15},
                        {"ProjectionMatrix", g::projectionMatrixFrameUnit, 2e-15}};
  for (const Case& c : cases) {
    double worst = 0.0;
    for (const Vector3d& n : normals) worst = std::max(worst, frameError(n, c.fn(n)));
    EXPECT_LE(worst, c.tolerance) << c.name;
    for (const Vector3d& n : nearAxisNormals()) EXPECT_LE(frameError(n, c.fn(n)), c.tolerance) << c.name << " " << n.transpose();
  }
}

TEST(Frames, AnyLengthNormals) {
  const auto normals = randomUnitNormals(20000);
  for (g::FrameMethod m : kMethods)
    for (double scale : {1e-9, 0.37, 1.0, 3.0, 1e7})
      for (const Vector3d& n : normals) ASSERT_LE(frameError(scale * n, g::tangentFrame(scale * n, m)), 4e-15)
          << g::frameMethodName(m) << " scale " << scale;
  for (g::FrameMethod m : kMethods)
    for (const Vector3d& n : nearAxisNormals()) EXPECT_LE(frameError(5 * n, g::tangentFrame(5 * n, m)), 4e-15);
  EXPECT_THROW(g::tangentFrame(Vector3d::Zero()), articula::InvalidParameter);
}

TEST(Frames, ThesisMirroredBranchIsLeftHandedAndOursIsNot) {
  // Table C.1 as printed, for n_x < 0.
  const Vector3d n = Vector3d(-0.6, 0.48, 0.64).normalized();
  const double k = 1.0 / (n.x() - 1.0);
  const Vector3d t(n.y(), 1 + n.y() * n.y() * k, n.y() * n.z() * k);
  const Vector3d b(n.z(), n.y() * n.z() * k, 1 + n.z() * n.z() * k);
  EXPECT_NEAR(t.cross(b).dot(n), -1.0, 1e-15);  // left-handed
  const g::TangentFrame ours = g::householderFrameUnit(n);
  EXPECT_TRUE(ours.t.isApprox(t, 1e-15));  // same tangent, binormal negated
  EXPECT_TRUE(ours.b.isApprox(-b, 1e-15));
  EXPECT_NEAR(ours.t.cross(ours.b).dot(n), 1.0, 1e-15);
}

TEST(Frames, HouseholderColumnsMatchTheMatrix) {
  // t and b are the 2nd and 3rd columns of H = I - 2 h h^T / h^T h (eq. 4.19), b signed for handedness.
  for (const Vector3d& n : randomUnitNormals(1000)) {
    const Vector3d m = 2.5 * n;
    const double s = m.x() >= 0 ? 1.0 : -1.0;
    const Vector3d h(m.x() + s * m.norm(), m.y(), m.z());
    const Eigen::Matrix3d H = Eigen::Matrix3d::Identity() - 2.0 * h * h.transpose() / h.squaredNorm();
    const g::TangentFrame f = g::householderFrame(m);
    EXPECT_TRUE(f.t.isApprox(H.col(1), 1e-14));
    EXPECT_TRUE(f.b.isApprox(s * H.col(2), 1e-14));
    EXPECT_TRUE((H * m).isApprox(-s * m.norm() * Vector3d::UnitX(), 1e-14));
  }
}

TEST(Curvature, SphereHasOneOverRadiusEverywhere) {
  const double r = 23.5;
  const g::Sphere sphere(r, Vector3d(10, -4, 80));
  const g::SurfaceMesh mesh = sphere.sample(24, 12);
  for (Eigen::Index i = 0; i < mesh.vertices.rows(); ++i) {
    const Vector3d x = mesh.vertices.row(i);
    const g::PrincipalCurvatures pc = g::principalCurvatures(sphere, x);
    EXPECT_NEAR(pc.k1, 1.0 / r, 1e-14);
    EXPECT_NEAR(pc.k2, 1.0 / r, 1e-14);
    const g::SurfaceFrame f = g::surfaceFrame(sphere, x);
    EXPECT_NEAR(f.normal.dot((x - Vector3d(10, -4, 80)) / r), 1.0, 1e-12);  // outward
    EXPECT_NEAR(f.tangent.cross(f.binormal).dot(f.normal), 1.0, 1e-14);
    EXPECT_NEAR(g::normalCurvature(sphere, x, f.tangent), 1.0 / r, 1e-14);
  }
}

TEST(Curvature, EllipsoidVerticesMatchClosedForm) {
  const Eigen::Vector3d radii(30.0, 24.0, 18.0);
  g::Pose pose;
  pose.rotation = g::rotationFromAngles(Vector3d(0.3, -0.5, 1.1));
  pose.translation = Vector3d(-12, 40, 7);
  pose.scale = radii;
  const g::Ellipsoid ellipsoid(pose);
  const double a = radii[0], b = radii[1], c = radii[2];
  // At the vertex on axis i the normal sections along the other axes j have
  // curvature r_i / r_j^2.
  struct Vertex {
    Vector3d local;
    double k1, k2;
    int axis1;  // local axis of the larger curvature
  };
  const Vertex vertices[] = {{{1, 0, 0}, a / (c * c), a / (b * b), 2}, {{-1, 0, 0}, a / (c * c), a / (b * b), 2},
                             {{0, 1, 0}, b / (c * c), b / (a * a), 2}, {{0, 0, -1}, c / (b * b), c / (a * a), 1}};
  for (const Vertex& v : vertices) {
    const Vector3d x = pose.toGlobal(v.local);
    const g::PrincipalCurvatures pc = g::principalCurvatures(ellipsoid, x);
    EXPECT_NEAR(pc.k1, v.k1, 1e-13);
    EXPECT_NEAR(pc.k2, v.k2, 1e-13);
    EXPECT_NEAR(std::fabs(pc.d1.dot(pose.rotation.col(v.axis1))), 1.0, 1e-12);
    EXPECT_NEAR(pc.d1.dot(pc.d2), 0.0, 1e-14);
  }
}
