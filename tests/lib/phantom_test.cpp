// Phantom: tissues where the truth puts them, the model varied by seed, the
// femur truth label, and deterministic output; the options of the wider
// phantom (radius, gap, socket, osteoporotic bone, fovea, both hips) checked
// voxel by voxel against the exact distance to the true head; the clinical
// options (arthritis, a clipped field of view, metal, kernels, a contrast
// vessel, the table, thick slices) against their analytic geometry.
#include <algorithm>
#include <cmath>
#include <set>

#include <gtest/gtest.h>

#include "articula/core/error.hpp"
#include "articula/distance/signed_distance.hpp"
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

Eigen::Vector3d vec3(const nlohmann::json& j) { return {j[0].get<double>(), j[1].get<double>(), j[2].get<double>()}; }

phantom::PhantomOptions clean(unsigned long long seed) {
  phantom::PhantomOptions o;
  o.seed = seed;
  o.noise_hu = 0;
  o.blur_mm = 0;  // every voxel away from an interface holds its tissue's HU exactly
  o.exact_depth = true;
  o.spacing = Eigen::Vector3d(1.0, 1.0, 1.0);
  return o;
}

// Every voxel centre of a noise- and blur-free phantom whose distance to the
// nearest tissue boundary exceeds half the voxel diagonal (no partial volume)
// holds the HU of the tissue the exact signed distance d to the true head
// (less the fovea) puts it in: cancellous below the cortex, cortex, the gap's
// soft tissue for 0 < d < gap, the socket's cortex at the gap from the head
// (congruent socket, within its cone); and the femur label is 1 exactly where d < 0 near the head.
void expectTissuesFollowTheExactSurface(const phantom::PhantomOptions& o) {
  const phantom::Phantom p = phantom::makePhantom(o);
  const phantom::Hip& hip = p.hips[0];
  const distance::SignedDistance exact(hip.head);
  const imaging::ImageGeometry& g = p.ct.geometry;
  const double hd = 0.5 * g.spacing.norm() + 1e-6, cortex = o.cortical_mm, gap = o.gap_mm;
  const double r = hip.head.radii.maxCoeff();
  int checked[4] = {0, 0, 0, 0};
  for (int k = 0; k < g.size[2]; ++k)
    for (int j = 0; j < g.size[1]; ++j)
      for (int i = 0; i < g.size[0]; ++i) {
        const Eigen::Vector3d x = g.toPhysical(Eigen::Vector3d(i, j, k));
        const Eigen::Vector3d u = x - hip.head.center;
        if (u.norm() > r + gap + 4.0) continue;
        // Only the cap facing the socket: away from the neck and within the socket's cone.
        if (u.normalized().dot(hip.socket_axis) < std::cos(60.0 * M_PI / 180.0)) continue;
        const double dh = exact.closest(x).distance;  // to the head; the socket follows it
        const double d = phantom::headSurfaceDistance(hip, dh, x);  // to the head less the pit
        const float hu = p.ct.at(i, j, k);
        EXPECT_EQ(p.femur.at(i, j, k), d < 0 ? 1 : 0) << "d " << d;
        if (d < -cortex - hd && d > -cortex - 3.0) {
          if (o.cancellous_variation_hu == 0) {
            EXPECT_FLOAT_EQ(hu, float(o.cancellous_hu)) << "d " << d;
          } else {
            EXPECT_LE(std::fabs(hu - o.cancellous_hu), o.cancellous_variation_hu + 1e-3) << "d " << d;
          }
          ++checked[0];
        } else if (d > -cortex + hd && d < -hd) {
          EXPECT_FLOAT_EQ(hu, float(o.cortical_hu)) << "d " << d;
          ++checked[1];
        } else if (d > hd && dh < gap - hd) {
          EXPECT_FLOAT_EQ(hu, float(o.soft_tissue_hu)) << "d " << d;
          ++checked[2];
        } else if (o.congruent_socket && dh > gap + hd && dh < gap + cortex - hd) {
          EXPECT_FLOAT_EQ(hu, float(o.socket_cortical_hu.value_or(o.cortical_hu))) << "d " << d;
          ++checked[3];
        }
      }
  // Each tissue was actually met (the cortex and the socket's only where thicker than a voxel).
  EXPECT_GT(checked[0], 100);
  EXPECT_GT(checked[2], 100);
  if (cortex > 2 * hd) {
    EXPECT_GT(checked[1], 100);
  }
  if (o.congruent_socket && cortex > 2 * hd) {
    EXPECT_GT(checked[3], 100);
  }
}

TEST(Phantom, TissuesFollowTheExactHeadSurface) {
  phantom::PhantomOptions o = clean(4);
  o.model = geometry::ShapeModel::Superovoid;
  o.gap_mm = 3.0;
  o.cortical_mm = 2.5;  // thicker than the 1 mm voxels' diagonal, so pure cortex voxels exist
  expectTissuesFollowTheExactSurface(o);
}

TEST(Phantom, NarrowGapSmallHeadWithFovea) {
  phantom::PhantomOptions o = clean(6);
  o.spacing = Eigen::Vector3d(0.6, 0.6, 0.6);
  o.model = geometry::ShapeModel::Superellipsoid;
  o.gap_mm = 1.5;
  o.head_radius_mm = 17.0;
  o.fovea = true;
  expectTissuesFollowTheExactSurface(o);
}

