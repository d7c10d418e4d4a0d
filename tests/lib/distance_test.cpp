// Signed distances checked against an independent brute-force reference: the
// nearest point of a dense parametric sample of the surface, zoomed in by
// repeated finer grids in (azimuth, latitude) until it stops moving.
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <utility>
#include <vector>

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

// Nearest point of the parametric surface to x, zoomed in by repeated finer
// grids in (azimuth, latitude) from each of `starts`, then polished in a
// chart free of pole singularities.
double zoomedDistance(const articula::geometry::PosedSurface& s, const Vector3d& x,
                      const std::vector<std::pair<double, double>>& starts, int n_az, int n_lat) {
  const articula::geometry::Pose& pose = s.pose();
  auto point = [&](double az, double lat) { return pose.toGlobal(s.canonicalPoint(az, lat)); };
  double best = std::numeric_limits<double>::infinity();
  Vector3d best_dir = Vector3d::UnitZ();
  for (const auto& [az0, lat0] : starts) {
    double az = az0, lat = lat0, d2 = (point(az, lat) - x).squaredNorm();
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
  // Polish: directions dir0 + a e1 + b e2 from the local origin, each
  // projected onto the surface by bisection.
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

// Dense search: zoomed from the 12 nearest samples of a 1-degree grid.
double bruteForceDistance(const articula::geometry::PosedSurface& s, const Vector3d& x) {
  const articula::geometry::Pose& pose = s.pose();
  const int n_az = 360, n_lat = 180;
  struct Candidate { double d2, az, lat; };
  std::vector<Candidate> all;
  for (int i = 0; i < n_az; ++i)
    for (int j = 0; j <= n_lat; ++j) {
      const double az = -M_PI + 2.0 * M_PI * i / n_az, lat = -M_PI / 2 + M_PI * j / n_lat;
      all.push_back({(pose.toGlobal(s.canonicalPoint(az, lat)) - x).squaredNorm(), az, lat});
    }
  std::partial_sort(all.begin(), all.begin() + 12, all.end(), [](auto& a, auto& b) { return a.d2 < b.d2; });
  std::vector<std::pair<double, double>> starts;
  for (int c = 0; c < 12; ++c) starts.emplace_back(all[c].az, all[c].lat);
  return zoomedDistance(s, x, starts, n_az, n_lat);
}

// Dense search for points deep inside, where many directions are nearly as
// close: zoomed from every local minimum of a 1-degree grid (the lowest 24),
// so that each basin is refined, however shallow.
double bruteForceDistanceDeep(const articula::geometry::PosedSurface& s, const Vector3d& x) {
  const articula::geometry::Pose& pose = s.pose();
  const int n_az = 360, n_lat = 180;
  Eigen::MatrixXd d2(n_az, n_lat + 1);
  for (int i = 0; i < n_az; ++i)
    for (int j = 0; j <= n_lat; ++j)
      d2(i, j) = (pose.toGlobal(s.canonicalPoint(-M_PI + 2.0 * M_PI * i / n_az, -M_PI / 2 + M_PI * j / n_lat)) - x)
                     .squaredNorm();
  std::vector<std::pair<double, std::pair<double, double>>> minima;
  for (int i = 0; i < n_az; ++i)
    for (int j = 0; j <= n_lat; ++j) {
      bool lowest = true;
      for (int di = -1; di <= 1 && lowest; ++di)
        for (int dj = -1; dj <= 1; ++dj) {
          const int jj = j + dj;
          if (jj < 0 || jj > n_lat) continue;
          if (d2((i + di + n_az) % n_az, jj) < d2(i, j)) lowest = false;
        }
      if (lowest) minima.push_back({d2(i, j), {-M_PI + 2.0 * M_PI * i / n_az, -M_PI / 2 + M_PI * j / n_lat}});
    }
  std::sort(minima.begin(), minima.end());
  std::vector<std::pair<double, double>> starts;
  for (size_t k = 0; k < minima.size() && k < 24; ++k) starts.push_back(minima[k].second);
  return zoomedDistance(s, x, starts, n_az, n_lat);
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

// Points deep inside, where the closest point's search is global: the exact
// centre, points within 1 mm of it (nearly every direction about as close on
// a head-like shape), and points within 0.05 mm of the medial sheet of
// elongated shapes (two minima on opposite sides, nearly as near).
TEST(SignedDistanceInterior, CentreAndMedialAxisMatchBruteForce) {
  std::vector<ShapeParameters> shapes;
  ShapeParameters head;  // near-spherical eggs: shallow minima all about
  head.model = ShapeModel::Superovoid;
  head.center = Vector3d(-80.0, -20.0, 95.0);
  head.angles = Vector3d(0.5, -0.4, 1.2);
  head.radii = Vector3d(24.5, 23.5, 22.5);
  head.exponents = Vector3d(2.09, 2.0, 2.05);
  head.cx = Eigen::Vector4d(0.95, 0.02, 0.05, 0.04);
  head.cy = Eigen::Vector4d(0.97, 0.03, 0.03, 0.07);
  shapes.push_back(head);
  head.model = ShapeModel::Ovoid;
  head.exponents = Vector3d::Constant(2.0);
  shapes.push_back(head);
  ShapeParameters rod = testShape(ShapeModel::Superellipsoid);  // elongated, boxy
  rod.radii = Vector3d(42.0, 17.0, 14.0);
  shapes.push_back(rod);
  ShapeParameters egg = testShape(ShapeModel::Ovoid);  // elongated egg
  egg.radii = Vector3d(20.0, 16.0, 38.0);
  shapes.push_back(egg);
  shapes.push_back(testShape(ShapeModel::Superovoid));
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  int checked = 0;
  for (const ShapeParameters& p : shapes) {
    const auto surface = articula::geometry::makeSurface(p);
    const articula::geometry::Pose& pose = surface->pose();
    const SignedDistance field(p);
    std::vector<Vector3d> points{p.center};
    // On the eggs, points (mm from the centre, local axes) whose nearest
    // surface sample lies in the basin of another local minimum, 0.01-0.04
    // mm farther than the nearest.
    std::vector<Vector3d> misleading;
    if (p.model == ShapeModel::Superovoid && p.radii[0] == 24.5)
      misleading = {{-0.92088828113956822, -0.25702931018272146, 0.21615808597270197},
                    {-0.71722816429665404, 0.15579600892949791, 0.15787714153700991}};
    if (p.model == ShapeModel::Ovoid && p.radii[0] == 24.5)
      misleading = {{-0.51322864407780389, 0.24524324220287314, 0.25228987215323473},
                    {-0.067192911832149177, 0.75050616934804459, 0.45488923788541646}};
    for (const Vector3d& v : misleading) points.push_back(pose.rotation * v + pose.translation);
    for (int k = 0; k < 4; ++k) {
      Vector3d v;
      do v = Vector3d(unit(rng), unit(rng), unit(rng)); while (v.squaredNorm() > 1.0);
      points.push_back(p.center + v);
    }
    // Medial sheet: the plane across the shortest axis, well inside; 0,
    // 1e-3 and 0.05 mm off it.
    int shortest = 0;
    pose.scale.minCoeff(&shortest);
    for (double along : {0.3, -0.55})
      for (double off : {0.0, 1e-3, 0.05}) {
        Vector3d u = Vector3d::Zero();
        u[(shortest + 1) % 3] = along;
        u[(shortest + 2) % 3] = 0.2;
        Vector3d local = pose.scale.cwiseProduct(u);
        local[shortest] = off;
        points.push_back(pose.rotation * local + pose.translation);
      }
    for (const Vector3d& x : points) {
      const auto c = field.closest(x);
      const double reference = bruteForceDistanceDeep(*surface, x);
      EXPECT_LT(reference, 0.0);
      EXPECT_NEAR(c.distance, reference, 1e-9) << articula::geometry::modelName(p.model) << " at " << x.transpose();
      EXPECT_NEAR((c.point - x).norm(), std::fabs(c.distance), 1e-9);
      EXPECT_LT(std::fabs(surface->value(c.point)), 1e-10);
      ++checked;
    }
  }
  EXPECT_EQ(checked, 5 * 11 + 2 * 2);
}

}  // namespace
