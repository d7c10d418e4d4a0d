#include "articula/checks/qc.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <utility>

#include "articula/core/error.hpp"
#include "articula/geometry/fibonacci.hpp"
#include "articula/imaging/edges.hpp"
#include "articula/imaging/noise.hpp"
#include "articula/checks/cap_departures.hpp"

namespace articula::checks {
namespace {

// Limits. A joint head's articular cap spans well over 45 degrees about its
// centre (femoral heads about 80-110, humeral 60-90) and is nearly spherical
// (RMS about its sphere 1-4 % of the radius); its normals point away from
// its centre (a socket's inner surface points towards it).
constexpr double kCapFailDeg = 30, kCapWarnDeg = 45;
constexpr double kOutwardFail = 0.90, kOutwardWarn = 0.97;
constexpr double kRmsWarn = 0.04, kRmsFail = 0.08;            // of the radius
constexpr double kCentreWarn = 0.15, kCentreFail = 0.30;      // search vs fit, of the radius
// The search's radius against the fit's, relative: at most 0.038 on 571
// phantom heads of three generators whose points are right (clipped by the
// field of view, metal, arthritis, coarse voxels included), 0.016-0.096 on
// the real CTs (0.096: the thorax's clipped humeral head); 0.156-0.227 where
// noise of 100 HU joined head and socket in the label and the points lay
// 4-5 mm out, the search's sphere right.
constexpr double kRadiusWarn = 0.08, kRadiusFail = 0.15;
constexpr double kEdgeFail = 0.4, kEdgeWarn = 0.6;            // share of the points on the CT's edge (a 1.5 mm gap and a thin cortex: down to 0.69 on correct heads)
constexpr double kInsideWarn = 0.15, kInsideFail = 0.30;      // share of the points inside the bone (a 1.5 mm gap at 1 mm voxels: up to 0.12 on correct heads)
// The cortex's contrast across the slices relative to within them: 0.38-1.05
// on the correct heads of two phantom generators (1.5 x 1.5 x 3 mm voxels
// included); 0.06-0.26 where a thin cortex under 1.5-2.5 mm of blur across
// 2-3 mm slices put the surface 0.36-0.79 mm outside on average; 0.30 where
// 4 mm thick slices (every 2 mm) put it 0.31 mm outside, beyond half the
// 0.7 mm voxel (the clinical matrix), and 0.35 at 1 mm voxels, 0.30 mm out.
constexpr double kSliceContrastWarn = 0.35;
constexpr double kSliceAxisShare = 0.8, kInPlaneShare = 0.3;  // |normal . slice axis| of the two groups of lines
constexpr int kMinLinesPerGroup = 20;
constexpr double kMinInPlaneContrastHu = 100;
// A label's depth against its fitted radius: 0.5-0.95 for a solid head
// (the cut at the neck makes it less than 1); a shell is thinner (0.08-0.28
// on phantoms and real CTs, correct or not).
constexpr double kShellDepthRelative = 0.4;
// The share of a hip head's points (within a slice) that face a socket:
// 0.25-0.97 on correct phantom heads (congruent or not, gaps 1.5-5 mm, up to
// 1.5 x 1.5 x 3 mm voxels); 0.00-0.15 where a faint head merged with its
// socket at 1.5-2 mm voxels and the socket's outer surface was taken.
constexpr double kSocketFacingWarn = 0.15, kSocketFacingFail = 0.08;
constexpr double kSocketRiseHu = 100;
// The joint space read on phantoms at 0.7 x 0.7 x 1.5 mm voxels (median of
// the socket-facing lines): 1.5, 1.75, 3.25 and 5.5 mm for gaps of 1, 1.5, 3
// and 5 mm. Adult hips show 3-5 mm; under 2 mm read is a narrowed joint.
constexpr double kJointSpaceWarnMm = 2.0;
constexpr double kSocketFromMm = 0.5, kSocketToMm = 8.0, kSocketStepMm = 0.25;
constexpr double kMidlineFailMm = 30, kHipFromMiddleWarnMm = 125, kShoulderFromMiddleWarnMm = 100;
constexpr int kDoubtsThatFail = 2;
// A head the field of view clips: the share of its sphere (the neck's 45
// degree cone aside) beyond the outermost voxel centres. A face 10 % of the
// radius into the head leaves about 0.06 of it outside, a quarter 0.15.
constexpr double kNeckConeDeg = 45;
constexpr int kOutsideDirections = 2000;
constexpr double kOutsideWarn = 0.02, kOutsideFail = 0.25;
// Metal near the head: voxels above 2,500 HU (cortical bone reaches about
// 2,000) within two radii of its centre, warned from 100 mm^3 (a screw of
// 6 mm by 5 mm; at 3 mm voxels partial volume leaves a screw's core only).
constexpr double kMetalReachRadii = 2, kMetalWarnMm3 = 100;  // metal: above imaging::kMetalHu
// The bone departs from the selected model over its cap (cap_departures.hpp):
// the largest region beyond the threshold and 2 mm deep, a hip's fovea
// aside. Warned from 40 mm^2: a dome flattened by a tenth of a 20 mm radius
// departs over about 125 mm^2 (on phantoms 230-320 mm^2 at 10-15 %), a 3 mm
// lip over 50-90 mm^2.
constexpr double kDepartureWarnMm2 = 40;
// The fitted sphere beyond the field of view on its farthest side, relative
// to the radius. On the clinical matrix (bench/clinical.sh: 6 heads, each
// face cut 0, 10, 25 and 50 % of the radius into the head): 0-0.09 at a
// tangent, 0.06-0.19 at 10 %, 0.20-0.34 at 25 %, 0.41-0.59 at 50 % (a head's
// extent along a face and its fitted sphere's differ by up to 6 %); 0 on
// every uncut CT. Warned above 0.03: every cut of a tenth of the radius, on
// the neck's side too, where the share above (its cone about the neck left
// out) stayed at 0.00-0.08.
constexpr double kBeyondFovWarn = 0.03;
// Articular points on the label's cut: any share warns; over a quarter the
// surface the fit takes is mostly the cut.
constexpr double kPointsOnCutWarn = 0.0, kPointsOnCutFail = 0.25;

// A yes-or-no check of how the head was found: 1 passes, 0 warns; no doubt
// about the structure either way.
QcCheck flag(const std::string& name, bool ok, const std::string& rule, const std::string& reason) {
  QcCheck c;
  c.name = name;
  c.of_structure = false;
  c.value = ok ? 1 : 0;
  c.rule = rule;
  c.status = ok ? "pass" : "warn";
  if (!ok) c.reason = reason;
  return c;
}

std::string number(double v) {
  std::ostringstream s;
  s.precision(3);
  s << v;
  return s.str();
}

double median(std::vector<double> v) {
  const auto mid = v.begin() + static_cast<long>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

/// The voxel axis of the largest spacing (the third on a tie): across the slices.
int sliceAxis(const Eigen::Vector3d& spacing) {
  return spacing[2] >= spacing[0] && spacing[2] >= spacing[1] ? 2 : spacing[1] >= spacing[0] ? 1 : 0;
}

/// Grades `value` (larger is worse unless `low_is_bad`) against a warn and,
/// where given, a fail limit.
QcCheck grade(const std::string& name, double value, double warn, std::optional<double> fail, bool low_is_bad,
              const std::string& what) {
  QcCheck c;
  c.name = name;
  c.value = value;
  const bool fails = fail && (low_is_bad ? value < *fail : value > *fail);
  const bool warns = low_is_bad ? value < warn : value > warn;
  c.status = fails ? "fail" : warns ? "warn" : "pass";
  const std::string direction = low_is_bad ? "below " : "above ";
  c.rule = "warn " + direction + number(warn) + (fail ? ", fail " + direction + number(*fail) : "");
  if (fails || warns) c.reason = what + " " + number(value) + " (" + (fails ? "limit " + number(*fail) : "doubtful beyond " + number(warn)) + ")";
  return c;
}

/// `check` with its reason followed by what it means for the result, when
/// it does not pass.
QcCheck explained(QcCheck check, const std::string& meaning) {
  if (check.status != "pass") check.reason += meaning;
  return check;
}

/// A check of what the data show (coverage, metal, noise, blur), not of
/// the structure's identity: not counted among the structure's doubts, its
/// reason explained.
QcCheck ofTheData(QcCheck check, const std::string& meaning) {
  check.of_structure = false;
  return explained(std::move(check), meaning);
}

}  // namespace

std::vector<std::string> QcReport::reasons() const {
  std::vector<std::string> out;
  for (const QcCheck& c : checks)
    if (c.status != "pass") out.push_back(c.status + ": " + c.reason);
  return out;
}

nlohmann::json QcReport::toJson() const {
  nlohmann::json checks_json = nlohmann::json::array();
  for (const QcCheck& c : checks)
    checks_json.push_back({{"name", c.name}, {"status", c.status}, {"value", c.value}, {"rule", c.rule}, {"reason", c.reason}});
  return {{"status", status}, {"checks", checks_json}, {"reasons", reasons()}};
}

PointsOnCtEdge pointsOnCtEdge(const imaging::Volume& ct, const Eigen::MatrixX3d& points, const Eigen::MatrixX3d& normals) {
  PointsOnCtEdge shares;
  if (points.rows() == 0 || normals.rows() != points.rows()) return shares;
  // The first bone edge met going out along the normal from 3 mm inside the
  // point (not the steepest: beyond a narrow gap a socket's cortex falls to
  // its cancellous bone, often more steeply than the head's own edge), or
  // the fall into a gap's valley before it, which must lie within half a
  // voxel of the point.
  const double voxel = ct.geometry.spacing.maxCoeff();
  const double reach = std::max(3.0, 1.5 * voxel), tolerance = std::max(0.5, 0.5 * voxel);
  Eigen::Index on_edge = 0, inside = 0;
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    const Eigen::Vector3d n = normals.row(i).transpose().normalized();
    const imaging::Edge e = imaging::firstEdgeBeforeAGap(ct, points.row(i).transpose() - reach * n, n, 0.0, 2 * reach,
                                                         imaging::EdgeSearch{});
    const double offset = e.offset_mm - reach;
    on_edge += e.found && std::abs(offset) <= tolerance;
    inside += e.found && offset > tolerance;
  }
  shares.on_edge = static_cast<double>(on_edge) / static_cast<double>(points.rows());
  shares.inside_bone = static_cast<double>(inside) / static_cast<double>(points.rows());
  return shares;
}

std::optional<double> cortexContrastAcrossSlices(const imaging::Volume& ct, const Eigen::MatrixX3d& points,
                                                 const Eigen::MatrixX3d& normals) {
  if (points.rows() == 0 || normals.rows() != points.rows()) return std::nullopt;
  const Eigen::Vector3d slice_direction = ct.geometry.direction.col(sliceAxis(ct.geometry.spacing)).normalized();
  std::vector<double> across, within;
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    const Eigen::Vector3d n = normals.row(i).transpose().normalized(), p = points.row(i).transpose();
    const double share = std::abs(n.dot(slice_direction));
    if (share < kSliceAxisShare && share > kInPlaneShare) continue;
    double peak = -std::numeric_limits<double>::infinity();
    for (int step = -60; step <= 10; ++step) peak = std::max(peak, imaging::interpolate(ct, p + 0.05 * step * n));
    const double contrast = peak - imaging::interpolate(ct, p - 4.0 * n);
    if (!std::isfinite(contrast)) continue;  // the line leaves the grid
    (share >= kSliceAxisShare ? across : within).push_back(contrast);
  }
  if (across.size() < kMinLinesPerGroup || within.size() < kMinLinesPerGroup) return std::nullopt;
  const double in_plane = median(within);
  if (in_plane < kMinInPlaneContrastHu) return std::nullopt;
  return median(across) / in_plane;
}