TEST(Phantom, OsteoporoticBoneInASphericalSocket) {
  phantom::PhantomOptions o = clean(7);
  o.model = geometry::ShapeModel::Ellipsoid;
  o.makeOsteoporotic();
  o.congruent_socket = false;
  o.head_radius_range_mm = Eigen::Vector2d(17, 30);
  expectTissuesFollowTheExactSurface(o);
  const phantom::Phantom p = phantom::makePhantom(o);
  // Cancellous HU below 200 in places and above in others; the faint cortex.
  float lowest = 1e9f, highest = -1e9f;
  for (float v : p.ct.voxels) lowest = std::min(lowest, v), highest = std::max(highest, v);
  EXPECT_EQ(highest, 700.0f);
  int below = 0, above = 0;
  const imaging::ImageGeometry& g = p.ct.geometry;
  for (int k = 0; k < g.size[2]; ++k)
    for (int j = 0; j < g.size[1]; ++j)
      for (int i = 0; i < g.size[0]; ++i)
        if (p.femur.at(i, j, k) == 1 && p.ct.at(i, j, k) > o.soft_tissue_hu + 1 && p.ct.at(i, j, k) < 699)
          (p.ct.at(i, j, k) < 200 ? below : above)++;
  EXPECT_GT(below, 1000);
  EXPECT_GT(above, 1000);
  // The spherical socket: its inner sphere is gap_mm beyond the head's bounding sphere at the pole
  // and wider towards the rim, as truth.json says.
  const phantom::Hip& hip = p.hips[0];
  const double r = hip.head.radii.maxCoeff();
  EXPECT_NEAR(p.truth["socket"]["inner_radius_mm"].get<double>(), r + o.gap_mm + o.socket_excess_mm, 1e-12);
  EXPECT_NEAR((hip.socket_center - hip.head.center).norm(), o.socket_excess_mm, 1e-12);
  EXPECT_GE(r, 17.0 * 0.94);
  EXPECT_LE(r, 30.0 * 1.06);
}

// The joint gap along rays from a sphere's centre within the socket's cone,
// measured on the CT (blur-free, partial volume by supersampling) as the
// distance between the two half-way crossings of cortex and soft tissue:
// the requested gap, congruent or, at the pole of a spherical socket.
TEST(Phantom, GapAlongRaysIsTheRequestedGap) {
  for (double gap : {1.5, 4.0}) {
    phantom::PhantomOptions o = clean(9);
    o.model = geometry::ShapeModel::Sphere;
    o.spacing = Eigen::Vector3d(0.6, 0.6, 0.6);
    o.gap_mm = gap;
    o.head_radius_mm = 24.0;
    const phantom::Phantom p = phantom::makePhantom(o);
    const imaging::ImageGeometry& g = p.ct.geometry;
    auto trilinear = [&](const Eigen::Vector3d& x) {
      const Eigen::Vector3d f = g.toIndex(x);
      const int i = int(std::floor(f[0])), j = int(std::floor(f[1])), k = int(std::floor(f[2]));
      const double a = f[0] - i, b = f[1] - j, c = f[2] - k;
      double v = 0;
      for (int n = 0; n < 8; ++n)
        v += (n & 1 ? a : 1 - a) * (n & 2 ? b : 1 - b) * (n & 4 ? c : 1 - c) * p.ct.at(i + (n & 1), j + (n >> 1 & 1), k + (n >> 2 & 1));
      return v;
    };
    const double level = 0.5 * (o.cortical_hu + o.soft_tissue_hu);
    const Eigen::Vector3d axis = p.hips[0].socket_axis;
    const Eigen::Vector3d side = axis.cross(Eigen::Vector3d::UnitZ()).normalized();
    for (double tilt : {0.0, 0.3, 0.6}) {
      const Eigen::Vector3d d = (axis + tilt * side).normalized();
      auto crossing = [&](double from, double to) {  // where the profile crosses the level, by bisection
        const bool rising = trilinear(p.head.center + to * d) > level;
        for (int n = 0; n < 60; ++n) {
          const double mid = 0.5 * (from + to);
          ((trilinear(p.head.center + mid * d) > level) == rising ? to : from) = mid;
        }
        return 0.5 * (from + to);
      };
      const double head = crossing(24.0 - 0.9, 24.0 + 0.5 * gap), socket = crossing(24.0 + 0.5 * gap, 24.0 + gap + 0.9);
      EXPECT_NEAR(head, 24.0, 0.15) << "gap " << gap << " tilt " << tilt;
      EXPECT_NEAR(socket - head, gap, 0.2) << "gap " << gap << " tilt " << tilt;
    }
  }
}

TEST(Phantom, FoveaIsAPitOnTheHead) {
  phantom::PhantomOptions o = clean(11);
  o.model = geometry::ShapeModel::Sphere;
  o.head_radius_mm = 22.0;
  o.fovea = true;
  const phantom::Phantom p = phantom::makePhantom(o);
  const phantom::Hip& hip = p.hips[0];
  ASSERT_TRUE(hip.fovea);
  const Eigen::Vector3d d = (hip.fovea_center - hip.head.center).normalized();
  EXPECT_NEAR((hip.fovea_center - hip.head.center).norm(), 22.0 + o.fovea_radius_mm - o.fovea_depth_mm, 1e-6);
  EXPECT_EQ(vec3(p.truth["fovea"]["center_mm"]), hip.fovea_center);
  // In the pit: soft tissue where the sphere alone would be cortex; beside it, cortex.
  const Eigen::Vector3d in_pit = hip.head.center + (22.0 - 0.5 * o.fovea_depth_mm) * d;
  EXPECT_FLOAT_EQ(huAt(p, in_pit), float(o.soft_tissue_hu));
  EXPECT_GT(phantom::headSurfaceDistance(hip, -0.5 * o.fovea_depth_mm, in_pit), 0.0);
  const Eigen::Vector3d away = (d + 0.6 * d.cross(Eigen::Vector3d::UnitZ()).normalized()).normalized();
  EXPECT_FLOAT_EQ(huAt(p, hip.head.center + 21.3 * away), float(o.cortical_hu));
  // Below the pit's floor the head is bone again.
  EXPECT_GT(huAt(p, hip.head.center + (22.0 - o.fovea_depth_mm - 0.8) * d), 1000.0);
}

