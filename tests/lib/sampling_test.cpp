// Sampling: the automatic articular selection of the phantom's segmented and
// meshed head lies on the true head (0.5 voxel RMS, centre within 0.5 mm);
// the open-ball down-sampling keeps points at least r apart, covers every
// dropped point within r, is seeded, and removes duplicates and outliers.
#include <random>

#include <gtest/gtest.h>

#include "articula/core/error.hpp"
#include "articula/imaging/segment.hpp"
#include "articula/mesh/mesh.hpp"
#include "articula/sampling/downsample.hpp"
#include "articula/sampling/select.hpp"
#include "ct_test_support.hpp"

namespace articula {
namespace {

TEST(Sampling, PhantomChainPutsArticularPointsOnTheTrueHead) {
  struct Case { geometry::ShapeModel model; bool right; double gap; };
  for (const Case& c : {Case{geometry::ShapeModel::Sphere, true, 3.0}, Case{geometry::ShapeModel::Superovoid, false, 2.0}}) {
    phantom::PhantomOptions o;
    o.seed = 11;
    o.model = c.model;
    o.right = c.right;
    o.gap_mm = c.gap;
    const phantom::Phantom p = phantom::makePhantom(o);
    imaging::SegmentOptions so;
    so.side = c.right ? imaging::Side::Right : imaging::Side::Left;
    mesh::TriangleMesh m = mesh::extractSurface(imaging::segmentHead(p.ct, so), {});
    mesh::snapToEdges(m, p.ct, {});
    sampling::SelectOptions sel_options;
    const sampling::Selection sel = sampling::selectArticular(m.vertices, m.normals, m.triangles, sel_options);
    const auto head = geometry::makeSurface(p.head);
    double sum = 0, mean = 0;
    for (int v : sel.indices) {
      const double d = testing::headDistance(*head, m.vertices.row(v).transpose());
      sum += d * d;
      mean += d / sel.indices.size();
    }
    const double rms = std::sqrt(sum / sel.indices.size());
    SCOPED_TRACE(geometry::modelName(c.model));
    EXPECT_GT(sel.indices.size(), 2000u);
    // On the CT's edge: a fraction of the in-plane voxel, and hardly outside
    // on average (a 1.5 mm cortex under 0.5 mm of blur: about 0.1 mm, see imaging/edges.hpp).
    EXPECT_LT(rms, 0.3 * p.ct.geometry.spacing.minCoeff()) << "RMS " << rms << " mean " << mean;
    EXPECT_LT(std::abs(mean), 0.15) << "mean " << mean;
    RecordProperty(geometry::modelName(c.model) + "_rms_mm", std::to_string(rms));
    // The sphere of the selected patch: centre of the true head within 0.5 mm for a sphere.
    if (c.model == geometry::ShapeModel::Sphere) {
      EXPECT_LT((sel.sphere_center - p.head.center).norm(), 0.5);
      EXPECT_NEAR(sel.sphere_radius, p.head.radii[0], 0.5);
    }
  }
}

Eigen::MatrixX3d randomSpherePoints(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0, 1);
  Eigen::MatrixX3d P(n, 3);
  for (int i = 0; i < n; ++i) P.row(i) = 20.0 * Eigen::RowVector3d(g(rng), g(rng), g(rng)).normalized();
  return P;
}

TEST(Sampling, OpenBallDownsamplingHonoursTheBall) {
  const Eigen::MatrixX3d P = randomSpherePoints(6000, 1);
  sampling::DownsampleOptions o;
  o.ball_radius_mm = 1.5;
  o.remove_outliers = false;
  sampling::DownsampleSummary s;
  const std::vector<int> kept = sampling::gaussianDownsample(P, o, &s);
  EXPECT_EQ(s.termination, "no point left");
  EXPECT_EQ(s.reduced, static_cast<long long>(kept.size()));
  EXPECT_LT(kept.size(), 3000u);
  // Kept points are pairwise at least r apart (nothing kept inside an open ball).
  for (size_t a = 0; a < kept.size(); ++a)
    for (size_t b = a + 1; b < kept.size(); ++b)
      ASSERT_GE((P.row(kept[a]) - P.row(kept[b])).norm(), o.ball_radius_mm);
  // Every point dropped lies within r of a kept point.
  for (Eigen::Index i = 0; i < P.rows(); ++i) {
    double nearest = 1e9;
    for (int k : kept) nearest = std::min(nearest, (P.row(i) - P.row(k)).norm());
    ASSERT_LT(nearest, o.ball_radius_mm);
  }
  // Seeded: the same seed gives the same points, another seed others.
  EXPECT_EQ(sampling::gaussianDownsample(P, o), kept);
  o.seed = 7;
  EXPECT_NE(sampling::gaussianDownsample(P, o), kept);
}

TEST(Sampling, RatioDuplicatesAndOutliers) {
  Eigen::MatrixX3d P = randomSpherePoints(2000, 2);
  Eigen::MatrixX3d Q(P.rows() + 101, 3);
  Q.topRows(P.rows()) = P;
  Q.block(P.rows(), 0, 100, 3) = P.topRows(100);        // 100 exact duplicates
  Q.row(Q.rows() - 1) = Eigen::RowVector3d(200, 0, 0);  // one far outlier
  sampling::DownsampleOptions o;
  o.ball_radius_mm = 0.0;  // keep everything but duplicates and outliers
  sampling::DownsampleSummary s;
  std::vector<int> kept = sampling::gaussianDownsample(Q, o, &s);
  EXPECT_EQ(s.duplicates, 100);
  EXPECT_EQ(s.outliers, 1);
  EXPECT_EQ(kept.size(), 2000u);
  o.ratio = 0.1;
  kept = sampling::gaussianDownsample(Q, o, &s);
  EXPECT_EQ(s.termination, "ratio reached");
  EXPECT_EQ(kept.size(), static_cast<size_t>(std::ceil(0.1 * Q.rows())));
  o.ratio = 0;
  EXPECT_THROW(sampling::gaussianDownsample(Q, o), UsageError);
}

TEST(Sampling, ManualSelectionsAndTheirErrors) {
  sampling::SelectOptions o;
  sampling::parseSelection("sphere:0,0,20,5", o);
  EXPECT_EQ(o.mode, sampling::SelectOptions::Mode::Sphere);
  const Eigen::MatrixX3d P = randomSpherePoints(5000, 3);
  o.min_points = 10;
  const auto cap = sampling::selectArticular(P, Eigen::MatrixX3d(), Eigen::MatrixX3i(), o);
  for (int i : cap.indices) EXPECT_LE((P.row(i) - Eigen::RowVector3d(0, 0, 20)).norm(), 5.0);
  EXPECT_GT(cap.indices.size(), 10u);
  sampling::parseSelection("box:-100,-100,19,100,100,100", o);
  EXPECT_GT(sampling::selectArticular(P, Eigen::MatrixX3d(), Eigen::MatrixX3i(), o).indices.size(), 10u);
  o.min_points = 100000;  // a selection with too few points
  EXPECT_THROW(sampling::selectArticular(P, Eigen::MatrixX3d(), Eigen::MatrixX3i(), o), InputError);
  EXPECT_THROW(sampling::parseSelection("sphere:1,2,3", o), UsageError);
  EXPECT_THROW(sampling::parseSelection("box:0,0,0,1,1,x", o), UsageError);
  EXPECT_THROW(sampling::parseSelection("blob", o), UsageError);
  // Auto on a plane: no sphere of head radius -> processing failed (exit 1).
  Eigen::MatrixX3d plane(2500, 3), normals(2500, 3);
  for (int i = 0; i < 2500; ++i) plane.row(i) << i % 50, i / 50, 0.0, normals.row(i) << 0, 0, 1;
  sampling::SelectOptions automatic;
  EXPECT_THROW(sampling::selectArticular(plane, normals, Eigen::MatrixX3i(), automatic), ProcessingError);
}

}  // namespace
}  // namespace articula