std::optional<SocketFacing> socketFacing(const imaging::Volume& ct, const Eigen::MatrixX3d& points,
                                         const Eigen::MatrixX3d& normals) {
  if (points.rows() == 0 || normals.rows() != points.rows()) return std::nullopt;
  const Eigen::Vector3d& spacing = ct.geometry.spacing;
  const int slice_axis = sliceAxis(spacing);
  double in_plane_voxel = 0;
  for (int a = 0; a < 3; ++a)
    if (a != slice_axis) in_plane_voxel = std::max(in_plane_voxel, spacing[a]);
  if (in_plane_voxel > imaging::kSeparateEdgesMaxVoxelMm + 1e-6) return std::nullopt;
  const Eigen::Vector3d slice_direction = ct.geometry.direction.col(slice_axis).normalized();
  int lines = 0, facing = 0;
  std::vector<double> gaps;
  std::vector<double> profile;
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    const Eigen::Vector3d n = normals.row(i).transpose().normalized(), p = points.row(i).transpose();
    if (std::abs(n.dot(slice_direction)) > 0.5) continue;
    double lowest = std::numeric_limits<double>::infinity(), rise = 0;
    bool inside_grid = true;
    profile.clear();
    for (double s = kSocketFromMm; s <= kSocketToMm + 1e-9 && inside_grid; s += kSocketStepMm) {
      const double v = imaging::interpolate(ct, p + s * n);
      inside_grid = std::isfinite(v);
      profile.push_back(v);
      lowest = std::min(lowest, v);
      rise = std::max(rise, v - lowest);
    }
    if (!inside_grid) continue;
    ++lines;
    if (rise < kSocketRiseHu) continue;
    ++facing;
    // The joint space along the line: from the head's edge (the point) to
    // the socket's, where the HU climb half their rise over the lowest.
    double low = std::numeric_limits<double>::infinity();
    for (size_t k = 0; k < profile.size(); ++k) {
      low = std::min(low, profile[k]);
      if (profile[k] - low >= 0.5 * rise) {
        gaps.push_back(kSocketFromMm + kSocketStepMm * static_cast<double>(k));
        break;
      }
    }
  }
  if (lines < kMinLinesPerGroup) return std::nullopt;
  SocketFacing out;
  out.share = static_cast<double>(facing) / lines;
  if (static_cast<int>(gaps.size()) >= kMinLinesPerGroup) out.joint_space_mm = median(gaps);
  return out;
}

