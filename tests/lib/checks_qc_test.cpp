// Head checks: a head's cap passes; each wrong structure fails the check
// made to reveal it (a socket's inner surface, a small trochanter-like
// blob, a cut cap, a non-spherical patch, a search that found elsewhere,
// a side the search could not tell, points inside the bone, a shell label
// off the CT's edges at coarse voxels, a socket's outer surface that faces
// no socket, a head on the body's midline); a cortex blurred away across
// the slices warns, and so do a head at the other joint's distance from
// the body's middle, a field of view that ends inside the head and a
// surface run into bone beyond the head.
#include <cmath>
#include <functional>

#include <gtest/gtest.h>

#include "articula/geometry/fibonacci.hpp"
#include "articula/checks/qc.hpp"

namespace articula {
namespace {

/// Points of a sphere cap of half-angle `cap_deg` about +z, with normals
/// pointing outwards (or inwards, as a socket's inner surface has them).
checks::HeadQcInput cap(double radius, double cap_deg, bool inward_normals = false) {
  checks::HeadQcInput in;
  const int n = 800;
  const Eigen::Vector3d centre(-90, -10, 30);
  in.points.resize(n, 3);
  in.normals.resize(n, 3);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d u = geometry::fibonacciDirection(i, n, std::cos(cap_deg * M_PI / 180));
    in.points.row(i) = (centre + radius * u).transpose();
    in.normals.row(i) = (inward_normals ? -u : u).transpose();
  }
  in.sphere_center = centre;
  in.sphere_radius_mm = radius;
  return in;
}

/// The standard normal distribution function.
double Phi(double z) { return 0.5 * std::erfc(-z / std::sqrt(2.0)); }

const checks::QcCheck& check(const checks::QcReport& r, const std::string& name) {
  for (const auto& c : r.checks)
    if (c.name == name) return c;
  throw std::runtime_error("no check " + name);
}

TEST(HeadQc, AFemoralHeadsCapPasses) {
  checks::HeadQcInput in = cap(23, 85);
  in.search_center = in.sphere_center + Eigen::Vector3d(0.5, 0, 0);
  in.search_radius_mm = 23.4;
  const checks::QcReport r = checks::checkHead(in);
  EXPECT_EQ(r.status, "pass") << r.toJson().dump();
  EXPECT_TRUE(r.reasons().empty());
  EXPECT_EQ(r.checks.size(), 7u);
  EXPECT_EQ(check(r, "stage_warnings").value, 0);
}

TEST(HeadQc, AStagesWarningAndASurfaceLeftOnTheLabelAreNamedChecks) {
  checks::HeadQcInput in = cap(23, 85);
  in.stage_warnings = {"2 file(s) of ct/ are in no DICOM series", "the search took the larger head"};
  in.surface_on_ct_edges = false;
  const checks::QcReport r = checks::checkHead(in);
  EXPECT_EQ(r.status, "warn");
  const checks::QcCheck& warned = check(r, "stage_warnings");
  EXPECT_EQ(warned.status, "warn");
  EXPECT_EQ(warned.value, 2);
  EXPECT_NE(warned.reason.find("no DICOM series; the search took the larger head"), std::string::npos) << warned.reason;
  EXPECT_EQ(check(r, "surface_on_ct_edges").status, "warn");
  EXPECT_NE(check(r, "surface_on_ct_edges").reason.find("voxel staircase"), std::string::npos);
  // Neither is a doubt about the structure: two of them do not fail the head.
  EXPECT_FALSE(warned.of_structure);
}

TEST(HeadQc, ASocketsInnerSurfaceFailsOnItsNormals) {
  const checks::QcReport r = checks::checkHead(cap(26, 80, true));
  EXPECT_EQ(r.status, "fail");
  EXPECT_EQ(check(r, "normals_outward_share").status, "fail");
  EXPECT_EQ(check(r, "head_radius_mm").status, "pass");  // its radius alone would not tell
}

TEST(HeadQc, ATrochanterSizedSphereFailsOnItsRadius) {
  const checks::QcReport r = checks::checkHead(cap(11, 80));
  EXPECT_EQ(check(r, "head_radius_mm").status, "fail");
  EXPECT_EQ(r.status, "fail");
  EXPECT_NE(r.reasons().front().find("not that of a joint head"), std::string::npos);
}

TEST(HeadQc, ACutCapFailsOrWarnsOnItsExtent) {
  EXPECT_EQ(check(checks::checkHead(cap(23, 20)), "cap_half_angle_deg").status, "fail");
  EXPECT_EQ(check(checks::checkHead(cap(23, 40)), "cap_half_angle_deg").status, "warn");
  EXPECT_EQ(check(checks::checkHead(cap(23, 60)), "cap_half_angle_deg").status, "pass");
}

TEST(HeadQc, ANonSphericalPatchFailsOnItsSpread) {
  checks::HeadQcInput in = cap(23, 80);
  // An elongated blob (axes 13, 15 and 20 mm scaled to a 23 mm mean): its sphere leaves >8 % RMS.
  for (Eigen::Index i = 0; i < in.points.rows(); ++i) {
    const Eigen::Vector3d d = in.points.row(i).transpose() - in.sphere_center;
    in.points.row(i) = (in.sphere_center + d.cwiseProduct(Eigen::Vector3d(0.75, 0.9, 1.3))).transpose();
  }
  EXPECT_EQ(check(checks::checkHead(in), "sphere_rms_relative").status, "fail");
}

TEST(HeadQc, ASearchThatFoundAnotherStructureFails) {
  checks::HeadQcInput in = cap(23, 85);
  in.search_center = in.sphere_center + Eigen::Vector3d(0, 12, 0);  // half a radius away
  in.search_radius_mm = 16;
  const checks::QcReport r = checks::checkHead(in);
  EXPECT_EQ(check(r, "search_centre_offset_relative").status, "fail");
  EXPECT_EQ(check(r, "search_radius_difference_relative").status, "fail");
}

// The search's sphere right, the points on a larger surface (head and socket
// joined in the label): the radii 16 % apart fail, 10 % apart warn.
TEST(HeadQc, ASearchRadiusFarFromTheFitsFails) {
  checks::HeadQcInput in = cap(23, 85);
  in.search_center = in.sphere_center;
  in.search_radius_mm = 23.0 * 0.84;
  EXPECT_EQ(check(checks::checkHead(in), "search_radius_difference_relative").status, "fail");
  in.search_radius_mm = 23.0 * 0.90;
  EXPECT_EQ(check(checks::checkHead(in), "search_radius_difference_relative").status, "warn");
  in.search_radius_mm = 23.0 * 0.97;
  EXPECT_EQ(check(checks::checkHead(in), "search_radius_difference_relative").status, "pass");
}

TEST(HeadQc, AnUnverifiedSideWarns) {
  checks::HeadQcInput in = cap(23, 85);
  in.side_verified = true;
  EXPECT_EQ(checks::checkHead(in).status, "pass");
  in.side_verified = false;
  const checks::QcReport r = checks::checkHead(in);
  EXPECT_EQ(r.status, "warn");
  EXPECT_EQ(check(r, "side_verified").status, "warn");
  EXPECT_NE(check(r, "side_verified").reason.find("side could not be verified"), std::string::npos);
}

TEST(HeadQc, AHeadAtTheOtherJointsDistanceFromTheMiddleWarnsAndOneOnTheMidlineFails) {
  // The cap's centre lies at x = -90 mm.
  checks::HeadQcInput in = cap(23, 85);
  in.joint = "hip";
  in.body_middle_x_mm = 0;
  EXPECT_EQ(check(checks::checkHead(in), "head_from_body_middle_mm").status, "pass");
  EXPECT_DOUBLE_EQ(check(checks::checkHead(in), "head_from_body_middle_mm").value, 90);
  in.joint = "shoulder";  // a shoulder run on a hip CT
  checks::QcReport r = checks::checkHead(in);
  EXPECT_EQ(check(r, "head_from_body_middle_mm").status, "warn");
  EXPECT_NE(check(r, "head_from_body_middle_mm").reason.find("is this a hip CT?"), std::string::npos);
  in.body_middle_x_mm = 45;  // 135 mm from the middle: a humeral head's place
  EXPECT_EQ(check(checks::checkHead(in), "head_from_body_middle_mm").status, "pass");
  in.joint = "hip";
  r = checks::checkHead(in);
  EXPECT_EQ(check(r, "head_from_body_middle_mm").status, "warn");
  EXPECT_NE(check(r, "head_from_body_middle_mm").reason.find("is this a shoulder CT?"), std::string::npos);
  in.body_middle_x_mm = -80;  // 10 mm: a vertebra or the symphysis
  r = checks::checkHead(in);
  EXPECT_EQ(check(r, "head_from_body_middle_mm").status, "fail");
  EXPECT_EQ(r.status, "fail");
  in.body_middle_x_mm.reset();  // no middle measured: no check
  EXPECT_THROW(check(checks::checkHead(in), "head_from_body_middle_mm"), std::runtime_error);
}

TEST(HeadQc, AHeadTheFieldOfViewClipsWarnsOrFails) {
  // A 1 mm grid over x, y in [-40, 40] and z up to a face `cut` of the
  // radius into the head (centre 0, radius 20, its cap facing +z, the neck -z).
  const auto share = [](double cut) {
    imaging::ImageGeometry grid;
    grid.origin = Eigen::Vector3d(-40, -40, -40);
    grid.spacing = Eigen::Vector3d::Ones();
    grid.size = Eigen::Vector3i(81, 81, static_cast<int>(std::lround(40 + 20 * (1 - cut))) + 1);
    checks::HeadQcInput in = cap(20, 80);
    in.points.rowwise() -= in.sphere_center.transpose();
    in.sphere_center.setZero();
    return checks::headOutsideVolumeShare(grid, in.points, in.sphere_center, 20);
  };
  EXPECT_EQ(share(0), 0);
  // Beyond a plane at 0.9 r lies (1 - 0.9) / 2 of a sphere; of the sphere
  // less the neck's 45-degree cone, (0.05) / (1 - (1 - cos 45) / 2).
  const double neck_free = 1 - (1 - std::cos(M_PI / 4)) / 2;
  EXPECT_NEAR(share(0.1), 0.05 / neck_free, 0.01);
  EXPECT_NEAR(share(0.25), 0.125 / neck_free, 0.01);
  EXPECT_NEAR(share(0.5), 0.25 / neck_free, 0.01);
  checks::HeadQcInput in = cap(23, 85);
  in.head_outside_volume_share = share(0.1);
  EXPECT_EQ(check(checks::checkHead(in), "head_outside_volume_share").status, "warn");
  in.head_outside_volume_share = share(0.5);
  const checks::QcReport r = checks::checkHead(in);
  EXPECT_EQ(check(r, "head_outside_volume_share").status, "fail");
  EXPECT_NE(check(r, "head_outside_volume_share").reason.find("the field of view clips the head"), std::string::npos);
}

// A field of view that ends on the neck's side: a face 0.9 r from the centre
// towards -z, where the cap's points (about +z) put the neck. The share
// leaves the neck's cone out and misses the cut; how far the sphere reaches
// beyond the last voxels (0.1 of the radius, a tenth of the radius cut)
// names it, on every face and orientation of the grid.
TEST(HeadQc, AFieldOfViewCutOnTheNecksSideWarns) {
  const auto grid = [](const Eigen::Vector3d& face, bool ras) {
    imaging::ImageGeometry g;  // 1 x 1 x 1.5 mm over +-39 mm about the centre 0, cut at 18 mm on `face`
    g.spacing = Eigen::Vector3d(1, 1, 1.5);
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(-39), hi = Eigen::Vector3d::Constant(39);
    for (int a = 0; a < 3; ++a)
      if (face[a] > 0) hi[a] = 18; else if (face[a] < 0) lo[a] = -18;
    for (int a = 0; a < 3; ++a) g.size[a] = static_cast<int>(std::lround((hi[a] - lo[a]) / g.spacing[a])) + 1;
    g.origin = lo;
    if (ras) {
      g.direction = Eigen::Vector3d(-1, -1, 1).asDiagonal();
      g.origin = Eigen::Vector3d(lo[0] + (g.size[0] - 1) * g.spacing[0], lo[1] + (g.size[1] - 1) * g.spacing[1], lo[2]);
    }
    return g;
  };
  checks::HeadQcInput in = cap(20, 80);
  in.points.rowwise() -= in.sphere_center.transpose();
  in.sphere_center.setZero();
  const imaging::ImageGeometry neck_side = grid(-Eigen::Vector3d::UnitZ(), false);
  EXPECT_LT(checks::headOutsideVolumeShare(neck_side, in.points, in.sphere_center, 20), 0.02);
  for (int a = 0; a < 3; ++a)
    for (double sign : {-1.0, 1.0})
      for (bool ras : {false, true}) {
        const Eigen::Vector3d face = sign * Eigen::Vector3d::Unit(a);
        EXPECT_NEAR(checks::headBeyondFieldOfView(grid(face, ras), in.sphere_center, 20), 2.0, 1e-9) << face.transpose();
      }
  EXPECT_EQ(checks::headBeyondFieldOfView(grid(Eigen::Vector3d::Zero(), false), in.sphere_center, 20), 0.0);
  in.head_beyond_fov_mm = checks::headBeyondFieldOfView(neck_side, in.sphere_center, 20);
  checks::QcReport r = checks::checkHead(in);
  EXPECT_EQ(check(r, "head_beyond_fov_relative").status, "warn");
  EXPECT_NEAR(check(r, "head_beyond_fov_relative").value, 0.1, 1e-9);
  EXPECT_NE(check(r, "head_beyond_fov_relative").reason.find("the field of view ends inside the head"), std::string::npos);
  EXPECT_EQ(r.status, "warn");  // of the data's coverage: no doubt about the structure
  in.head_beyond_fov_mm = 0.5;  // 0.025 of the radius: a tangent's reach
  EXPECT_EQ(check(checks::checkHead(in), "head_beyond_fov_relative").status, "pass");
}

TEST(HeadQc, AHeadTheSearchTookByItsFallbackWarns) {
  checks::HeadQcInput in = cap(23, 85);
  in.found_by_edges = true;
  EXPECT_EQ(checks::checkHead(in).status, "pass");
  in.found_by_edges = false;
  in.side_verified = false;  // neither is a doubt about the structure: together they only warn
  const checks::QcReport r = checks::checkHead(in);
  EXPECT_EQ(r.status, "warn");
  EXPECT_EQ(check(r, "head_found_by_edges").status, "warn");
  EXPECT_NE(check(r, "head_found_by_edges").reason.find("its fallback"), std::string::npos);
}

TEST(HeadQc, MetalNearTheHeadWarns) {
  // A 1 mm grid of bone (1,800 HU, below the metal threshold) with a screw,
  // 3 x 3 x 20 voxels of 3,000 HU, 30 mm from the head's centre, and another
  // 60 mm away (beyond two radii of a 20 mm head).
  imaging::Volume ct;
  ct.geometry.size = Eigen::Vector3i(100, 100, 40);
  ct.geometry.origin = Eigen::Vector3d(-50, -50, -20);
  ct.voxels.assign(static_cast<size_t>(ct.geometry.voxelCount()), 1800.0f);
  for (int x : {30, 60})
    for (int k = 10; k < 30; ++k)
      for (int j = 49; j < 52; ++j)
        for (int i = 49 + x; i < 52 + x && i < 100; ++i) ct.at(i, j, k) = 3000.0f;
  const Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  EXPECT_DOUBLE_EQ(checks::metalNearHead(ct, centre, 20), 3 * 3 * 20);  // the near screw whole, the far one not
  EXPECT_DOUBLE_EQ(checks::metalNearHead(ct, centre, 10), 0);
  checks::HeadQcInput in = cap(23, 85);
  in.metal_near_head_mm3 = checks::metalNearHead(ct, centre, 20);
  const checks::QcReport r = checks::checkHead(in);
  EXPECT_EQ(check(r, "metal_near_head_mm3").status, "warn");
  EXPECT_EQ(r.status, "warn");
  in.metal_near_head_mm3 = 0;
  EXPECT_EQ(check(checks::checkHead(in), "metal_near_head_mm3").status, "pass");
}

TEST(HeadQc, ANoisyCtWarnsByItsOwnNameAndIsNoDoubtOfThePoints) {
  // The segmentation's measure of a sharp kernel over 100 HU of noise, and
  // of a phantom at 20 HU.
  checks::HeadQcInput in = cap(23, 85);
  in.ct_noise_hu = 157;
  const checks::QcReport r = checks::checkHead(in);
  EXPECT_EQ(check(r, "ct_noise_hu").status, "warn");
  EXPECT_FALSE(check(r, "ct_noise_hu").of_structure);
  EXPECT_NE(check(r, "ct_noise_hu").reason.find("smoothed copy"), std::string::npos);
  EXPECT_EQ(r.status, "warn");
  in.ct_noise_hu = 20;
  EXPECT_EQ(check(checks::checkHead(in), "ct_noise_hu").status, "pass");
}

TEST(HeadQc, ArticularPointsOnTheLabelsCutWarnAndMostlySoFail) {
  // The sample stage kept 1,665 of 1,677 points on the label's cut (an
  // osteoporotic head merged with its socket at 2.5 mm slices): they lie on
  // the cut, 3 mm outside the bone, where a correct cap keeps none.
  checks::HeadQcInput in = cap(23, 85);
  in.points_on_cut_share = 0.0;
  EXPECT_EQ(check(checks::checkHead(in), "articular_points_on_cut").status, "pass");
  in.points_on_cut_share = 0.1;
  EXPECT_EQ(check(checks::checkHead(in), "articular_points_on_cut").status, "warn");
  in.points_on_cut_share = 1665.0 / 1677.0;
  const checks::QcReport r = checks::checkHead(in);
  EXPECT_EQ(check(r, "articular_points_on_cut").status, "fail");
  EXPECT_NE(check(r, "articular_points_on_cut").reason.find("the segmentation's cut, not the head's"), std::string::npos);
  EXPECT_EQ(r.status, "fail");
}

TEST(HeadQc, TheSurfaceRunIntoBoneBeyondWarnsByItsOwnNameAndIsNoDoubtOfThePoints) {
  // A departure of the bone and a region with bone beyond it, each over
  // 395 mm^2 (the socket's roof a thick-sliced phantom head's pole took).
  checks::HeadQcInput in = cap(23, 85);
  in.cap_bone_beyond_mm2 = 395;
  const checks::QcReport r = checks::checkHead(in);
  EXPECT_EQ(check(r, "cap_bone_beyond_mm2").status, "warn");
  EXPECT_NE(check(r, "cap_bone_beyond_mm2").reason.find("joint gap is not resolved"), std::string::npos);
  EXPECT_EQ(r.status, "warn");
  // With a doubt about the structure (a search centre 0.2 radii away) it
  // does not fail the head: the band of points leaves such regions out.
  in.search_center = in.sphere_center + Eigen::Vector3d(0, 0.2 * 23, 0);
  in.search_radius_mm = 23;
  EXPECT_EQ(checks::checkHead(in).status, "warn");
  in.cap_bone_beyond_mm2 = 30;  // under 40 mm^2
  EXPECT_EQ(check(checks::checkHead(in), "cap_bone_beyond_mm2").status, "pass");
}

TEST(HeadQc, TwoDoubtsTogetherFail) {
  // A search centre 0.2 radii away warns; so does a spread of 5 % of the
  // radius about the sphere; together they fail. An unverified side does
  // not count as a doubt about the structure.
  checks::HeadQcInput in = cap(23, 85);
  in.search_center = in.sphere_center + Eigen::Vector3d(0, 0.2 * 23, 0);
  in.search_radius_mm = 23;
  EXPECT_EQ(checks::checkHead(in).status, "warn");
  in.side_verified = false;
  EXPECT_EQ(checks::checkHead(in).status, "warn");
  for (Eigen::Index i = 0; i < in.points.rows(); ++i) {
    const Eigen::Vector3d u = (in.points.row(i).transpose() - in.sphere_center).normalized();
    in.points.row(i) += (0.05 * 23 * (i % 2 ? 1.0 : -1.0) * u).transpose();
  }
  const checks::QcReport r = checks::checkHead(in);
  EXPECT_EQ(check(r, "sphere_rms_relative").status, "warn");
  EXPECT_EQ(check(r, "doubtful_checks").status, "fail");
  EXPECT_EQ(check(r, "doubtful_checks").value, 2);
  EXPECT_EQ(r.status, "fail");
}

/// A head of radius 22 mm about `centre`: a thin cortex (1 mm at 700 HU
/// over 120 HU cancellous bone), soft tissue around, a socket shell 2.5 mm
/// beyond; blurred radially (0.6 mm), on 0.8 mm voxels.
imaging::Volume faintHead(const Eigen::Vector3d& centre) {
  imaging::Volume v;
  const double h = 0.8;
  v.geometry.size = Eigen::Vector3i(80, 80, 80);
  v.geometry.spacing = Eigen::Vector3d::Constant(h);
  v.geometry.origin = centre - Eigen::Vector3d::Constant(39.5 * h);
  v.voxels.resize(static_cast<size_t>(v.geometry.voxelCount()));
  const double s = 0.6;
  for (int k = 0; k < 80; ++k)
    for (int j = 0; j < 80; ++j)
      for (int i = 0; i < 80; ++i) {
        const double r = (v.geometry.toPhysical(Eigen::Vector3d(i, j, k)) - centre).norm();
        const double head = 40 + 660 * Phi((22 - r) / s) - 580 * Phi((21 - r) / s);
        const double socket = 900 * (Phi((r - 24.5) / s) - Phi((r - 29.5) / s));
        v.at(i, j, k) = static_cast<float>(head + socket);
      }
  return v;
}

TEST(HeadQc, PointsInsideTheBoneFailOnTheCtsEdges) {
  // On the head's surface the points pass; from a label that a bone window
  // cut 2.5 mm inside a faint cortex, they fail (the structure is right,
  // its surface is not).
  checks::HeadQcInput in = cap(22, 80);
  const imaging::Volume ct = faintHead(in.sphere_center);
  in.ct_edges = checks::pointsOnCtEdge(ct, in.points, in.normals);
  EXPECT_GT(in.ct_edges->on_edge, 0.95);
  EXPECT_LT(in.ct_edges->inside_bone, 0.02);
  EXPECT_EQ(checks::checkHead(in).status, "pass");

  checks::HeadQcInput cut = cap(19.5, 80);
  cut.sphere_center = in.sphere_center;
  cut.ct_edges = checks::pointsOnCtEdge(ct, cut.points, cut.normals);
  EXPECT_LT(cut.ct_edges->on_edge, 0.05);
  EXPECT_GT(cut.ct_edges->inside_bone, 0.95);
  const checks::QcReport r = checks::checkHead(cut);
  EXPECT_EQ(check(r, "points_inside_bone_share").status, "fail");
  EXPECT_EQ(check(r, "points_on_ct_edge_share").status, "fail");
  EXPECT_EQ(r.status, "fail");
}

/// A cube of side 2 `half_mm` about `centre` on voxels of `spacing`, each
/// voxel's HU `hu` of its offset from the centre (point-sampled).
imaging::Volume volumeAbout(const Eigen::Vector3d& centre, double half_mm, const Eigen::Vector3d& spacing,
                            const std::function<double(const Eigen::Vector3d&)>& hu) {
  imaging::Volume v;
  v.geometry.spacing = spacing;
  v.geometry.size = (2 * half_mm / spacing.array()).ceil().cast<int>() + 1;
  v.geometry.origin = centre - Eigen::Vector3d::Constant(half_mm);
  v.voxels.resize(static_cast<size_t>(v.geometry.voxelCount()));
  for (int k = 0; k < v.geometry.size[2]; ++k)
    for (int j = 0; j < v.geometry.size[1]; ++j)
      for (int i = 0; i < v.geometry.size[0]; ++i)
        v.at(i, j, k) = static_cast<float>(hu(v.geometry.toPhysical(Eigen::Vector3d(i, j, k)) - centre));
  return v;
}

/// A head of radius 22 mm about `centre` with a cortex `cortex_mm` thick
/// (900 HU over 250 HU cancellous bone, 40 HU around), point-sampled on
/// voxels of `spacing`, blurred along its normal by the Gaussian that an
/// anisotropic point spread (`sigma_xy` within the slices, `sigma_z` across)
/// has there: exact for a surface flat over a few sigma.
imaging::Volume shellHead(const Eigen::Vector3d& centre, double cortex_mm, double sigma_xy, double sigma_z,
                          const Eigen::Vector3d& spacing) {
  return volumeAbout(centre, 28, spacing, [&](const Eigen::Vector3d& d) {
    const double r = d.norm(), nz2 = r > 0 ? d.z() * d.z() / (r * r) : 0;
    const double s = std::sqrt(sigma_xy * sigma_xy * (1 - nz2) + sigma_z * sigma_z * nz2);
    return 40 + 860 * Phi((22 - r) / s) - 650 * Phi((22 - cortex_mm - r) / s);
  });
}

TEST(HeadQc, ACortexBlurredAwayAcrossTheSlicesWarns) {
  // A 0.7 mm cortex under 2 mm of blur across 2.5 mm slices: its steepest
  // fall there lies about 1 mm outside. Warned, without failing the head.
  checks::HeadQcInput in = cap(22, 100);
  const auto contrast = [&](double cortex, double sigma_xy, double sigma_z, const Eigen::Vector3d& spacing) {
    return checks::cortexContrastAcrossSlices(shellHead(in.sphere_center, cortex, sigma_xy, sigma_z, spacing),
                                                in.points, in.normals);
  };
  in.cortex_contrast_across_slices = contrast(0.7, 0.4, 2.0, Eigen::Vector3d(0.7, 0.7, 2.5));
  ASSERT_TRUE(in.cortex_contrast_across_slices);
  EXPECT_LT(*in.cortex_contrast_across_slices, 0.15);
  checks::QcReport r = checks::checkHead(in);
  EXPECT_EQ(check(r, "cortex_contrast_across_slices").status, "warn");
  EXPECT_EQ(r.status, "warn");

  // The same cortex sharp both ways, on fine voxels; and a 2.5 mm cortex
  // under 1 mm of blur across 1.25 mm slices: it shows across the slices.
  in.cortex_contrast_across_slices = contrast(0.7, 0.4, 0.4, Eigen::Vector3d(0.6, 0.6, 0.6));
  ASSERT_TRUE(in.cortex_contrast_across_slices);
  EXPECT_GT(*in.cortex_contrast_across_slices, 0.8);
  EXPECT_EQ(checks::checkHead(in).status, "pass");
  in.cortex_contrast_across_slices = contrast(2.5, 0.4, 1.0, Eigen::Vector3d(0.7, 0.7, 1.25));
  ASSERT_TRUE(in.cortex_contrast_across_slices);
  EXPECT_GT(*in.cortex_contrast_across_slices, 0.5);
  EXPECT_EQ(check(checks::checkHead(in), "cortex_contrast_across_slices").status, "pass");

  // No cortex anywhere (cancellous bone to its surface): not measurable.
  EXPECT_FALSE(contrast(0.0, 0.4, 0.4, Eigen::Vector3d(0.6, 0.6, 0.6)));
}

TEST(HeadQc, AShellLabelOffTheCtsEdgesFailsAtCoarseVoxels) {
  // At 1.5 x 1.5 x 3 mm the CT's edge checks are off, but a label 5 mm
  // deep for a head of radius 22 mm is a shell, and its points must lie on
  // the CT's edge: those of the head's surface do; those of a shell cut
  // 3 mm inside it (the cortex below the bone window) do not.
  checks::HeadQcInput in = cap(22, 80);
  const imaging::Volume ct = shellHead(in.sphere_center, 1.0, 0.6, 1.2, Eigen::Vector3d(1.5, 1.5, 3.0));
  in.ct_voxel_mm = 3.0;
  in.label_depth_mm = 5.0;
  in.ct_edges = checks::pointsOnCtEdge(ct, in.points, in.normals);
  EXPECT_GT(in.ct_edges->on_edge, 0.9);
  checks::QcReport r = checks::checkHead(in);
  EXPECT_EQ(check(r, "shell_label_points_on_ct_edge_share").status, "pass");
  EXPECT_THROW(check(r, "points_on_ct_edge_share"), std::runtime_error) << "off beyond 2 mm voxels";
  EXPECT_EQ(r.status, "pass");

  checks::HeadQcInput cut = cap(19, 80);
  cut.sphere_center = in.sphere_center;
  cut.ct_voxel_mm = 3.0;
  cut.label_depth_mm = 5.0;
  cut.ct_edges = checks::pointsOnCtEdge(ct, cut.points, cut.normals);
  EXPECT_LT(cut.ct_edges->on_edge, 0.1);
  r = checks::checkHead(cut);
  EXPECT_EQ(check(r, "shell_label_points_on_ct_edge_share").status, "fail");
  EXPECT_EQ(r.status, "fail");

  // A solid label (16 mm deep) is not checked so at these voxels.
  cut.label_depth_mm = 16.0;
  r = checks::checkHead(cut);
  EXPECT_THROW(check(r, "shell_label_points_on_ct_edge_share"), std::runtime_error);
  EXPECT_EQ(r.status, "pass");
}

/// A femoral head of radius 22 mm about `centre` (a 1 mm cortex at 700 HU
/// over 150 HU), a 2 mm joint gap and a 4 mm acetabular wall (600 HU) over
/// the head's upper half, in 40 HU soft tissue; blurred radially (0.8 mm),
/// on voxels of `spacing`.
imaging::Volume hipWithSocket(const Eigen::Vector3d& centre, const Eigen::Vector3d& spacing, double gap = 2) {
  constexpr double s = 0.8;
  return volumeAbout(centre, 34, spacing, [gap](const Eigen::Vector3d& d) {
    const double r = d.norm();
    const double head = 660 * Phi((22 - r) / s) - 550 * Phi((21 - r) / s);
    const double socket = d.z() > -0.2 * r ? 560 * (Phi((r - 22 - gap) / s) - Phi((r - 26 - gap) / s)) : 0.0;
    return 40 + head + socket;
  });
}

TEST(HeadQc, ANarrowedJointSpaceWarns) {
  // The joint space read across the gap follows the gap; a gap of 0.8 mm
  // (a narrowed, arthritic joint) warns.
  checks::HeadQcInput head = cap(22, 80);
  for (const double gap : {0.8, 2.0, 4.0}) {
    const auto facing = checks::socketFacing(hipWithSocket(head.sphere_center, Eigen::Vector3d(0.7, 0.7, 1.5), gap),
                                               head.points, head.normals);
    ASSERT_TRUE(facing && facing->joint_space_mm) << gap;
    // Under the blur (0.8 mm) the two edges merge: the reading stops near 1.5 mm.
    if (gap >= 2) EXPECT_NEAR(*facing->joint_space_mm, gap, 0.6) << gap;
    else EXPECT_LT(*facing->joint_space_mm, 2.0) << gap;
    head.joint_space_mm = facing->joint_space_mm;
    EXPECT_EQ(check(checks::checkHead(head), "joint_space_mm").status, gap < 1.5 ? "warn" : "pass") << gap;
  }
}

TEST(HeadQc, ASocketsOuterSurfaceFailsOnTheSocketItFaces) {
  // The head's cap faces its acetabulum across the gap; the acetabulum's
  // outer surface, taken for a head where a faint head merged with it, has
  // soft tissue beyond.
  const Eigen::Vector3d voxels(1.5, 1.5, 3.0);
  checks::HeadQcInput head = cap(22, 80);
  const imaging::Volume ct = hipWithSocket(head.sphere_center, voxels);
  const auto facing = checks::socketFacing(ct, head.points, head.normals);
  ASSERT_TRUE(facing);
  head.socket_facing_share = facing->share;
  EXPECT_GT(*head.socket_facing_share, 0.8);
  EXPECT_EQ(checks::checkHead(head).status, "pass");

  checks::HeadQcInput outer = cap(28, 80);
  outer.sphere_center = head.sphere_center;
  const auto outer_facing = checks::socketFacing(ct, outer.points, outer.normals);
  ASSERT_TRUE(outer_facing);
  outer.socket_facing_share = outer_facing->share;
  EXPECT_LT(*outer.socket_facing_share, 0.05);
  const checks::QcReport r = checks::checkHead(outer);
  EXPECT_EQ(check(r, "socket_facing_share").status, "fail");
  EXPECT_EQ(r.status, "fail");

  // Voxels of 3 mm within the slices resolve no gap: not measured.
  EXPECT_FALSE(checks::socketFacing(hipWithSocket(head.sphere_center, Eigen::Vector3d::Constant(3.0)),
                                      head.points, head.normals));
}

TEST(HeadQc, TooFewPointsAreRefused) {
  checks::HeadQcInput in = cap(23, 85);
  in.points.conservativeResize(3, 3);
  EXPECT_THROW(checks::checkHead(in), std::exception);
}

}  // namespace
}  // namespace articula