TEST(Phantom, BothHipsWhereTheTruthSays) {
  phantom::PhantomOptions o;
  o.seed = 12;
  o.both_hips = true;
  o.right = false;  // the left head is the top-level truth and label 1
  o.spacing = Eigen::Vector3d(1.5, 1.5, 3.0);
  o.ras_storage = true;
  o.gap_mm = 2.0;
  o.head_radius_range_mm = Eigen::Vector2d(17, 30);
  const phantom::Phantom p = phantom::makePhantom(o);
  ASSERT_EQ(p.hips.size(), 2u);
  ASSERT_EQ(p.truth["hips"].size(), 2u);
  EXPECT_FALSE(p.hips[0].right);
  EXPECT_TRUE(p.hips[1].right);
  EXPECT_EQ(p.truth["side"], "left");
  EXPECT_EQ(p.truth["hips"][1]["side"], "right");
  const Eigen::Vector3d left = vec3(p.truth["hips"][0]["head_center_mm"]), right = vec3(p.truth["hips"][1]["head_center_mm"]);
  EXPECT_GT(left[0], 80.0);
  EXPECT_LT(right[0], -80.0);
  EXPECT_GT((left - right).norm(), 170.0);
  EXPECT_LT((left - right).norm(), 200.0);
  for (int n = 0; n < 2; ++n) {
    const Eigen::Vector3d idx = p.femur.geometry.toIndex(p.hips[n].head.center);
    const int i = int(std::lround(idx[0])), j = int(std::lround(idx[1])), k = int(std::lround(idx[2]));
    EXPECT_EQ(p.femur.at(i, j, k), n + 1);
    EXPECT_NEAR(p.ct.at(i, j, k), o.cancellous_hu, 4 * o.noise_hu);
  }
  // The requested side's head is the single-hip phantom's of the same seed.
  phantom::PhantomOptions single = o;
  single.both_hips = false;
  EXPECT_EQ(phantom::makePhantom(single).head.center, p.head.center);
  // Bone at the midline (sacrum and symphysis), none in a single-hip phantom's field there.
  const Eigen::Vector3d mid = 0.5 * (left + right);
  EXPECT_GT(huAt(p, Eigen::Vector3d(0, mid[1] + 65.0, mid[2] + 30.0)), 200.0);
  EXPECT_GT(huAt(p, Eigen::Vector3d(0, mid[1] - 45.0, mid[2] - 20.0)), 200.0);
}

TEST(Phantom, RadiusOptions) {
  phantom::PhantomOptions o;
  o.spacing = Eigen::Vector3d(3, 3, 3);
  o.model = geometry::ShapeModel::Sphere;
  o.head_radius_mm = 17.0;
  EXPECT_EQ(phantom::makePhantom(o).head.radii[0], 17.0);
  o.head_radius_mm.reset();
  o.head_radius_range_mm = Eigen::Vector2d(17, 30);
  std::set<double> radii;
  for (unsigned long long seed = 0; seed < 8; ++seed) {
    o.seed = seed;
    const double r = phantom::makePhantom(o).head.radii[0];
    EXPECT_GE(r, 17.0);
    EXPECT_LE(r, 30.0);
    radii.insert(std::floor(r / 4.0));
  }
  EXPECT_GE(radii.size(), 3u);  // the draws spread over the range
  o.head_radius_mm = 50.0;
  EXPECT_THROW(phantom::makePhantom(o), UsageError);
  o.head_radius_mm.reset();
  o.head_radius_range_mm = Eigen::Vector2d(30, 17);
  EXPECT_THROW(phantom::makePhantom(o), UsageError);
}


