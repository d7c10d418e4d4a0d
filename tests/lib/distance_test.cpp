// Signed distances checked against an independent brute-force reference: the
// nearest point of a dense parametric sample of the surface, zoomed in by
// repeated finer grids in (azimuth, latitude) until it stops moving.
#include <cmath>
#include <random>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "articula/distance/ellipsoid_distance.hpp"
#include "articula/distance/signed_distance.hpp"
#include "articula/geometry/pose.hpp"
#include "articula/geometry/surface.hpp"

namespace {

using articula::distance::SignedDistance;
using articula::geometry::ShapeModel;
using articula::geometry::ShapeParameters;
using Eigen::Vector3d;

ShapeParameters testShape(ShapeModel model) {
  ShapeParameters p;
  p.model = model;
  p.center = Vector3d(12.0, -25.0, 140.0);
  p.angles = Vector3d(0.3, -0.5, 1.1);
  p.radii = model == ShapeModel::Sphere ? Vector3d::Constant(23.0) : Vector3d(26.0, 22.5, 19.0);
  if (model == ShapeModel::Superellipsoid || model == ShapeModel::Superovoid) p.exponents = Vector3d(2.7, 2.2, 3.4);
  if (model == ShapeModel::Ovoid || model == ShapeModel::Superovoid) {
    p.cx = Eigen::Vector4d(0.92, 0.08, 0.06, -0.05);
    p.cy = Eigen::Vector4d(0.95, 0.03, -0.08, 0.07);
  }
  return p;
}

// Nearest point of the parametric surface to x by dense search and zooming.
double bruteForceDistance(const articula::geometry::PosedSurface& s, const Vector3d& x) {
  const articula::geometry::Pose& pose = s.pose();
  auto point = [&](double az, double lat) { return pose.toGlobal(s.canonicalPoint(az, lat)); };
  const int n_az = 360, n_lat = 180;
  struct Candidate { double d2, az, lat; };
  std::vector<Candidate> all;
  for (int i = 0; i < n_az; ++i)
    for (int j = 0; j <= n_lat; ++j) {
      const double az = -M_PI + 2.0 * M_PI * i / n_az, lat = -M_PI / 2 + M_PI * j / n_lat;
      all.push_back({(point(az, lat) - x).squaredNorm(), az, lat});
    }
  std::partial_sort(all.begin(), all.begin() + 12, all.end(), [](auto& a, auto& b) { return a.d2 < b.d2; });
  double best = std::numeric_limits<double>::infinity();
  Vector3d best_dir = Vector3d::UnitZ();
  for (int c = 0; c < 12; ++c) {
    double az = all[c].az, lat = all[c].lat, d2 = all[c].d2;
    double w_az = 2.0 * M_PI / n_az, w_lat = M_PI / n_lat;
    for (int round = 0; round < 40; ++round) {
      double b_az = az, b_lat = lat;
      for (int i = -10; i <= 10; ++i)
        for (int j = -10; j <= 10; ++j) {
          const double a = az + w_az * i / 5.0;
          const double l = std::clamp(lat + w_lat * j / 5.0, -M_PI / 2, M_PI / 2);
          const double e = (point(a, l) - x).squaredNorm();
          if (e < d2) { d2 = e; b_az = a; b_lat = l; }
        }
      if (b_az == az && b_lat == lat) { w_az *= 0.3; w_lat *= 0.3; }
      az = b_az;
      lat = b_lat;
    }
    if (d2 < best * best) {
      best = std::sqrt(d2);
      best_dir = s.canonicalPoint(az, lat).normalized();
    }
  }
  // Polish in a chart free of pole singularities: directions dir0 + a e1 + b e2
  // from the local origin, each projected onto the surface by bisection.
  const Vector3d e1 = best_dir.unitOrthogonal(), e2 = best_dir.cross(e1);
  auto radial = [&](const Vector3d& dir) {
    double lo = 0.0, hi = 8.0;
    for (int i = 0; i < 60; ++i) {
      const double mid = 0.5 * (lo + hi);
      (s.evaluateCanonical(mid * dir, 0).value < 0.0 ? lo : hi) = mid;
    }
    return pose.toGlobal(0.5 * (lo + hi) * dir);
  };
  double a = 0.0, b = 0.0, w = 0.05, d2 = best * best;
  for (int round = 0; round < 60 && w > 1e-13; ++round) {
    double ba = a, bb = b;
    for (int i = -4; i <= 4; ++i)
      for (int j = -4; j <= 4; ++j) {
        const double e = (radial((best_dir + (a + w * i / 2) * e1 + (b + w * j / 2) * e2).normalized()) - x).squaredNorm();
        if (e < d2) { d2 = e; ba = a + w * i / 2; bb = b + w * j / 2; }
      }
    if (ba == a && bb == b) w *= 0.3;
    a = ba;
    b = bb;
  }
  best = std::sqrt(d2);
  return s.value(x) < 0.0 ? -best : best;
}

class DistanceTest : public ::testing::TestWithParam<ShapeModel> {};

TEST_P(DistanceTest, MatchesBruteForceInsideOutsideNearFar) {
  const ShapeParameters p = testShape(GetParam());
  const auto surface = articula::geometry::makeSurface(p);
  const SignedDistance field(p);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::vector<double> scales = {0.0, 0.05, 0.3, 0.7, 0.97, 1.02, 1.3, 3.0};  // times the surface radius
  int checked = 0;
  for (double s : scales)
    for (int k = 0; k < 4; ++k) {
      Vector3d dir(unit(rng), unit(rng), unit(rng));
      dir.normalize();
      // Along a ray from the centre: s = 0 is the centre itself, s < 1 inside.
      const Vector3d on = surface->pose().toGlobal(surface->canonicalPoint(std::atan2(dir.y(), dir.x()),
                                                                           std::asin(dir.z())));
      const Vector3d x = p.center + s * (on - p.center) + (k == 3 ? Vector3d(0.01, -0.02, 0.015) : Vector3d::Zero());
      const auto c = field.closest(x);
      const double ref = bruteForceDistance(*surface, x);
      EXPECT_NEAR(c.distance, ref, 1e-9) << "scale " << s << " point " << x.transpose();
      EXPECT_NEAR((c.point - x).norm(), std::fabs(c.distance), 1e-9);
      EXPECT_LT(std::fabs(surface->value(c.point)), 1e-10);
      ++checked;
    }
  EXPECT_EQ(checked, 32);
}

TEST_P(DistanceTest, WarmStartAgreesWithGlobalSearch) {
  const ShapeParameters p = testShape(GetParam());
  const SignedDistance field(p);
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.5);
  const auto surface = articula::geometry::makeSurface(p);
  const auto mesh = surface->sample(24, 12);
  Eigen::MatrixX3d pts = mesh.vertices;
  for (Eigen::Index i = 0; i < pts.rows(); ++i) pts.row(i) += Eigen::RowVector3d(noise(rng), noise(rng), noise(rng));
  Eigen::VectorXd cold, warm;
  Eigen::MatrixX3d feet;
  field.evaluate(pts, cold, feet, false);
  Eigen::MatrixX3d guesses = mesh.vertices;
  field.evaluate(pts, warm, guesses, true);
  EXPECT_LT((cold - warm).cwiseAbs().maxCoeff(), 1e-9);
  // Exact from any guesses, even poor ones (points of another surface, the
  // far side of this one): the same distances as the global search, points
  // deep inside included.
  Eigen::MatrixX3d deep = pts;
  deep.bottomRows(pts.rows() / 4) *= 0.3;
  Eigen::VectorXd reference, exact;
  Eigen::MatrixX3d reference_feet;
  field.evaluate(deep, reference, reference_feet);
  Eigen::MatrixX3d far_guesses = -mesh.vertices * 1.2;
  field.evaluate(deep, exact, far_guesses, SignedDistance::Start::WarmExact);
  EXPECT_LT((reference - exact).cwiseAbs().maxCoeff(), 1e-9);
  for (Eigen::Index i = deep.rows() - 1; i >= 0; i -= 15)
    EXPECT_NEAR(exact[i], bruteForceDistance(*surface, deep.row(i).transpose()), 1e-9) << "point " << i;
}

