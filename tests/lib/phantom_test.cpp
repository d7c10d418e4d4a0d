// Phantom: tissues where the truth puts them, the model varied by seed, the
// femur truth label, and deterministic output.
#include <set>

#include <gtest/gtest.h>

#include "articula/core/error.hpp"
#include "articula/geometry/surface.hpp"
#include "articula/phantom/phantom.hpp"

namespace articula {
namespace {

double huAt(const phantom::Phantom& p, const Eigen::Vector3d& x) {
  const Eigen::Vector3d idx = p.ct.geometry.toIndex(x);
  return p.ct.at(int(std::lround(idx[0])), int(std::lround(idx[1])), int(std::lround(idx[2])));
}

TEST(Phantom, TissuesSitWhereTheTruthSays) {
  for (bool ras : {false, true}) {
    phantom::PhantomOptions o;
    o.seed = 3;
    o.gap_mm = 4.0;
    o.noise_hu = 0;
    o.ras_storage = ras;
    const phantom::Phantom p = phantom::makePhantom(o);
    const Eigen::Vector3d c = p.head.center;
    EXPECT_NEAR(huAt(p, c), o.cancellous_hu, 1.0);
    // Along the socket axis: cortex just inside the head, soft tissue mid-gap, bone in the socket.
    const Eigen::Vector3d a(p.truth["socket_axis"][0], p.truth["socket_axis"][1], p.truth["socket_axis"][2]);
    const auto head = geometry::makeSurface(p.head);
    double t = 0;  // the head surface along the axis, by bisection on F
    for (double lo = 0, hi = 40; hi - lo > 1e-6; t = 0.5 * (lo + hi)) (head->value(c + 0.5 * (lo + hi) * a) < 0 ? lo : hi) = 0.5 * (lo + hi);
    EXPECT_GT(huAt(p, c + (t - 0.75) * a), 800.0);
    EXPECT_LT(huAt(p, c + (t + 2.0) * a), 200.0);
    EXPECT_GT(huAt(p, c + (t + 5.0) * a), 600.0);
    EXPECT_EQ(p.femur.at(0, 0, 0), 0);
    const Eigen::Vector3d idx = p.femur.geometry.toIndex(c);
    EXPECT_EQ(p.femur.at(int(std::lround(idx[0])), int(std::lround(idx[1])), int(std::lround(idx[2]))), 1);
    EXPECT_EQ(p.truth["coordinate_system"], "LPS");
    EXPECT_EQ(p.truth["head_center_mm"][0].get<double>(), c[0]);
  }
}

TEST(Phantom, SeedsVaryTheModelAndRepeatExactly) {
  std::set<std::string> models;
  for (unsigned long long seed = 0; seed < 5; ++seed) {
    phantom::PhantomOptions o;
    o.seed = seed;
    o.spacing = Eigen::Vector3d(3, 3, 3);
    models.insert(phantom::makePhantom(o).truth["model"].get<std::string>());
  }
  EXPECT_EQ(models.size(), 5u);
  phantom::PhantomOptions o;
  o.spacing = Eigen::Vector3d(2, 2, 3);
  EXPECT_EQ(phantom::makePhantom(o).ct.voxels, phantom::makePhantom(o).ct.voxels);
  o.right = false;
  EXPECT_GT(phantom::makePhantom(o).head.center[0], 0.0);  // left hip: +x in LPS
  o.gap_mm = 0;
  EXPECT_THROW(phantom::makePhantom(o), UsageError);
}

}  // namespace
}  // namespace articula