// A flattened dome: above the plane fraction x radius below the top, soft
// tissue where the sphere was bone; just below it, new cortex; the recorded
// area is the cut cap's, 2 pi r h.
TEST(Phantom, FlattenedDomeIsCutByAPlaneUnderNewCortex) {
  phantom::PhantomOptions o = clean(13);
  o.model = geometry::ShapeModel::Sphere;
  o.head_radius_mm = 22.0;
  o.cortical_mm = 2.5;  // thicker than the voxels' diagonal: pure cortex voxels under the cut
  o.flattened_dome = 0.2;
  const phantom::Phantom p = phantom::makePhantom(o);
  const phantom::Hip& hip = p.hips[0];
  ASSERT_TRUE(hip.flat_dome);
  const Eigen::Vector3d c = hip.head.center, up = Eigen::Vector3d::UnitZ();
  const double r = 22.0, h = 0.2 * r, plane_z = c.z() + r - h;
  EXPECT_NEAR((hip.flat_dome->top - (c + r * up)).norm(), 0.0, 1e-3);  // flat at the top: its place along the surface is loose
  EXPECT_NEAR(hip.flat_dome->point.z(), plane_z, 1e-5);
  const nlohmann::json& d = p.truth["departures"][0];
  EXPECT_EQ(d["kind"], "flattened_dome");
  EXPECT_EQ(d["surface_change"], "inward");
  EXPECT_NEAR(d["max_depth_mm"].get<double>(), h, 1e-5);
  EXPECT_NEAR(d["area_mm2"].get<double>(), 2 * M_PI * r * h, 0.005 * 2 * M_PI * r * h);
  EXPECT_NEAR((vec3(d["direction"]) - up).norm(), 0.0, 1e-5);
  const imaging::ImageGeometry& g = p.ct.geometry;
  const double hd = 0.5 * g.spacing.norm() + 1e-6;
  int above = 0, cortex = 0;
  for (int k = 0; k < g.size[2]; ++k)
    for (int j = 0; j < g.size[1]; ++j)
      for (int i = 0; i < g.size[0]; ++i) {
        const Eigen::Vector3d x = g.toPhysical(Eigen::Vector3d(i, j, k));
        if ((x - c).norm() > r - hd) continue;  // inside the sphere, clear of its surface
        const double over = x.z() - plane_z;
        if (over > hd) {
          EXPECT_FLOAT_EQ(p.ct.at(i, j, k), float(o.soft_tissue_hu)) << over;
          EXPECT_EQ(p.femur.at(i, j, k), 0);
          ++above;
        } else if (over < -hd && over > -o.cortical_mm + hd) {
          EXPECT_FLOAT_EQ(p.ct.at(i, j, k), float(o.cortical_hu)) << over;
          ++cortex;
        }
      }
  EXPECT_GT(above, 100);
  EXPECT_GT(cortex, 100);
  // The true surface the scorer reads back: on the plane over the cut, the sphere elsewhere.
  const phantom::Hip back = phantom::hipFromTruth(p.truth);
  const Eigen::Vector3d on_plane = c + (r - h) * up + 3.0 * Eigen::Vector3d::UnitX();
  EXPECT_NEAR(phantom::headSurfaceDistance(back, (on_plane - c).norm() - r, on_plane), 0.0, 1e-9);
  const Eigen::Vector3d side = c + r * Eigen::Vector3d::UnitY();
  EXPECT_NEAR(phantom::headSurfaceDistance(back, 0.0, side), 0.0, 1e-9);
}

// Osteophytes: a lip whose axis runs on the head along the head-neck
// junction (the neck's radius from its axis), bone up to its height outside
// the head; its recorded area is the band of the sphere within its radius of
// that arc, R^2 dphi (cos(t - e) - cos(t + e)) plus a cap of angular radius
// e at the two ends, e = 2 asin(rho / 2R).
TEST(Phantom, OsteophytesRingTheHeadNeckJunction) {
  phantom::PhantomOptions o = clean(14);
  o.model = geometry::ShapeModel::Sphere;
  o.head_radius_mm = 22.0;
  o.osteophytes_mm = 3.0;
  const phantom::Phantom p = phantom::makePhantom(o);
  const phantom::Hip& hip = p.hips[0];
  ASSERT_TRUE(hip.osteophytes);
  const double R = 22.0, rho = 3.0, neck = 0.68 * R;
  const Eigen::Vector3d c = hip.head.center, a = hip.neck_axis;
  double from_axis_max = 0;
  for (const Eigen::Vector3d& q : hip.osteophytes->path) {
    EXPECT_NEAR((q - c).norm(), R, 1e-6);
    const Eigen::Vector3d u = q - c;
    from_axis_max = std::max(from_axis_max, std::abs((u - u.dot(a) * a).norm() - neck));
  }
  EXPECT_LT(from_axis_max, 1e-6);
  // Bone half the lip's height beyond the head surface at each path point.
  for (size_t n = 0; n < hip.osteophytes->path.size(); n += 5) {
    const Eigen::Vector3d q = hip.osteophytes->path[n];
    const Eigen::Vector3d out = q + 0.5 * rho * (q - c).normalized();
    EXPECT_GE(huAt(p, out), o.cancellous_hu);
    const Eigen::Vector3d idx = p.femur.geometry.toIndex(out);
    EXPECT_EQ(p.femur.at(int(std::lround(idx[0])), int(std::lround(idx[1])), int(std::lround(idx[2]))), 1);
  }
  const double theta = std::asin(neck / R), e = 2 * std::asin(rho / (2 * R)), dphi = 150.0 * M_PI / 180.0;
  const double area = R * R * dphi * (std::cos(theta - e) - std::cos(theta + e)) + 2 * M_PI * R * R * (1 - std::cos(e));
  const nlohmann::json& d = p.truth["departures"][0];
  EXPECT_EQ(d["kind"], "osteophytes");
  EXPECT_EQ(d["surface_change"], "outward");
  EXPECT_NEAR(d["area_mm2"].get<double>(), area, 0.01 * area);
  EXPECT_EQ(d["max_depth_mm"].get<double>(), rho);
  // The superior side of the junction: the lip's middle lies above the neck axis.
  EXPECT_GT((vec3(d["centre_mm"]) - c).dot(Eigen::Vector3d::UnitZ()), (a * R).z());
  const phantom::Hip back = phantom::hipFromTruth(p.truth);
  ASSERT_TRUE(back.osteophytes);
  const Eigen::Vector3d tip = hip.osteophytes->path[10] + rho * (hip.osteophytes->path[10] - c).normalized();
  EXPECT_NEAR(phantom::headSurfaceDistance(back, rho, tip), 0.0, 1e-9);
}