INSTANTIATE_TEST_SUITE_P(AllModels, DistanceTest,
                         ::testing::Values(ShapeModel::Sphere, ShapeModel::Ellipsoid, ShapeModel::Superellipsoid,
                                           ShapeModel::Ovoid, ShapeModel::Superovoid),
                         [](const auto& param_info) { return articula::geometry::modelName(param_info.param); });

TEST(EllipsoidDistance, DegenerateAxesAndSymmetryPlanes) {
  const Vector3d radii(5.0, 3.0, 2.0);
  Vector3d q;
  // Centre: nearest is the end of the shortest axis.
  EXPECT_NEAR(articula::distance::ellipsoidClosestPoint(radii, Vector3d::Zero(), q), -2.0, 1e-15);
  // On the long axis inside, beyond the evolute: nearest is the axis end.
  EXPECT_NEAR(articula::distance::ellipsoidClosestPoint(radii, Vector3d(4.5, 0, 0), q), -0.5, 1e-14);
  // Outside on an axis.
  EXPECT_NEAR(articula::distance::ellipsoidClosestPoint(radii, Vector3d(0, -7.0, 0), q), 4.0, 1e-14);
  EXPECT_NEAR(q.y(), -3.0, 1e-14);
  // Sphere: equal radii reduce to |y| - r.
  EXPECT_NEAR(articula::distance::ellipsoidClosestPoint(Vector3d::Constant(4.0), Vector3d(1, 2, -2), q), -1.0, 1e-14);
}

}  // namespace
