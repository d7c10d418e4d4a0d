// Departures of a bone's mesh from its fitted head, on an exact sphere mesh
// reshaped where the answer is known in closed form: a dome flattened by a
// plane, an outward bump on the cap's rim, a pit at the medial pole, a neck
// rising beyond the rim with and without a lip at the junction, a raised
// dome with and without the socket's bone beyond it, a surface running on
// past half a radius.
#include <algorithm>
#include <cmath>
#include <functional>

#include <gtest/gtest.h>

#include "articula/geometry/surface.hpp"
#include "articula/checks/cap_departures.hpp"
#include "articula/imaging/image.hpp"

namespace articula::checks {
namespace {

constexpr double kRadius = 20;

geometry::ShapeParameters sphere() {
  geometry::ShapeParameters s;
  s.model = geometry::ShapeModel::Sphere;
  s.radii = Eigen::Vector3d::Constant(kRadius);
  s.center = Eigen::Vector3d(10, -30, 5);
  return s;
}

// The sphere's exact mesh (about 0.4 mm edges) and, as articular points,
// its vertices more than 60 degrees above the south pole (the neck's side)
// and away from `skip` (the dome the selection would leave out).
struct Case {
  CapDepartureInput input;
  Case() {
    const geometry::SurfaceMesh mesh = geometry::makeSurface(sphere())->sample(320, 160);
    input.vertices = mesh.vertices;
    input.triangles = mesh.triangles;
    input.model = sphere();
    input.medial = Eigen::Vector3d::UnitX();
  }
  Eigen::Vector3d local(Eigen::Index v) const { return input.vertices.row(v).transpose() - sphere().center; }
  void choosePoints(double skip_above_z) {
    std::vector<Eigen::Index> rows;
    for (Eigen::Index v = 0; v < input.vertices.rows(); ++v)
      if (local(v).z() > -0.5 * kRadius && local(v).z() < skip_above_z) rows.push_back(v);
    input.points.resize(static_cast<Eigen::Index>(rows.size()), 3);
    for (size_t i = 0; i < rows.size(); ++i) input.points.row(static_cast<Eigen::Index>(i)) = input.vertices.row(rows[i]);
  }
  // Moves vertices within `reach` mm of the surface point along `direction`
  // radially by height * (1 - (s / reach)^2): a smooth bump (or pit, height < 0).
  void bump(const Eigen::Vector3d& direction, double reach, double height) {
    const Eigen::Vector3d apex = kRadius * direction.normalized();
    for (Eigen::Index v = 0; v < input.vertices.rows(); ++v) {
      const double s = (local(v) - apex).norm();
      if (s < reach)
        input.vertices.row(v) += (height * (1 - (s / reach) * (s / reach)) * local(v).normalized()).transpose();
    }
  }
};

TEST(CapDepartures, AnExactSphereDepartsNowhere) {
  Case c;
  c.choosePoints(kRadius);
  const CapDepartures d = capDepartures(c.input);
  EXPECT_TRUE(d.regions.empty());
  EXPECT_NEAR(d.threshold_mm, 0.75, 1e-9);
  // The cap: from the pole to 120 degrees (the 98th percentile of the points' angles, 118).
  EXPECT_NEAR(d.cap_axis.z(), 1, 1e-3);
  EXPECT_NEAR(d.cap_half_angle_deg, 118, 2);
  const double cap_area = 2 * M_PI * kRadius * kRadius * (1 - std::cos(120 * M_PI / 180));
  EXPECT_NEAR(d.cap_area_mm2, cap_area, 0.03 * cap_area);
}

TEST(CapDepartures, AFlattenedDomeIsMeasuredInAreaAndDepth) {
  Case c;
  const double h = 0.12 * kRadius, plane = kRadius - h;  // cut 2.4 mm below the top
  for (Eigen::Index v = 0; v < c.input.vertices.rows(); ++v)
    if (c.local(v).z() > plane) c.input.vertices(v, 2) = sphere().center.z() + plane;
  c.choosePoints(plane - 0.5);
  const CapDepartures d = capDepartures(c.input);
  ASSERT_EQ(d.regions.size(), 1u);
  const DepartingRegion& dome = d.regions[0];
  EXPECT_EQ(dome.kind, "inward");
  EXPECT_NEAR(dome.depth_mm, h, 0.05);
  // The flat's part more than t below the sphere: a disc of radius^2 = (R - t)^2 - (R - h)^2.
  const double t = d.threshold_mm, expected = M_PI * ((kRadius - t) * (kRadius - t) - plane * plane);
  EXPECT_NEAR(dome.area_mm2, expected, 0.08 * expected);
  EXPECT_GT(dome.direction.z(), 0.99);
  EXPECT_EQ(dome.where, "superior");
  EXPECT_NEAR(d.largestFindingMm2(), dome.area_mm2, 1e-9);  // 2.4 mm deep: a finding
  // Every vertex of the region, and only those, is marked with it: on the plane, deeper than t.
  ASSERT_EQ(d.region_of_vertex.size(), static_cast<size_t>(c.input.vertices.rows()));
  for (Eigen::Index v = 0; v < c.input.vertices.rows(); ++v) {
    const bool deep = std::abs(c.local(v).z() - plane) < 1e-9 && c.local(v).norm() < kRadius - t - 1e-6;
    const bool edge = std::abs(c.local(v).norm() - (kRadius - t)) < 0.05;  // rounding at the border
    if (!edge) {
      EXPECT_EQ(d.region_of_vertex[static_cast<size_t>(v)], deep ? 0 : -1) << v;
    }
  }
}

TEST(CapDepartures, ADomeLeftOutIsMeasuredWhenAChannelWithoutPointsJoinsItToTheNecksSide) {
  // The dome flattened as above, its hole in the points joined to the part
  // beyond the cap by a strip 12 degrees wide without points, down a
  // meridian: as a selection's band, a few points off, can leave it. The
  // dome is measured as it is without the channel, not taken for the neck's
  // side and left unmeasured.
  Case c;
  const double h = 0.12 * kRadius, plane = kRadius - h;
  for (Eigen::Index v = 0; v < c.input.vertices.rows(); ++v)
    if (c.local(v).z() > plane) c.input.vertices(v, 2) = sphere().center.z() + plane;
  c.choosePoints(plane - 0.5);
  const CapDepartures closed = capDepartures(c.input);
  ASSERT_EQ(closed.regions.size(), 1u);
  std::vector<Eigen::Index> kept;
  for (Eigen::Index i = 0; i < c.input.points.rows(); ++i) {
    const Eigen::Vector3d x = c.input.points.row(i).transpose() - sphere().center;
    if (!(x.x() > 0 && std::abs(std::atan2(x.y(), x.x())) < 6 * M_PI / 180)) kept.push_back(i);
  }
  ASSERT_LT(kept.size(), static_cast<size_t>(c.input.points.rows()));
  const Eigen::MatrixX3d points = c.input.points(kept, Eigen::all);
  c.input.points = points;
  const CapDepartures channel = capDepartures(c.input);
  ASSERT_EQ(channel.regions.size(), 1u);
  EXPECT_EQ(channel.regions[0].kind, "inward");
  EXPECT_NEAR(channel.regions[0].area_mm2, closed.regions[0].area_mm2, 0.05 * closed.regions[0].area_mm2);
}

TEST(CapDepartures, AnOsteophyteOnTheRimIsOutwardAndAPitAtTheMedialPoleIsTheFovea) {
  Case c;
  c.choosePoints(kRadius);
  // The rim lies about 118 degrees from the pole; a 3 mm lip at 125 degrees, lateral.
  const double rim = 125 * M_PI / 180;
  c.bump(Eigen::Vector3d(-std::sin(rim), 0, std::cos(rim)), 4, 3);
  c.bump(Eigen::Vector3d::UnitX(), 5, -2);  // the fovea: 5 mm across, 2 mm deep, medial
  const CapDepartures d = capDepartures(c.input);
  ASSERT_EQ(d.regions.size(), 2u);
  const DepartingRegion* lip = nullptr;
  const DepartingRegion* fovea = nullptr;
  for (const auto& r : d.regions) (r.kind == "outward" ? lip : fovea) = &r;
  ASSERT_TRUE(lip && fovea);
  EXPECT_NEAR(lip->depth_mm, 3, 0.05);
  // The lip rises above t within s = 4 sqrt(1 - t/3) of its apex: the area
  // of a paraboloid of slope k rho (k = 2 x 3 / 4^2) to s on a plane; on
  // the sphere, pushed out radially by 0.75-3 mm, it stretches by
  // ((R + height) / R)^2: 1.08-1.32.
  const double k = 2.0 * 3 / 16, s = 4 * std::sqrt(1 - d.threshold_mm / 3);
  const double flat = 2 * M_PI / (3 * k * k) * (std::pow(1 + k * k * s * s, 1.5) - 1);
  EXPECT_GT(lip->area_mm2, 1.08 * flat);
  EXPECT_LT(lip->area_mm2, 1.32 * flat);
  EXPECT_EQ(lip->where, "lateral, inferior");
  EXPECT_EQ(fovea->kind, "fovea");
  EXPECT_NEAR(fovea->depth_mm, 2, 0.05);
  EXPECT_NEAR(d.largestFindingMm2(), lip->area_mm2, 1e-9);  // the fovea is anatomy, not a finding

  // Without the hip's medial side, the same pit is an inward departure,
  // listed, but at 2 mm deep no finding.
  c.input.medial.reset();
  const CapDepartures unsided = capDepartures(c.input);
  ASSERT_EQ(unsided.regions.size(), 2u);
  for (const auto& r : unsided.regions) EXPECT_NE(r.kind, "fovea");
  c.bump(Eigen::Vector3d::UnitX(), 5, 0.1);  // 1.9 mm deep
  EXPECT_NEAR(capDepartures(c.input).largestFindingMm2(), lip->area_mm2, 1.0);
}

TEST(CapDepartures, ANeckRisingOutOfTheHeadBeyondTheRimIsNoFinding) {
  Case c;
  c.choosePoints(kRadius);
  // Beyond the cap (past 120 degrees) the surface leaves the sphere outwards
  // and keeps rising to the zone's edge, as a neck wider than the head's
  // waist does: 0 at 125 degrees, 1 mm more every 5 degrees.
  for (Eigen::Index v = 0; v < c.input.vertices.rows(); ++v) {
    const double angle = std::acos(c.local(v).normalized().z()) * 180 / M_PI;
    if (angle > 125) c.input.vertices.row(v) += ((angle - 125) / 5 * c.local(v).normalized()).transpose();
  }
  EXPECT_TRUE(capDepartures(c.input).regions.empty());
}

// A CT of 1 mm voxels over the sphere and 15 mm about it: 500 HU where
// `bone` holds (of the position relative to the sphere's centre), 0 elsewhere.
// A CT of `hu` at each voxel (a function of the position from the centre).
imaging::Volume ctOf(const std::function<float(const Eigen::Vector3d&)>& hu) {
  imaging::Volume ct;
  ct.geometry.spacing = Eigen::Vector3d::Constant(1.0);
  ct.geometry.size = Eigen::Vector3i::Constant(70);
  ct.geometry.origin = sphere().center - Eigen::Vector3d::Constant(35);
  ct.voxels.resize(static_cast<size_t>(ct.geometry.voxelCount()));
  for (int k = 0; k < 70; ++k)
    for (int j = 0; j < 70; ++j)
      for (int i = 0; i < 70; ++i)
        ct.at(i, j, k) = hu(ct.geometry.toPhysical(Eigen::Vector3d(i, j, k)) - sphere().center);
  return ct;
}

// 500 HU where `bone`, 0 elsewhere.
imaging::Volume ctAbout(const std::function<bool(const Eigen::Vector3d&)>& bone) {
  return ctOf([&bone](const Eigen::Vector3d& x) { return bone(x) ? 500.0f : 0.0f; });
}

// A neck rising out of the head from 127 degrees (1 mm every 5 degrees, as
// above) with a lip at the junction: a bump `lip_mm` high, 4 mm in reach,
// at 126 degrees, joined to the neck. The CT: 500 HU inside the reshaped
// surface and 0 outside, or 500 HU everywhere where the bone goes on
// beyond the mesh (the head's label cut across the neck).
struct NeckWithLip {
  Case c;
  imaging::Volume ct;
  double lift(const Eigen::Vector3d& unit, double lip_mm) const {
    const double angle = std::acos(std::clamp(unit.z(), -1.0, 1.0)) * 180 / M_PI;
    const double at = 126 * M_PI / 180;
    const double s = (kRadius * unit - kRadius * Eigen::Vector3d(-std::sin(at), 0, std::cos(at))).norm();
    return (angle > 127 ? (angle - 127) / 5 : 0) + (s < 4 ? lip_mm * (1 - s * s / 16) : 0);
  }
  NeckWithLip(double lip_mm, bool bone_beyond) {
    c.choosePoints(kRadius);  // the points end at 120 degrees
    for (Eigen::Index v = 0; v < c.input.vertices.rows(); ++v) {
      const Eigen::Vector3d unit = c.local(v).normalized();
      c.input.vertices.row(v) += (lift(unit, lip_mm) * unit).transpose();
    }
    ct = ctAbout([&](const Eigen::Vector3d& x) { return bone_beyond || x.norm() < kRadius + lift(x.normalized(), lip_mm); });
    c.input.ct = &ct;
    c.input.seek_junction_lip = true;
  }
};

TEST(CapDepartures, ALipAtTheJunctionIsToldFromTheNeckItJoins) {
  NeckWithLip lipped(3, false);
  const CapDepartures d = capDepartures(lipped.c.input);
  ASSERT_EQ(d.regions.size(), 1u);
  const DepartingRegion& lip = d.regions[0];
  EXPECT_EQ(lip.kind, "outward");
  // Its crest, where it faces out as the head does (slope under tan 25
  // degrees = 0.466): on the head's side of 127 degrees, within 1.24 mm
  // of the apex (the bump's slope is 0.375 s); beyond, where the neck's
  // slope (0.573 along the meridian) and the bump's cancel, within 1.24
  // mm of a point 1.53 mm past the apex. The two parts of discs: 3.3 +
  // 4.8 mm^2 on a plane, by ((R + 3) / R)^2 = 1.32 on the sphere, 10.7
  // mm^2, and the vertices' areas at the border (0.4 mm edges) add up to a
  // third; their centre about 128.5 degrees from the pole.
  EXPECT_NEAR(lip.depth_mm, 3.2, 0.2);
  EXPECT_GT(lip.area_mm2, 10.7);
  EXPECT_LT(lip.area_mm2, 1.35 * 10.7);
  EXPECT_NEAR(lip.from_cap_axis_deg, 128.5, 1);
  EXPECT_EQ(lip.where, "lateral, inferior");
  EXPECT_NEAR(d.largestFindingMm2(), lip.area_mm2, 1e-9);

  // Without the CT nothing tells the lip from a cut across the neck: the
  // neck's region is no finding, lip and all.
  lipped.c.input.ct = nullptr;
  EXPECT_TRUE(capDepartures(lipped.c.input).regions.empty());
  // Nor on a shoulder, whose tuberosities stand out beside its neck.
  lipped.c.input.ct = &lipped.ct;
  lipped.c.input.seek_junction_lip = false;
  EXPECT_TRUE(capDepartures(lipped.c.input).regions.empty());
  // Bone beyond it: the label's cut across the neck, no lip.
  NeckWithLip cut(3, true);
  EXPECT_TRUE(capDepartures(cut.c.input).regions.empty());
  // A lip 2 mm high stands under kLipMinHeightMm: left with the neck.
  NeckWithLip low(2, false);
  EXPECT_TRUE(capDepartures(low.c.input).regions.empty());
  // The neck alone, with its CT.
  NeckWithLip none(0, false);
  EXPECT_TRUE(capDepartures(none.c.input).regions.empty());
}

// A dome raised 3 mm (6 mm in reach) at the pole, and a CT of 500 HU inside
// the raised surface and 0 outside; with a socket, bone of 500 HU also from
// 2 to 10 mm beyond the sphere, so that the raised dome reaches into it:
// the surface run into the socket across a gap the CT did not show.
struct RaisedDome {
  Case c;
  imaging::Volume ct;
  explicit RaisedDome(bool socket, float socket_hu = 500) {
    c.choosePoints(kRadius);
    c.bump(Eigen::Vector3d::UnitZ(), 6, 3);
    ct = ctOf([socket, socket_hu](const Eigen::Vector3d& x) {
      const double s = (x.normalized() * kRadius - kRadius * Eigen::Vector3d::UnitZ()).norm();
      if (x.norm() < kRadius + (s < 6 ? 3 * (1 - s * s / 36) : 0)) return 500.0f;
      return socket && x.norm() > kRadius + 2 && x.norm() < kRadius + 10 ? socket_hu : 0.0f;
    });
    c.input.ct = &ct;
  }
};

TEST(CapDepartures, ARegionWithBoneBeyondIsTheSurfaceRunIntoItNotTheHeadsBone) {
  RaisedDome socket(true);
  const CapDepartures d = capDepartures(socket.c.input);
  ASSERT_EQ(d.regions.size(), 1u);
  EXPECT_EQ(d.regions[0].kind, "bone_beyond");
  EXPECT_NEAR(d.regions[0].depth_mm, 3, 0.05);
  EXPECT_EQ(d.regions[0].where, "superior");
  EXPECT_EQ(d.largestFindingMm2(), 0);
  EXPECT_NEAR(d.largestBoneBeyondMm2(), d.regions[0].area_mm2, 1e-9);

  // A socket of cancellous bone, 200 HU beside the head's 500 (under half
  // of it), is bone all the same.
  RaisedDome dim(true, 200);
  ASSERT_EQ(capDepartures(dim.c.input).regions.size(), 1u);
  EXPECT_EQ(capDepartures(dim.c.input).regions[0].kind, "bone_beyond");

  // Soft tissue beyond: the head's own bone stands out.
  RaisedDome bare(false);
  const CapDepartures own = capDepartures(bare.c.input);
  ASSERT_EQ(own.regions.size(), 1u);
  EXPECT_EQ(own.regions[0].kind, "outward");
  EXPECT_NEAR(own.regions[0].area_mm2, d.regions[0].area_mm2, 1e-9);
  EXPECT_NEAR(own.largestFindingMm2(), own.regions[0].area_mm2, 1e-9);
  EXPECT_EQ(own.largestBoneBeyondMm2(), 0);
  // Without the CT nothing tells them apart.
  socket.c.input.ct = nullptr;
  EXPECT_EQ(capDepartures(socket.c.input).regions.at(0).kind, "outward");
}

// A surface that runs on past half a radius beyond the head (the socket's
// roof and the pelvis merged into the label) is another bone, with or
// without the CT; a raised dome that stays within it departs as before.
TEST(CapDepartures, ASurfaceRunningOnPastHalfARadiusIsAnotherBone) {
  Case merged;
  merged.choosePoints(kRadius);
  merged.bump(Eigen::Vector3d::UnitZ(), 8, 14);  // the apex 1.7 radii out
  const CapDepartures d = capDepartures(merged.input);
  ASSERT_EQ(d.regions.size(), 1u);
  EXPECT_EQ(d.regions[0].kind, "bone_beyond");
  EXPECT_EQ(d.regions[0].where, "superior");
  EXPECT_GT(d.regions[0].depth_mm, 0.45 * kRadius);
  EXPECT_EQ(d.largestFindingMm2(), 0);
  EXPECT_NEAR(d.largestBoneBeyondMm2(), d.regions[0].area_mm2, 1e-9);

  Case raised;
  raised.choosePoints(kRadius);
  raised.bump(Eigen::Vector3d::UnitZ(), 8, 8);  // 1.4 radii out
  const CapDepartures own = capDepartures(raised.input);
  ASSERT_EQ(own.regions.size(), 1u);
  EXPECT_EQ(own.regions[0].kind, "outward");
  EXPECT_NEAR(own.regions[0].depth_mm, 8, 0.05);
  EXPECT_NEAR(own.largestFindingMm2(), own.regions[0].area_mm2, 1e-9);
}

TEST(CapDepartures, ASurfaceShortOfADomeTheCtDoesNotPartFromTheSocketIsNoFlattening) {
  // The dome flattened 2.4 mm as above. With a CT whose bone goes on beyond
  // the flat (thick slices smear the head's edge into the socket's roof),
  // the surface there is no edge of the head; with the flattened head's CT,
  // the widened gap beyond it, it is a flattened dome.
  Case c;
  const double plane = kRadius - 0.12 * kRadius;
  for (Eigen::Index v = 0; v < c.input.vertices.rows(); ++v)
    if (c.local(v).z() > plane) c.input.vertices(v, 2) = sphere().center.z() + plane;
  c.choosePoints(plane - 0.5);
  const imaging::Volume smeared = ctAbout([](const Eigen::Vector3d& x) { return x.norm() < kRadius + 8; });
  c.input.ct = &smeared;
  const CapDepartures d = capDepartures(c.input);
  ASSERT_EQ(d.regions.size(), 1u);
  EXPECT_EQ(d.regions[0].kind, "bone_beyond");
  EXPECT_EQ(d.largestFindingMm2(), 0);
  EXPECT_NEAR(d.largestBoneBeyondMm2(), d.regions[0].area_mm2, 1e-9);
  const imaging::Volume flattened = ctAbout([plane](const Eigen::Vector3d& x) { return x.norm() < kRadius && x.z() < plane; });
  c.input.ct = &flattened;
  const CapDepartures own = capDepartures(c.input);
  ASSERT_EQ(own.regions.size(), 1u);
  EXPECT_EQ(own.regions[0].kind, "inward");
  EXPECT_NEAR(own.largestFindingMm2(), own.regions[0].area_mm2, 1e-9);
}

// The dome merged with the socket across thick slices: the points a band
// from 30 degrees below the equator to 24 above, so that the part without
// points about the pole (66 degrees around it) is larger than the neck's
// (60 degrees around the other pole).
TEST(CapDepartures, OnAHipThePartBeyondIsTheNecksSideThoughTheDomeLeftOutIsLarger) {
  RaisedDome merged(true);
  merged.c.choosePoints(0.4 * kRadius);
  const CapDepartures d = capDepartures(merged.c.input);
  ASSERT_EQ(d.regions.size(), 1u);
  EXPECT_EQ(d.regions[0].kind, "bone_beyond");
  EXPECT_EQ(d.regions[0].where, "superior");
  EXPECT_NEAR(d.regions[0].depth_mm, 3, 0.05);
  // Without a hip's sides the larger part, the dome's, is taken for the
  // neck's side, and nothing over it is measured.
  merged.c.input.medial.reset();
  EXPECT_TRUE(capDepartures(merged.c.input).regions.empty());
}

}  // namespace
}  // namespace articula::checks