// Subchondral cysts: fluid-HU balls 2-5 mm across whose walls lie just under
// the cortex of the superior cap.
TEST(Phantom, CystsLieJustUnderTheCortex) {
  phantom::PhantomOptions o = clean(15);
  o.model = geometry::ShapeModel::Sphere;
  o.head_radius_mm = 24.0;
  o.spacing = Eigen::Vector3d(0.6, 0.6, 0.6);
  o.cysts = true;
  const phantom::Phantom p = phantom::makePhantom(o);
  const phantom::Hip& hip = p.hips[0];
  ASSERT_EQ(hip.cysts.size(), 3u);
  const Eigen::Vector3d c = hip.head.center;
  for (const phantom::Cyst& cyst : hip.cysts) {
    EXPECT_GE(cyst.radius_mm, 1.0);
    EXPECT_LE(cyst.radius_mm, 2.5);
    const double under = 24.0 - (cyst.center - c).norm() - cyst.radius_mm;  // cyst wall to the surface
    EXPECT_NEAR(under, o.cortical_mm + 0.3, 1e-6);
    EXPECT_GT((cyst.center - c).normalized().z(), std::cos(40.0 * M_PI / 180.0));
    EXPECT_FLOAT_EQ(huAt(p, cyst.center), float(o.cyst_hu));
    // Beyond the cyst, towards the centre: cancellous bone again.
    EXPECT_FLOAT_EQ(huAt(p, cyst.center + (cyst.radius_mm + 1.0) * (c - cyst.center).normalized()), float(o.cancellous_hu));
  }
  EXPECT_EQ(p.truth["departures"][0]["kind"], "cysts");
  EXPECT_EQ(p.truth["departures"][0]["cysts"].size(), 3u);
}

// A narrowed joint: along superior the gap between the half-way crossings
// is the narrow gap; along the socket's axis (43 degrees from superior)
// the joint's own; the recorded patch is the cap within 32 degrees.
TEST(Phantom, NarrowGapOverTheSuperiorPatch) {
  phantom::PhantomOptions o = clean(16);
  o.model = geometry::ShapeModel::Sphere;
  o.spacing = Eigen::Vector3d(0.6, 0.6, 0.6);
  o.head_radius_mm = 23.0;
  o.gap_mm = 3.0;
  o.narrow_gap_mm = 0.8;
  const phantom::Phantom p = phantom::makePhantom(o);
  const Eigen::Vector3d c = p.head.center;
  const imaging::ImageGeometry& g = p.ct.geometry;
  auto trilinear = [&](const Eigen::Vector3d& x) {
    const Eigen::Vector3d f = g.toIndex(x);
    const int i = int(std::floor(f[0])), j = int(std::floor(f[1])), k = int(std::floor(f[2]));
    const double a = f[0] - i, b = f[1] - j, cc = f[2] - k;
    double v = 0;
    for (int n = 0; n < 8; ++n)
      v += (n & 1 ? a : 1 - a) * (n & 2 ? b : 1 - b) * (n & 4 ? cc : 1 - cc) * p.ct.at(i + (n & 1), j + (n >> 1 & 1), k + (n >> 2 & 1));
    return v;
  };
  const double level = 0.5 * (o.cortical_hu + o.soft_tissue_hu);
  auto crossing = [&](const Eigen::Vector3d& d, double from, double to) {
    const bool rising = trilinear(c + to * d) > level;
    for (int n = 0; n < 60; ++n) {
      const double mid = 0.5 * (from + to);
      ((trilinear(c + mid * d) > level) == rising ? to : from) = mid;
    }
    return 0.5 * (from + to);
  };
  const auto gapAlong = [&](const Eigen::Vector3d& d, double gap) {
    const double head = crossing(d, 23.0 - 0.9, 23.0 + 0.5 * gap);
    return crossing(d, 23.0 + 0.5 * gap, 23.0 + gap + 0.9) - head;
  };
  EXPECT_NEAR(gapAlong(Eigen::Vector3d::UnitZ(), 0.8), 0.8, 0.15);
  EXPECT_NEAR(gapAlong(p.hips[0].socket_axis, 3.0), 3.0, 0.2);
  const nlohmann::json& d = p.truth["departures"][0];
  EXPECT_EQ(d["kind"], "narrow_gap");
  const double patch = 2 * M_PI * 23.0 * 23.0 * (1 - std::cos(32.0 * M_PI / 180.0));
  EXPECT_NEAR(d["area_mm2"].get<double>(), patch, 0.005 * patch);
  EXPECT_EQ(d["gap_mm"].get<double>(), 0.8);
}

// The arthritic options change the head alone: voxels far from it, noise
// included, are the default phantom's of the same seed.
TEST(Phantom, ArthritisLeavesTheRestOfTheSeedsCt) {
  phantom::PhantomOptions o;
  o.seed = 17;
  o.spacing = Eigen::Vector3d(2, 2, 2);
  const phantom::Phantom plain = phantom::makePhantom(o);
  o.flattened_dome = 0.1;
  o.osteophytes_mm = 2;
  o.cysts = true;
  o.narrow_gap_mm = 1;
  const phantom::Phantom arthritic = phantom::makePhantom(o);
  EXPECT_EQ(plain.head.center, arthritic.head.center);
  const imaging::ImageGeometry& g = plain.ct.geometry;
  ASSERT_EQ(g.size, arthritic.ct.geometry.size);
  int same = 0, different = 0;
  const double r = plain.head.radii.maxCoeff();
  for (int k = 0; k < g.size[2]; ++k)
    for (int j = 0; j < g.size[1]; ++j)
      for (int i = 0; i < g.size[0]; ++i) {
        const bool far = (g.toPhysical(Eigen::Vector3d(i, j, k)) - plain.head.center).norm() > r + o.gap_mm + o.socket_wall_mm + 12;
        if (far) {
          EXPECT_EQ(plain.ct.at(i, j, k), arthritic.ct.at(i, j, k));
          ++same;
        } else {
          different += plain.ct.at(i, j, k) != arthritic.ct.at(i, j, k);
        }
      }
  EXPECT_GT(same, 1000);
  EXPECT_GT(different, 100);
  EXPECT_EQ(arthritic.truth["departures"].size(), 4u);
  EXPECT_FALSE(plain.truth.contains("departures"));
  o.narrow_gap_mm = o.gap_mm;
  EXPECT_THROW(phantom::makePhantom(o), UsageError);
}

