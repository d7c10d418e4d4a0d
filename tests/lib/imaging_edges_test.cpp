// Sub-voxel bone edges: a cortex of known position, blurred by a known
// point-spread and sampled on a grid, is found where the closed form of its
// blurred profile puts the steepest fall (on the surface for a thick
// cortex); a ray from a head's centre stops at the head, not at the socket.
#include <cmath>

#include <gtest/gtest.h>

#include "articula/imaging/edges.hpp"

namespace articula {
namespace {

double Phi(double x) { return 0.5 * std::erfc(-x / std::sqrt(2.0)); }

struct Cortex {
  double soft = 40, cortical = 1300, cancellous = 350, thickness = 1.5, sigma = 0.6;
  /// HU at signed distance x outside the bone's outer surface (x < 0 inside),
  /// for a flat cortex from -thickness to 0 blurred by a Gaussian of sigma.
  double hu(double x) const {
    return soft + (cancellous - soft) * Phi(-(x + thickness) / sigma) +
           (cortical - soft) * (Phi(-x / sigma) - Phi(-(x + thickness) / sigma));
  }
};

/// A volume whose bone's outer surface is the plane n . (x - p) = 0.
imaging::Volume flatCortex(const Cortex& c, const Eigen::Vector3d& n, double plane_offset, double spacing) {
  imaging::Volume v;
  v.geometry.size = Eigen::Vector3i(40, 40, 40);
  v.geometry.spacing = Eigen::Vector3d::Constant(spacing);
  v.geometry.origin = Eigen::Vector3d::Constant(-20 * spacing);
  v.voxels.resize(static_cast<size_t>(v.geometry.voxelCount()));
  for (int k = 0; k < 40; ++k)
    for (int j = 0; j < 40; ++j)
      for (int i = 0; i < 40; ++i)
        v.at(i, j, k) = static_cast<float>(c.hu(n.dot(v.geometry.toPhysical(Eigen::Vector3d(i, j, k))) - plane_offset));
  return v;
}

/// An n^3 grid of spacing h centred on the origin, each voxel hu(its centre).
template <class F>
imaging::Volume cubeAboutOrigin(int n, double h, F hu) {
  imaging::Volume v;
  v.geometry.size = Eigen::Vector3i(n, n, n);
  v.geometry.spacing = Eigen::Vector3d::Constant(h);
  v.geometry.origin = Eigen::Vector3d::Constant(-0.5 * (n - 1) * h);
  v.voxels.resize(static_cast<size_t>(v.geometry.voxelCount()));
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) v.at(i, j, k) = static_cast<float>(hu(v.geometry.toPhysical(Eigen::Vector3d(i, j, k))));
  return v;
}

constexpr double kSigma = 0.6;  // the rays' heads' radial blur
/// A head of radius 20 mm with a 1.5 mm cortex over cancellous bone, in soft
/// tissue, blurred radially: HU at r from its centre.
double headHu(double r) {
  const double head = 350 + 950 * Phi((r - 18.5) / kSigma);  // cancellous, then the cortex
  return 40 + (head - 40) * Phi((20 - r) / kSigma);
}

TEST(Edges, InterpolationIsExactOnLinearFieldsAndNanOutside) {
  imaging::Volume v;
  v.geometry.size = Eigen::Vector3i(5, 6, 7);
  v.geometry.spacing = Eigen::Vector3d(0.5, 1.0, 2.0);
  v.geometry.direction = Eigen::Vector3d(-1, -1, 1).asDiagonal();
  v.voxels.resize(static_cast<size_t>(v.geometry.voxelCount()));
  const auto f = [](const Eigen::Vector3d& x) { return 3 * x[0] - 2 * x[1] + 0.5 * x[2] + 7; };
  for (int k = 0; k < 7; ++k)
    for (int j = 0; j < 6; ++j)
      for (int i = 0; i < 5; ++i) v.at(i, j, k) = static_cast<float>(f(v.geometry.toPhysical(Eigen::Vector3d(i, j, k))));
  const Eigen::Vector3d x = v.geometry.toPhysical(Eigen::Vector3d(1.3, 2.7, 5.5));
  EXPECT_NEAR(imaging::interpolate(v, x), f(x), 1e-4);
  EXPECT_TRUE(std::isnan(imaging::interpolate(v, v.geometry.toPhysical(Eigen::Vector3d(-0.2, 0, 0)))));
}

/// Where the steepest fall of the blurred profile of `c` lies (closed form,
/// by bisection on the slope's derivative near 0): the reference for the
/// sampled, interpolated search.
double steepestFall(const Cortex& c) {
  const auto slope = [&c](double x) { return (c.hu(x + 1e-4) - c.hu(x - 1e-4)) / 2e-4; };
  double lo = -0.5 * c.sigma, hi = 1.5 * c.sigma;
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (lo + hi);
    (slope(mid + 1e-3) - slope(mid - 1e-3) < 0 ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

TEST(Edges, SteepestFallIsFoundWhereTheBlurredCortexPutsIt) {
  const Eigen::Vector3d n = Eigen::Vector3d(1, 0.3, -0.2).normalized();
  for (double thickness : {0.8, 1.5, 3.0})
    for (double offset : {-0.37, 0.0, 0.21}) {
      Cortex c;
      c.thickness = thickness;
      const imaging::Volume v = flatCortex(c, n, offset, 0.5);
      const Eigen::Vector3d start = 0.5 * n;  // 0.5 mm off the plane through the origin
      const imaging::Edge e = imaging::locateEdge(v, start, n, {});
      ASSERT_TRUE(e.found) << thickness;
      // A thick cortex is found on its surface. A thin one's peak spans a
      // voxel or two: grid sampling and trilinear interpolation move it by up
      // to a tenth of a millimetre about the closed form, with the grid phase.
      if (thickness >= 3.0) {
        EXPECT_NEAR(e.offset_mm, offset - 0.5, 0.08) << "offset " << offset;
      } else {
        EXPECT_NEAR(e.offset_mm, offset - 0.5 + steepestFall(c), 0.12) << "thickness " << thickness << ", offset " << offset;
      }
    }
  Cortex thin;
  thin.thickness = 0.8;
  EXPECT_GT(steepestFall(thin), 0.05);  // the inner rise's pull, which the closed form confirms
}

TEST(Edges, NoEdgeWithoutContrastOrOutsideTheGrid) {
  Cortex c;
  c.cortical = c.soft + 60;  // a 60 HU step: below the 150 HU contrast asked for
  c.cancellous = c.soft + 60;
  const imaging::Volume v = flatCortex(c, Eigen::Vector3d::UnitX(), 0.0, 0.7);
  EXPECT_FALSE(imaging::locateEdge(v, Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX(), {}).found);
  Cortex strong;
  const imaging::Volume w = flatCortex(strong, Eigen::Vector3d::UnitX(), 0.0, 0.7);
  EXPECT_FALSE(imaging::locateEdge(w, Eigen::Vector3d(13.5, 0, 0), Eigen::Vector3d::UnitX(), {}).found);
}

TEST(Edges, FirstEdgeAlongARayIsTheHeadNotTheSocketBehindANarrowGap) {
  // Head: a ball of radius 20 with a 1.5 mm cortex; socket: a shell from
  // 21.5 to 26.5 mm (a 1.5 mm gap), all blurred radially.
  const imaging::Volume v = cubeAboutOrigin(90, 0.7, [](const Eigen::Vector3d& x) {
    const double r = x.norm();
    const double socket = 1260 * (Phi((r - 21.5) / kSigma) - Phi((r - 26.5) / kSigma));
    return headHu(r) + socket;
  });
  for (const Eigen::Vector3d& u : {Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(1, 1, 1).normalized(),
                                   Eigen::Vector3d(-0.2, 0.5, -0.8).normalized()}) {
    const imaging::Edge e = imaging::firstEdgeAlongRay(v, Eigen::Vector3d::Zero(), u, 6.0, 30.0, {});
    ASSERT_TRUE(e.found);
    EXPECT_NEAR(e.offset_mm, 20.0, 0.25);  // not 26.5, the socket's outer surface
  }
}

/// An osteoporotic head of radius 20 mm (a 0.8 mm cortex at 700 HU over 190
/// HU), and, when `gap_mm` > 0, a socket across that gap (the same cortex
/// and cancellous bone, 5 mm thick), in soft tissue at 40 HU, blurred
/// radially by 0.5 mm: HU at r from its centre.
double faintHeadHu(double r, double gap_mm) {
  const auto layer = [r](double from, double to, double hu) { return (hu - 40) * (Phi((r - from) / 0.5) - Phi((r - to) / 0.5)); };
  double hu = 40 + layer(-100, 19.2, 190) + layer(19.2, 20, 700);
  if (gap_mm > 0) hu += layer(20 + gap_mm, 20.8 + gap_mm, 700) + layer(20.8 + gap_mm, 25, 190);
  return hu;
}

// Across a 1 mm gap between faint cortices the gap's blurred valley lies
// 145-165 HU below the head's cortex, about an edge's least contrast: the
// first edge on a ray is then the head's on some rays and the socket's far
// side on others (here along x, at 22 mm). The first fall into a valley is
// the head's on every ray.
TEST(Edges, FirstValleyAlongARayIsTheHeadAcrossAFaintNarrowGap) {
  const imaging::Volume across_gap =
      cubeAboutOrigin(110, 0.5, [](const Eigen::Vector3d& x) { return faintHeadHu(x.norm(), 1.0); });
  const imaging::Volume alone = cubeAboutOrigin(110, 0.5, [](const Eigen::Vector3d& x) { return faintHeadHu(x.norm(), 0); });
  for (const Eigen::Vector3d& u : {Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(1, 1, 1).normalized(),
                                   Eigen::Vector3d(-0.2, 0.5, -0.8).normalized()}) {
    const imaging::Edge valley = imaging::firstValleyAlongRay(across_gap, Eigen::Vector3d::Zero(), u, 6.0, 26.0, {});
    ASSERT_TRUE(valley.found) << u.transpose();
    EXPECT_NEAR(valley.offset_mm, 20.0, 0.25) << u.transpose();
    // Alone, the head's edge has no valley beyond it: soft tissue, no rise.
    EXPECT_FALSE(imaging::firstValleyAlongRay(alone, Eigen::Vector3d::Zero(), u, 6.0, 26.0, {}).found) << u.transpose();
    const imaging::Edge edge = imaging::firstEdgeAlongRay(alone, Eigen::Vector3d::Zero(), u, 6.0, 26.0, {});
    ASSERT_TRUE(edge.found);
    EXPECT_NEAR(edge.offset_mm, 20.0, 0.25);
  }
}

// A screw in the head (a 3.25 mm rod at 3,071 HU, a CT's ceiling, its tip
// beyond the centre) lies on the rays cast from the centre: its fall is the
// steepest on them, and the first. The ray's edge is the head's cortex all
// the same.
TEST(Edges, FirstEdgeAlongARayIsTheBoneNotAScrewInIt) {
  const Eigen::Vector3d axis = Eigen::Vector3d(1, 0.3, -0.2).normalized();
  const imaging::Volume v = cubeAboutOrigin(70, 0.7, [&](const Eigen::Vector3d& x) {
    const double bone = headHu(x.norm()), from_axis = (x - x.dot(axis) * axis).norm();
    // From outside the bone at -25 mm to its tip 10 mm beyond the centre.
    const double screw =
        Phi((3.25 - from_axis) / kSigma) * Phi((x.dot(axis) + 25) / kSigma) * Phi((10 - x.dot(axis)) / kSigma);
    return bone + (3071 - bone) * screw;
  });
  // Past its tip (its fall at 10 mm), across it (at 3.25 mm) and aslant.
  for (const Eigen::Vector3d& u : {axis, Eigen::Vector3d(axis.cross(Eigen::Vector3d::UnitZ()).normalized()),
                                   Eigen::Vector3d(0, 1, 1).normalized()}) {
    const imaging::Edge e = imaging::firstEdgeAlongRay(v, Eigen::Vector3d::Zero(), u, 0.0, 30.0, {});
    ASSERT_TRUE(e.found);
    EXPECT_NEAR(e.offset_mm, 20.0, 0.25) << u.transpose();
  }
}

}  // namespace
}  // namespace articula