double headOutsideVolumeShare(const imaging::ImageGeometry& grid, const Eigen::MatrixX3d& points,
                              const Eigen::Vector3d& center, double radius_mm) {
  const Eigen::Vector3d axis = (points.rowwise() - center.transpose()).rowwise().normalized().colwise().mean().transpose().normalized();
  const double neck_cos = std::cos(kNeckConeDeg * M_PI / 180);
  const Eigen::Vector3d last = (grid.size.cast<double>() - Eigen::Vector3d::Ones());
  int considered = 0, outside = 0;
  for (int i = 0; i < kOutsideDirections; ++i) {
    const Eigen::Vector3d u = geometry::fibonacciDirection(i, kOutsideDirections);
    if (u.dot(-axis) > neck_cos) continue;
    ++considered;
    const Eigen::Vector3d index = grid.toIndex(center + radius_mm * u);
    outside += (index.array() < -1e-6).any() || (index.array() > last.array() + 1e-6).any();
  }
  return considered > 0 ? static_cast<double>(outside) / considered : 0.0;
}

double metalNearHead(const imaging::Volume& ct, const Eigen::Vector3d& center, double radius_mm) {
  const imaging::ImageGeometry& g = ct.geometry;
  const double reach = kMetalReachRadii * radius_mm;
  // The index box holding the ball (the grid may be rotated: its corners' indices bound it).
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d x = center + reach * Eigen::Vector3d(corner & 1 ? 1 : -1, corner & 2 ? 1 : -1, corner & 4 ? 1 : -1);
    lo = lo.cwiseMin(g.toIndex(x));
    hi = hi.cwiseMax(g.toIndex(x));
  }
  long long metal = 0;
  for (int k = std::max(0, int(std::floor(lo.z()))); k <= std::min(g.size[2] - 1, int(std::ceil(hi.z()))); ++k)
    for (int j = std::max(0, int(std::floor(lo.y()))); j <= std::min(g.size[1] - 1, int(std::ceil(hi.y()))); ++j)
      for (int i = std::max(0, int(std::floor(lo.x()))); i <= std::min(g.size[0] - 1, int(std::ceil(hi.x()))); ++i)
        if (ct.at(i, j, k) > imaging::kMetalHu && (g.toPhysical(Eigen::Vector3d(i, j, k)) - center).norm() <= reach) ++metal;
  return static_cast<double>(metal) * g.spacing.prod();
}