// A clipped field of view: the stored grid's last layer of voxel centres
// lies on the plane fraction x radius inside the head's extent along the
// face; the head's farthest point beyond it is outside the grid, and the
// layer at the plane still holds the head's bone.
TEST(Phantom, FieldOfViewCutEndsTheGridInsideTheHead) {
  for (const auto& [face, ras] : {std::pair<std::string, bool>{"+z", false}, {"-x", true}, {"A", false}}) {
    phantom::PhantomOptions o = clean(18);
    o.model = geometry::ShapeModel::Sphere;
    o.head_radius_mm = 22.0;
    o.spacing = Eigen::Vector3d(1.0, 1.0, 1.5);
    o.ras_storage = ras;
    o.fov_cut = 0.25;
    o.fov_face = phantom::faceDirection(face);
    const phantom::Phantom p = phantom::makePhantom(o);
    const Eigen::Vector3d u = o.fov_face, c = p.head.center;
    const double plane = c.dot(u) + 22.0 - 0.25 * 22.0;
    const imaging::ImageGeometry& g = p.ct.geometry;
    double farthest = -1e9;
    for (int corner = 0; corner < 8; ++corner) {
      const Eigen::Vector3d idx((corner & 1) * (g.size[0] - 1), (corner >> 1 & 1) * (g.size[1] - 1), (corner >> 2 & 1) * (g.size[2] - 1));
      farthest = std::max(farthest, g.toPhysical(idx).dot(u));
    }
    EXPECT_NEAR(farthest, plane, 1e-9) << face;
    // The head's top along the face: beyond the last voxels.
    const Eigen::Vector3d top_index = g.toIndex(c + 22.0 * u);
    EXPECT_TRUE((top_index.array() < -0.5).any() || (top_index.array() > g.size.cast<double>().array() - 0.5).any()) << face;
    // On the plane, on the head's axis: cancellous bone, the head cut open.
    EXPECT_FLOAT_EQ(huAt(p, c + (plane - c.dot(u)) * u), float(o.cancellous_hu)) << face;
    EXPECT_NEAR(p.truth["fov_cut"]["fraction_of_radius"].get<double>(), 0.25, 1e-6) << face;
    EXPECT_EQ(vec3(p.truth["fov_cut"]["face"]), u) << face;
    EXPECT_EQ(p.truth["grid"]["size"][0].get<int>(), g.size[0]);
    EXPECT_EQ(vec3(p.truth["grid"]["origin_mm"]), g.origin);
    EXPECT_EQ(p.femur.geometry.size, g.size);
    EXPECT_EQ(p.femur.geometry.origin, g.origin);
  }
  EXPECT_THROW(phantom::faceDirection("+w"), UsageError);
}

// Metal: a screw along the neck axis from under the dome, a stem down the
// shaft; dense (above 2,500 HU along the axis, clipped at 3,071); streaks
// in the slices through it (soft tissue far from the metal off by hundreds
// of HU) and none elsewhere (slices without metal are the plain phantom's,
// noise included).
TEST(Phantom, MetalScrewAndStemWithStreaks) {
  for (const auto metal : {phantom::PhantomOptions::Metal::Screw, phantom::PhantomOptions::Metal::Stem}) {
    phantom::PhantomOptions o;
    o.seed = 19;
    o.model = geometry::ShapeModel::Sphere;
    o.head_radius_mm = 22.0;
    o.spacing = Eigen::Vector3d(1.0, 1.0, 2.0);
    const phantom::Phantom plain = phantom::makePhantom(o);
    o.metal = metal;
    const phantom::Phantom p = phantom::makePhantom(o);
    const Eigen::Vector3d from = vec3(p.truth["metal"]["from_mm"]), to = vec3(p.truth["metal"]["to_mm"]);
    const Eigen::Vector3d c = p.head.center;
    if (metal == phantom::PhantomOptions::Metal::Screw) {
      EXPECT_EQ(p.truth["metal"]["kind"], "screw");
      EXPECT_NEAR((from - c).normalized().dot(-p.neck_axis), 1.0, 1e-9);  // into the head, opposite the neck
      EXPECT_NEAR((to - c).normalized().dot(p.neck_axis), 1.0, 1e-9);
      EXPECT_NEAR((from - c).norm(), 22.0 - 6.0, 1e-6);                  // 6 mm under the dome
    } else {
      EXPECT_EQ(p.truth["metal"]["kind"], "stem");
      EXPECT_NEAR((to - from).normalized().z(), -1.0, 1e-12);
    }
    int dense = 0;
    for (double t = 0.05; t <= 0.95; t += 0.05) {
      const Eigen::Vector3d idx = p.ct.geometry.toIndex(from + t * (to - from));
      if ((idx.array() < 0).any() || (idx.array() > p.ct.geometry.size.cast<double>().array() - 1).any()) continue;  // a stem runs on beyond the field
      EXPECT_GT(huAt(p, from + t * (to - from)), 2500.0) << t;
      ++dense;
    }
    EXPECT_GE(dense, 6);
    const auto [lowest, highest] = std::minmax_element(p.ct.voxels.begin(), p.ct.voxels.end());
    EXPECT_EQ(*highest, 3071.0f);
    EXPECT_GE(*lowest, -1024.0f);
    // Per slice: streaks where the slice holds metal, the plain phantom elsewhere.
    const imaging::ImageGeometry& g = p.ct.geometry;
    int streaked = 0, untouched = 0;
    for (int k = 0; k < g.size[2]; ++k) {
      const double z = g.toPhysical(Eigen::Vector3d(0, 0, k)).z();
      const bool has_metal = z > std::min(from.z(), to.z()) + 4 && z < std::max(from.z(), to.z()) - 4;
      const bool clear = z < std::min(from.z(), to.z()) - 8 || z > std::max(from.z(), to.z()) + 8;  // beyond the blur
      int off = 0;
      bool same = true;
      for (int j = 0; j < g.size[1]; ++j)
        for (int i = 0; i < g.size[0]; ++i) {
          same = same && p.ct.at(i, j, k) == plain.ct.at(i, j, k);
          const Eigen::Vector3d x = g.toPhysical(Eigen::Vector3d(i, j, k));
          if (plain.femur.at(i, j, k) == 0 && (x - c).norm() > 45 && std::abs(p.ct.at(i, j, k) - plain.ct.at(i, j, k)) > 100) ++off;
        }
      if (has_metal) streaked += off > 20;
      if (clear) {
        EXPECT_TRUE(same) << "slice " << k;
        ++untouched;
      }
    }
    EXPECT_GT(streaked, 5);
    EXPECT_GT(untouched, 5);
  }
  EXPECT_THROW(phantom::metalFromName("plate"), UsageError);
}