double headBeyondFieldOfView(const imaging::ImageGeometry& grid, const Eigen::Vector3d& center, double radius_mm) {
  // The grid's axes are orthonormal: the sphere spans radius / spacing
  // indices either way along each, about its centre's index.
  const Eigen::Vector3d c = grid.toIndex(center);
  double beyond = 0;
  for (int a = 0; a < 3; ++a) {
    const double reach = radius_mm / grid.spacing[a];
    beyond = std::max({beyond, (c[a] + reach - (grid.size[a] - 1)) * grid.spacing[a], (reach - c[a]) * grid.spacing[a]});
  }
  return beyond;
}

QcReport checkHead(const HeadQcInput& in) {
  const Eigen::Index n = in.points.rows();
  if (n < 4) throw InputError("head checks need at least 4 points, found " + std::to_string(n));
  QcReport report;
  const Eigen::Vector3d c = in.sphere_center;
  const double r = in.sphere_radius_mm;

  QcCheck radius;
  radius.name = "head_radius_mm";
  radius.value = r;
  radius.rule = "fail outside [" + number(in.min_radius_mm) + ", " + number(in.max_radius_mm) + "] mm";
  radius.status = r >= in.min_radius_mm && r <= in.max_radius_mm ? "pass" : "fail";
  if (radius.status == "fail") radius.reason = "fitted sphere radius " + number(r) + " mm is not that of a joint head (" + radius.rule + ")";
  report.checks.push_back(radius);

  // The cap's half-angle: the 95th percentile of the points' angles from
  // their mean direction about the centre.
  Eigen::MatrixX3d u = in.points.rowwise() - c.transpose();
  u.rowwise().normalize();
  const Eigen::Vector3d axis = u.colwise().mean().transpose().normalized();
  std::vector<double> angles(static_cast<size_t>(n));
  for (Eigen::Index i = 0; i < n; ++i)
    angles[static_cast<size_t>(i)] = std::acos(std::clamp(u.row(i).dot(axis.transpose()), -1.0, 1.0)) * 180 / M_PI;
  std::nth_element(angles.begin(), angles.begin() + static_cast<long>(0.95 * (n - 1)), angles.end());
  report.checks.push_back(grade("cap_half_angle_deg", angles[static_cast<size_t>(0.95 * (n - 1))], kCapWarnDeg, kCapFailDeg,
                                true, "the articular cap spans a half-angle of only (degrees)"));

  if (in.normals.rows() == n) {
    Eigen::Index outward = 0;
    for (Eigen::Index i = 0; i < n; ++i) outward += in.normals.row(i).dot(in.points.row(i) - c.transpose()) > 0;
    report.checks.push_back(grade("normals_outward_share", static_cast<double>(outward) / n, kOutwardWarn, kOutwardFail,
                                  true, "share of point normals pointing away from the head's centre (a socket's point towards it):"));
  }

  const Eigen::ArrayXd residual = (in.points.rowwise() - c.transpose()).rowwise().norm().array() - r;
  const double rms = std::sqrt(residual.square().mean());
  report.checks.push_back(grade("sphere_rms_relative", rms / r, kRmsWarn, kRmsFail, false,
                                "RMS of the points about their sphere, relative to its radius:"));

  if (in.search_center) {
    report.checks.push_back(grade("search_centre_offset_relative", (*in.search_center - c).norm() / r, kCentreWarn,
                                  kCentreFail, false, "the head search's centre lies away from the fitted one, relative to the radius:"));
    if (in.search_radius_mm > 0)
      report.checks.push_back(grade("search_radius_difference_relative", std::abs(in.search_radius_mm - r) / r, kRadiusWarn,
                                    kRadiusFail, false, "the head search's radius differs from the fitted one, relative:"));
  }
  if (in.joint_space_mm) {
    // Of the joint, not of the structure: a narrowed space is a finding.
    report.checks.push_back(
        ofTheData(grade("joint_space_mm", *in.joint_space_mm, kJointSpaceWarnMm, std::nullopt, true,
                        "the joint space (median, from the head's edge to the socket's across the gap, mm) is only"),
                  ": a narrowed joint (adult hips: 3-5 mm), or the socket's edge taken into the head; check the slices"));
  }
  if (in.socket_facing_share)
    report.checks.push_back(grade("socket_facing_share", *in.socket_facing_share, kSocketFacingWarn, kSocketFacingFail,
                                  true, "share of the points (within a slice) with a socket across the joint gap (a "
                                        "hip's head faces its acetabulum; a socket's outer surface has soft tissue "
                                        "beyond):"));
  const bool fine_voxels = in.ct_voxel_mm <= imaging::kSeparateEdgesMaxVoxelMm + 1e-6;
  if (in.ct_edges && !fine_voxels && in.label_depth_mm && *in.label_depth_mm < kShellDepthRelative * r) {
    // A shell's outer surface is the bone's only where the CT's edge is
    // (a thin cortex over faint cancellous bone); a shell cut from within
    // the bone (the cortex itself below the window) has no edge there.
    report.checks.push_back(grade("shell_label_points_on_ct_edge_share", in.ct_edges->on_edge, kEdgeWarn, kEdgeFail,
                                  true, "the label is a shell (" + number(*in.label_depth_mm) +
                                            " mm deep for a head of radius " + number(r) +
                                            " mm), and the share of its points on the CT's bone edge is"));
  }
  if (in.ct_edges && fine_voxels) {
    report.checks.push_back(grade("points_on_ct_edge_share", in.ct_edges->on_edge, kEdgeWarn, kEdgeFail, true,
                                  "share of the points on the CT's bone edge (within half a voxel):"));
    report.checks.push_back(grade("points_inside_bone_share", in.ct_edges->inside_bone, kInsideWarn, kInsideFail, false,
                                  "share of the points with the CT's bone edge further out (a label cut inside the "
                                  "head, where a faint cortex fell below the bone window):"));
  }
  if (in.cortex_contrast_across_slices) {
    // Of the surface's accuracy, not of the structure: it only warns.
    report.checks.push_back(ofTheData(
        grade("cortex_contrast_across_slices", *in.cortex_contrast_across_slices, kSliceContrastWarn, std::nullopt, true,
              "the cortex is blurred away across the slices (its contrast over the cancellous bone there, relative to "
              "within a slice):"),
        ": where the normals cross the slices the surface lies outside the bone's, by up to the blur across the slices"));
  }
  if (in.head_outside_volume_share) {
    // Of what the data covers, not of the structure: a clipped head is still the head.
    report.checks.push_back(ofTheData(
        grade("head_outside_volume_share", *in.head_outside_volume_share, kOutsideWarn, kOutsideFail, false,
              "the field of view clips the head: the share of its sphere (the neck aside) outside the CT is"),
        ": the points cover only the part in view, and the fitted shape extrapolates the rest"));
  }
  if (in.metal_near_head_mm3) {
    report.checks.push_back(ofTheData(
        grade("metal_near_head_mm3", *in.metal_near_head_mm3, kMetalWarnMm3, std::nullopt, false,
              "metal near the head: the volume (mm^3) above " + number(imaging::kMetalHu) + " HU within " +
                  number(kMetalReachRadii) + " radii of its centre is"),
        ": its streaks and dark bands can move the bone's edges; check the head on the slices"));
  }
  if (in.ct_noise_hu) {
    report.checks.push_back(ofTheData(
        grade("ct_noise_hu", *in.ct_noise_hu, imaging::kSmoothSegmentationAboveNoiseHu, std::nullopt, false,
              "a noisy CT (a low dose or a sharp kernel): its noise voxel to voxel (HU) is"),
        ": the head was searched and labelled on a smoothed copy, its surface placed on the noisy voxels; check the "
        "head on the slices"));
  }
  // Regions of the cap off the model (cap_departures.hpp) warn from
  // kDepartureWarnMm2 and are no doubt about the structure: the band of
  // points the fit takes leaves them out.
  const auto capRegions = [](const std::string& name, double area_mm2, const std::string& what, const std::string& why) {
    return ofTheData(grade(name, area_mm2, kDepartureWarnMm2, std::nullopt, false, what), why);
  };
  // A finding of the bone (a flattened dome, an osteophyte); also where the
  // surface is off the bone (a slice too many at thick slices; a narrowed
  // joint whose socket is dim beside the cortex): a doubtful warning
  // rather than a silent error.
  if (in.cap_departure_mm2)
    report.checks.push_back(capRegions(
        "cap_departure_mm2", *in.cap_departure_mm2,
        "the bone departs from the selected model over part of its cap: the largest region departing by " +
            number(kFindingDepthMm) + " mm or more (mm^2, a hip's fovea aside) is",
        ": a flattened or eroded dome, an osteophyte, a surface off the bone there (a neighbouring bone taken in, a "
        "slice too many at coarse slices), or a head no model of the hierarchy follows there; the model describes "
        "the rest (see cap_departures in results.json and the slices)"));
  // Regions with bone going on beyond them are no departure of the head's
  // bone: the surface met a neighbouring bone. At 2.5-3 mm
  // slices over a 2 mm gap the socket's roof joins the dome (395 mm^2 of a
  // correct phantom head); a narrowed joint does the same at any slices.
  if (in.cap_bone_beyond_mm2)
    report.checks.push_back(capRegions(
        "cap_bone_beyond_mm2", *in.cap_bone_beyond_mm2,
        "the surface meets bone beyond the head over part of its cap: the largest region departing from the model by " +
            number(kFindingDepthMm) + " mm or more with bone going on beyond it, or running on past half a radius (mm^2), is",
        ": the joint gap is not resolved there (a narrowed joint, or slices too thick for the gap) or a neighbouring "
        "bone was taken into the head's label; the mesh there is not the head's surface (see cap_departures in "
        "results.json and the slices)"));
  if (in.surface_on_ct_edges)
    report.checks.push_back(flag("surface_on_ct_edges", *in.surface_on_ct_edges,
                                 "warn when the surface could not be moved onto the CT's bone edges",
                                 "too few of the surface's vertices found a bone edge in the CT (coarse or lossy voxels, "
                                 "or not the CT the label was made from): the surface is the label's voxel staircase, "
                                 "up to half a voxel off the bone"));
  if (in.points_on_cut_share) {
    // The sample stage keeps points on the label's cut (where no bone edge
    // bounds it) only when too few would remain without them: the label was
    // cut from a neighbouring bone across most of the cap (a joint gap the
    // CT does not show), and the points lie on that cut, not on the head
    // (an osteoporotic head at 0.9 x 0.9 x 2.5 mm under 60 HU of noise: 99 %
    // of its points, 3 mm outside the bone). No correct head of the
    // benches' 2,300 runs kept one.
    report.checks.push_back(explained(
        grade("articular_points_on_cut", *in.points_on_cut_share, kPointsOnCutWarn, kPointsOnCutFail, false,
              "the articular points lie where the label was cut from a neighbouring bone (no bone edge in the CT "
              "there): their share is"),
        ": the surface there is the segmentation's cut, not the head's (a joint gap the CT does not resolve); check "
        "the head on the slices, or give a label (--label)"));
  }
  {
    // Every warning of a stage is a named check, never a terminal line only.
    std::string joined;
    for (const auto& w : in.stage_warnings) joined += (joined.empty() ? "" : "; ") + w;
    QcCheck warned = flag("stage_warnings", in.stage_warnings.empty(), "warn when a stage warned (0: none)",
                          "the stages warned: " + joined);
    warned.value = static_cast<double>(in.stage_warnings.size());
    report.checks.push_back(warned);
  }
  if (in.body_middle_x_mm && (in.joint == "hip" || in.joint == "shoulder")) {
    // Femoral heads lie 60-110 mm from the body's middle (half the distance
    // between them), humeral heads 120-190 mm (the glenoids on either side
    // of the thorax): a head at the other joint's distance is likely the
    // other joint (a shoulder run on a hip CT), one on the midline a vertebra
    // or the symphysis.
    const bool hip = in.joint == "hip";
    QcCheck lateral;
    lateral.name = "head_from_body_middle_mm";
    lateral.value = std::abs(c.x() - *in.body_middle_x_mm);
    lateral.rule = std::string("fail below ") + number(kMidlineFailMm) + " mm; warn " +
                   (hip ? "above " + number(kHipFromMiddleWarnMm) : "below " + number(kShoulderFromMiddleWarnMm)) + " mm";
    lateral.status = "pass";
    if (lateral.value < kMidlineFailMm) {
      lateral.status = "fail";
      lateral.reason = "the head lies " + number(lateral.value) +
                       " mm from the body's middle: a structure on the midline (a vertebra, the symphysis), not a joint head";
    } else if (hip ? lateral.value > kHipFromMiddleWarnMm : lateral.value < kShoulderFromMiddleWarnMm) {
      lateral.status = "warn";
      lateral.reason = "the head lies " + number(lateral.value) + " mm from the body's middle, " +
                       (hip ? "where humeral heads lie (femoral heads: 60-110 mm): is this a shoulder CT?"
                            : "where femoral heads lie (humeral heads: 120-190 mm): is this a hip CT?") +
                       " Check --joint";
    }
    report.checks.push_back(lateral);
  }
  if (in.found_by_edges)
    report.checks.push_back(
        flag("head_found_by_edges", *in.found_by_edges,
             "warn when the search found no sphere through the head's bone edges and took it by its facing surface voxels",
             "the head search found no spherical bone edge along its rays and took the head by the surface voxels "
             "facing a centre (its fallback): check the head on the slices"));
  if (in.side_verified)
    report.checks.push_back(
        flag("side_verified", *in.side_verified,
             "warn when neither the body's middle, a field of view holding both sides, nor the socket tells the side",
             "the joint's side could not be verified (a narrow field of view without the body's outline, and no "
             "socket clearly medial to the head): the joint in view was taken as the requested side"));
  if (in.head_beyond_fov_mm) {
    // Of what the data covers, not of the structure (as the share above).
    report.checks.push_back(
        ofTheData(grade("head_beyond_fov_relative", *in.head_beyond_fov_mm / r, kBeyondFovWarn, std::nullopt, false,
                        "the field of view ends inside the head's sphere: it reaches beyond the CT's last voxels, "
                        "relative to its radius, by"),
                  " (" + number(*in.head_beyond_fov_mm) +
                      " mm; on the neck's side too): the points cover only the part in view, and the fitted shape "
                      "extrapolates the rest"));
  }
  // Doubts compound: two checks of the structure that each find the head
  // doubtful are two independent signs of a wrong structure (on the phantom matrix, the one
  // head with two warnings had taken part of its socket; no correct head
  // had more than one).
  int doubts = 0;
  for (const QcCheck& check : report.checks) doubts += check.status == "warn" && check.of_structure;
  if (doubts >= kDoubtsThatFail) {
    QcCheck together;
    together.name = "doubtful_checks";
    together.value = doubts;
    together.rule = "fail at " + std::to_string(kDoubtsThatFail) + " or more warnings";
    together.status = "fail";
    together.reason = std::to_string(doubts) + " checks find the head doubtful at once";
    report.checks.push_back(together);
  }
  for (const QcCheck& check : report.checks) {
    if (check.status == "fail") report.status = "fail";
    else if (check.status == "warn" && report.status == "pass") report.status = "warn";
  }
  return report;
}

}  // namespace articula::checks