// Noise in a block of soft tissue far from bone: its standard deviation and
// the correlation of in-plane neighbours.
std::pair<double, double> softTissueNoise(const phantom::Phantom& p) {
  const imaging::ImageGeometry& g = p.ct.geometry;
  const Eigen::Vector3d idx = g.toIndex(p.head.center + Eigen::Vector3d(0, -45, 0));  // anterior, in soft tissue
  double sum = 0, sum2 = 0, cross = 0;
  int n = 0;
  for (int k = int(idx[2]) - 4; k <= int(idx[2]) + 4; ++k)
    for (int j = int(idx[1]) - 3; j <= int(idx[1]) + 3; ++j)
      for (int i = int(idx[0]) - 8; i <= int(idx[0]) + 8; ++i) {
        const double v = p.ct.at(i, j, k) - 40.0, w = p.ct.at(i + 1, j, k) - 40.0;
        sum += v, sum2 += v * v, cross += v * w, ++n;
      }
  const double var = sum2 / n - (sum / n) * (sum / n);
  return {std::sqrt(var), (cross / n - (sum / n) * (sum / n)) / var};
}

// The kernels: soft halves the noise and correlates neighbours; sharp
// raises it, and overshoots each edge (noise-free: HU above the cortex's
// and below the soft tissue's beside the head's surface, which the standard
// kernel never leaves).
TEST(Phantom, KernelsSmoothOrSharpenEdgesAndNoise) {
  phantom::PhantomOptions o;
  o.seed = 20;
  o.model = geometry::ShapeModel::Sphere;
  o.head_radius_mm = 22.0;
  o.spacing = Eigen::Vector3d(1.0, 1.0, 1.5);
  o.cortical_mm = 2.5;
  const auto [standard_sd, standard_corr] = softTissueNoise(phantom::makePhantom(o));
  o.kernel = phantom::PhantomOptions::Kernel::Soft;
  const auto [soft_sd, soft_corr] = softTissueNoise(phantom::makePhantom(o));
  o.kernel = phantom::PhantomOptions::Kernel::Sharp;
  const phantom::Phantom sharp = phantom::makePhantom(o);
  const auto [sharp_sd, sharp_corr] = softTissueNoise(sharp);
  EXPECT_NEAR(standard_sd, 20.0, 2.5);
  EXPECT_LT(std::abs(standard_corr), 0.1);
  EXPECT_LT(soft_sd, 0.6 * standard_sd);
  EXPECT_GT(soft_corr, 0.3);
  EXPECT_GT(sharp_sd, 1.6 * standard_sd);
  EXPECT_GT(std::abs(sharp_corr), 0.1);
  EXPECT_EQ(sharp.truth["kernel"], "sharp");
  // Noise-free: the range along in-plane rays across the head's surface.
  o.noise_hu = 0;
  for (const auto kernel : {phantom::PhantomOptions::Kernel::Standard, phantom::PhantomOptions::Kernel::Sharp}) {
    o.kernel = kernel;
    const phantom::Phantom p = phantom::makePhantom(o);
    double highest = -1e9, lowest = 1e9;
    for (double angle = 0; angle < 2 * M_PI; angle += 0.2) {
      const Eigen::Vector3d d(std::cos(angle), std::sin(angle), 0);
      if (d.dot(p.hips[0].socket_axis) > 0) continue;  // away from the socket
      for (double t = 18.0; t <= 26.0; t += 0.2) {
        const double v = huAt(p, p.head.center + t * d);
        highest = std::max(highest, v);
        if (t > 22.0) lowest = std::min(lowest, v);
      }
    }
    if (kernel == phantom::PhantomOptions::Kernel::Sharp) {
      EXPECT_GT(highest, o.cortical_hu + 50);
      EXPECT_LT(lowest, o.soft_tissue_hu - 50);
    } else {
      EXPECT_LE(highest, o.cortical_hu + 1);
      EXPECT_GE(lowest, o.soft_tissue_hu - 1);
    }
  }
}

// A contrast vessel anterior-medial to the head at 300 HU, its wall 5 mm off
// the head's bounding sphere; a table behind the body, air beyond it.
TEST(Phantom, ContrastVesselAndTable) {
  phantom::PhantomOptions o = clean(21);
  o.model = geometry::ShapeModel::Sphere;
  o.head_radius_mm = 22.0;
  o.contrast_vessel = true;
  o.table = true;
  const phantom::Phantom p = phantom::makePhantom(o);
  const Eigen::Vector3d c = p.head.center;
  const Eigen::Vector3d at = vec3(p.truth["contrast_vessel"]["point_mm"]), along = vec3(p.truth["contrast_vessel"]["direction"]);
  // At the head's level: the vessel's axis 22 + 5 + 3 mm from the centre, anterior (-y) and medial (+x for a right hip).
  EXPECT_NEAR((at - c).norm(), 30.0, 1e-9);
  EXPECT_LT((at - c).y(), -25.0);
  EXPECT_GT((at - c).x(), 5.0);
  for (double t = -30; t <= 0; t += 5) EXPECT_FLOAT_EQ(huAt(p, at + t * along), float(o.vessel_hu)) << t;  // above, the socket's bone stays
  EXPECT_FLOAT_EQ(huAt(p, at + 4.0 * Eigen::Vector3d(0, -1, 0)), float(o.soft_tissue_hu));
  // The table: the grid's posterior end holds its slab, then air.
  const imaging::ImageGeometry& g = p.ct.geometry;
  const double axis_y = p.truth["table"]["axis_xy_mm"][1].get<double>(), r = 400.0;
  const double x = c.x(), top = axis_y + std::sqrt(r * r - x * x);  // the slab's inner surface at this x
  EXPECT_FLOAT_EQ(huAt(p, Eigen::Vector3d(x, top + 3.0, c.z())), 700.0f);
  EXPECT_FLOAT_EQ(huAt(p, Eigen::Vector3d(x, top + 12.0, c.z())), -1000.0f);
  EXPECT_FLOAT_EQ(huAt(p, Eigen::Vector3d(x, top - 3.0, c.z())), float(o.soft_tissue_hu));
  phantom::PhantomOptions plain = clean(21);
  plain.model = o.model;
  plain.head_radius_mm = o.head_radius_mm;
  const double grown = (g.size[1] - phantom::makePhantom(plain).ct.geometry.size[1]) * g.spacing[1];
  EXPECT_NEAR(grown, 26.0, 1.0);
}

// Thick slices: along the vertical through a sphere's centre, each slice is
// the mean of the thin profile (head, gap, socket) over a box of the
// thickness about it, as sampled by slices 4 times finer.
TEST(Phantom, ThickSlicesAverageABoxAcrossTheSlices) {
  phantom::PhantomOptions o = clean(22);
  o.model = geometry::ShapeModel::Sphere;
  o.head_radius_mm = 22.0;
  o.spacing = Eigen::Vector3d(1.0, 1.0, 2.0);
  o.slice_thickness_mm = 4.0;
  const phantom::Phantom p = phantom::makePhantom(o);
  const Eigen::Vector3d c = p.head.center;
  const double top = c.z() + 22.0;
  const auto thin = [&](double z) {  // the head's cortex and bone, the gap, the congruent socket's cortex and bone
    const double d = z - top, gap = o.gap_mm, cortex = o.cortical_mm;
    if (d > gap + cortex) return o.cancellous_hu;
    if (d > gap) return o.cortical_hu;
    if (d > 0) return o.soft_tissue_hu;
    return d > -cortex ? o.cortical_hu : o.cancellous_hu;
  };
  const imaging::ImageGeometry& g = p.ct.geometry;
  const Eigen::Vector3d idx = g.toIndex(c);
  const int i = int(std::lround(idx[0])), j = int(std::lround(idx[1]));
  int compared = 0;
  for (int k = 0; k < g.size[2]; ++k) {
    const Eigen::Vector3d x = g.toPhysical(Eigen::Vector3d(i, j, k));
    if (std::abs(x.z() - top) > 6.0) continue;
    // The box over the slices rendered 4 times finer (0.5 mm): the fine
    // slices weighted by their overlap with it, 1/8 each and 1/16 at the ends.
    double expected = 0;
    for (int q = -4; q <= 4; ++q)
      for (int n = 0; n < 1000; ++n)
        expected += (std::abs(q) == 4 ? 1.0 / 16 : 1.0 / 8) * thin(x.z() + 0.5 * (q - 0.5 + (n + 0.5) / 1000)) / 1000;
    EXPECT_NEAR(p.ct.at(i, j, k), expected, 20.0) << "z - top " << x.z() - top;  // partial volume: 3 samples across a fine slice
    EXPECT_EQ(p.femur.at(i, j, k), (x - c).norm() < 22.0 ? 1 : 0);
    ++compared;
  }
  EXPECT_GE(compared, 5);
  EXPECT_EQ(p.truth["slice_thickness_mm"].get<double>(), 4.0);
}

}  // namespace
}  // namespace articula
