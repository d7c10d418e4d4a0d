#include "articula/checks/cap_departures.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include <Eigen/Geometry>

#include "articula/core/error.hpp"
#include "articula/distance/signed_distance.hpp"
#include "articula/geometry/fibonacci.hpp"
#include "articula/geometry/mesh_components.hpp"
#include "articula/imaging/edges.hpp"

namespace articula::checks {
namespace {

constexpr double kRimExtensionDeg = 15;   // osteophytes grow at the cap's margin, beyond its points
constexpr int kCapDirections = 3000;     // about 3.7 degrees apart
constexpr double kChannelDeg = 8;        // half the narrowest channel that joins a hole to the part beyond
constexpr double kNeckPartShare = 0.25;  // of the largest part without points: a hip's part beyond is the one of these towards its neck
constexpr double kThresholdFloorMm = 0.75;
constexpr double kZoneInner = 0.5, kZoneOuter = 1.5;  // the vertices measured lie within these model radii of the centre
constexpr double kFoveaMaxAngleDeg = 45;  // from the medial direction
constexpr double kFoveaMaxAreaMm2 = 250, kFoveaMaxDepthMm = 5;

double degrees(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::acos(std::clamp(a.normalized().dot(b.normalized()), -1.0, 1.0)) * 180 / M_PI;
}

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  const auto k = static_cast<long>(q * static_cast<double>(v.size() - 1));
  std::nth_element(v.begin(), v.begin() + k, v.end());
  return v[static_cast<size_t>(k)];
}

// "superior, lateral": the LPS axes along which `direction` mostly points,
// with medial/lateral instead of left/right where the medial side is known.
std::string anatomicalWords(const Eigen::Vector3d& d, const std::optional<Eigen::Vector3d>& medial) {
  std::vector<std::pair<double, std::string>> words;
  const double lr = medial ? d.dot(*medial) : d.x();
  words.push_back({std::abs(lr), medial ? (lr > 0 ? "medial" : "lateral") : (lr > 0 ? "left" : "right")});
  words.push_back({std::abs(d.y()), d.y() > 0 ? "posterior" : "anterior"});
  words.push_back({std::abs(d.z()), d.z() > 0 ? "superior" : "inferior"});
  std::sort(words.begin(), words.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  std::string text = words[0].second;
  for (size_t i = 1; i < words.size(); ++i)
    if (words[i].first >= 0.4) text += ", " + words[i].second;
  return text;
}

// The directions from the head's centre over its articular cap: a lattice
// of directions, those holding a point's direction, and every hole they
// enclose (a dome or a fovea the selection left out, gaps between sparse
// points); beyond it, the largest part without points (the neck's side;
// on a hip, of the large ones, the one towards the neck; holes joined to
// it by a narrow channel stay holes), whose directions
// within kRimExtensionDeg of the cap are its rim.
struct CapDirections {
  static constexpr char kCap = 0, kRim = 1, kBeyond = 2;
  Eigen::MatrixX3d directions;
  std::vector<char> place;
  int nearest(const Eigen::Vector3d& unit) const {
    Eigen::Index best = 0;
    (directions * unit).maxCoeff(&best);
    return static_cast<int>(best);
  }
};

CapDirections capDirections(const Eigen::MatrixX3d& unit_points, const std::optional<Eigen::Vector3d>& neck_side) {
  CapDirections cap;
  const int n = kCapDirections;
  cap.directions.resize(n, 3);
  for (int i = 0; i < n; ++i) cap.directions.row(i) = geometry::fibonacciDirection(i, n).transpose();
  std::vector<char> held(static_cast<size_t>(n), 0);
  for (Eigen::Index i = 0; i < unit_points.rows(); ++i) held.at(static_cast<size_t>(cap.nearest(unit_points.row(i).transpose()))) = 1;
  // Neighbours: within 1.8 lattice spacings (the lattice's spacing is about sqrt(4 pi / n)).
  const double neighbour_cos = std::cos(1.8 * std::sqrt(4 * M_PI / n));
  const auto cosine = [&cap](int i, int j) { return cap.directions.row(i).dot(cap.directions.row(j)); };
  std::vector<Eigen::Vector3i> pairs;  // as degenerate triangles (i, j, j): connectedParts joins through edges
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j)
      if (cosine(i, j) >= neighbour_cos) pairs.emplace_back(i, j, j);
  Eigen::MatrixX3i edges(static_cast<Eigen::Index>(pairs.size()), 3);
  for (size_t k = 0; k < pairs.size(); ++k) edges.row(static_cast<Eigen::Index>(k)) = pairs[k].transpose();
  // The part beyond is found among the directions at least kChannelDeg from
  // every point, then grown back by as much over the directions without
  // points: a hole that reaches it only through a channel narrower than
  // that (a dome left out near the cap's margin) stays a hole of the cap,
  // as it does where the points close it, instead of turning on a few
  // points whether it is measured at all.
  const double channel_cos = std::cos(kChannelDeg * M_PI / 180);
  std::vector<char> far_from_points(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) {
    bool far = !held[static_cast<size_t>(i)];
    for (int j = 0; j < n && far; ++j) far = !(held[static_cast<size_t>(j)] && cosine(i, j) >= channel_cos);
    far_from_points[static_cast<size_t>(i)] = far;
  }
  const std::vector<int> part = geometry::connectedParts(far_from_points, edges);
  std::vector<int> size(static_cast<size_t>(n), 0);
  for (int p : part)
    if (p >= 0) ++size[static_cast<size_t>(p)];
  int largest = static_cast<int>(std::max_element(size.begin(), size.end()) - size.begin());
  // A hip's dome merged with its socket across thick slices leaves a part
  // without points at the pole as large as the neck's: the part beyond is
  // then the one towards the neck's side, and the dome a hole of the cap.
  if (neck_side && size[static_cast<size_t>(largest)] > 0) {
    std::vector<Eigen::Vector3d> sum(static_cast<size_t>(n), Eigen::Vector3d::Zero());
    for (int i = 0; i < n; ++i)
      if (part[static_cast<size_t>(i)] >= 0) sum[static_cast<size_t>(part[static_cast<size_t>(i)])] += cap.directions.row(i).transpose();
    const int biggest = largest;
    double best = -2;
    for (int p = 0; p < n; ++p) {
      if (size[static_cast<size_t>(p)] < kNeckPartShare * size[static_cast<size_t>(biggest)]) continue;
      const double towards_neck = sum[static_cast<size_t>(p)].normalized().dot(*neck_side);
      if (towards_neck > best) best = towards_neck, largest = p;
    }
  }
  std::vector<char> beyond(static_cast<size_t>(n), 0);
  if (size[static_cast<size_t>(largest)] > 0)
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n && !held[static_cast<size_t>(i)] && !beyond[static_cast<size_t>(i)]; ++j)
        beyond[static_cast<size_t>(i)] = part[static_cast<size_t>(j)] == largest && cosine(i, j) >= channel_cos;
  cap.place.assign(static_cast<size_t>(n), CapDirections::kCap);
  const double rim_cos = std::cos(kRimExtensionDeg * M_PI / 180);
  for (int i = 0; i < n; ++i) {
    if (!beyond[static_cast<size_t>(i)]) continue;
    bool near_cap = false;
    for (int j = 0; j < n && !near_cap; ++j) near_cap = !beyond[static_cast<size_t>(j)] && cosine(i, j) >= rim_cos;
    cap.place[static_cast<size_t>(i)] = near_cap ? CapDirections::kRim : CapDirections::kBeyond;
  }
  return cap;
}

// Each vertex's share of its triangles' area (a third of each), and its
// area-weighted normal (winding as stored).
void vertexAreasAndNormals(const Eigen::MatrixX3d& V, const Eigen::MatrixX3i& F, Eigen::VectorXd& area, Eigen::MatrixX3d& normal) {
  area = Eigen::VectorXd::Zero(V.rows());
  normal = Eigen::MatrixX3d::Zero(V.rows(), 3);
  for (Eigen::Index t = 0; t < F.rows(); ++t) {
    const Eigen::Vector3d a = V.row(F(t, 0)), b = V.row(F(t, 1)), c = V.row(F(t, 2));
    const Eigen::Vector3d twice = (b - a).cross(c - a);
    for (int k = 0; k < 3; ++k) {
      area[F(t, k)] += twice.norm() / 6;
      normal.row(F(t, k)) += twice.transpose();
    }
  }
}

constexpr double kProbeMm = 3;
constexpr double kPastModelMm = 0.5;  // an inward region's outer probe, past the model's surface
constexpr double kSoftTissueShare = 0.5;  // 3 mm lips on the clinical bench: 0.08-0.46; cuts across the neck: 0.8-1.1
constexpr double kBoneBeyondHu = 150;     // soft tissue reads under 100 HU; a socket's cancellous bone 150-400

// Per part of the vertices (`part`, -1: none; `parts` of them), what lies
// beyond it: kSoftTissue where the CT's mean outside its vertices (along
// `outward_normal`, kProbeMm out or, given, `out_mm` per vertex) is below
// kSoftTissueShare of its mean kProbeMm inside and below `bone_hu`;
// kBone where the bone goes on (a neighbouring bone, or one across a joint
// gap the CT does not resolve: a socket's cancellous bone can read under
// half the head's cortex beside it); kUnknown where no probe lies in the CT.
enum Beyond : signed char { kUnknown = -1, kBone = 0, kSoftTissue = 1 };
std::vector<signed char> whatLiesBeyond(const Eigen::MatrixX3d& V, const Eigen::MatrixX3d& outward_normal, const imaging::Volume& ct,
                                   const std::vector<int>& part, int parts, double bone_hu,
                                   const std::vector<double>& out_mm = {}) {
  std::vector<double> inside(static_cast<size_t>(parts), 0), outside(static_cast<size_t>(parts), 0);
  std::vector<int> probed(static_cast<size_t>(parts), 0);
  for (size_t v = 0; v < part.size(); ++v) {
    if (part[v] < 0 || part[v] >= parts) continue;
    const auto p = static_cast<size_t>(part[v]);
    const Eigen::Vector3d x = V.row(static_cast<Eigen::Index>(v)).transpose();
    const Eigen::Vector3d n = outward_normal.row(static_cast<Eigen::Index>(v)).normalized().transpose();
    const double in = imaging::interpolate(ct, x - kProbeMm * n), out = imaging::interpolate(ct, x + (out_mm.empty() ? kProbeMm : out_mm[v]) * n);
    if (!std::isfinite(in) || !std::isfinite(out)) continue;
    inside[p] += in;
    outside[p] += out;
    ++probed[p];
  }
  std::vector<signed char> beyond(static_cast<size_t>(parts), kUnknown);
  for (size_t p = 0; p < beyond.size(); ++p)
    if (probed[p] > 0)
      beyond[p] = outside[p] < kSoftTissueShare * inside[p] && outside[p] < bone_hu * probed[p] ? kSoftTissue : kBone;
  return beyond;
}

// A lip at the head-neck junction (an osteophyte, a cam) joins the neck's
// outward region, which runs on beyond the rim and is no finding as a
// whole. What tells the lip from the neck is which way the bone faces: the
// neck rises out of the head at a slant (its surface faces sideways, about
// 45 degrees from the direction out of the head's centre), a lip stands
// out and faces outwards as the head does. So does the face where the
// head's label was cut across the neck, but the CT's bone goes on beyond
// it. The vertices of a region reaching beyond the rim that face within
// kLipTiltDeg of the way out of the centre (`distance`: from the model,
// per vertex) form parts; a part is a lip when it comes within kLipReachMm
// of an articular point, has soft tissue beyond it (whatLiesBeyond) and stands
// kLipMinHeightMm or more above the model (its median vertex). Lips are
// given parts of their own in `part`, numbered from the count of parts
// before, which is returned.
constexpr double kLipTiltDeg = 25;
constexpr double kLipReachMm = 6;         // a lip's crest lies about 1.4 times its height beyond the cap's edge
// The junction's terraces at 3 mm slices face out up to a median 2.1 mm
// above the model (the robustness matrix's 64 heads); 3 mm lips stand 2.7-3.3.
constexpr double kLipMinHeightMm = 2.4;

int splitLipsFromNeck(const Eigen::MatrixX3d& V, const Eigen::MatrixX3d& outward_normal, const Eigen::Vector3d& c,
                      const Eigen::MatrixX3d& points, const std::vector<char>& beyond_rim, const Eigen::MatrixX3i& triangles,
                      const imaging::Volume& ct, const std::vector<double>& distance, std::vector<int>& part) {
  int first = 0;
  for (int p : part) first = std::max(first, p + 1);
  std::vector<char> reaches_beyond(static_cast<size_t>(first), 0);
  for (size_t v = 0; v < part.size(); ++v)
    if (part[v] >= 0 && beyond_rim[v]) reaches_beyond[static_cast<size_t>(part[v])] = 1;
  std::vector<char> facing_out(part.size(), 0);
  bool any = false;
  for (size_t v = 0; v < part.size(); ++v) {
    if (part[v] < 0 || !reaches_beyond[static_cast<size_t>(part[v])]) continue;
    const auto i = static_cast<Eigen::Index>(v);
    if (degrees(outward_normal.row(i).transpose(), V.row(i).transpose() - c) < kLipTiltDeg) facing_out[v] = any = 1;
  }
  if (!any) return first;
  const std::vector<int> lip = geometry::connectedParts(facing_out, triangles);
  int lips = 0;
  for (int p : lip) lips = std::max(lips, p + 1);
  // Each part's vertices' heights above the model.
  std::vector<std::vector<double>> height(static_cast<size_t>(lips));
  for (size_t v = 0; v < lip.size(); ++v)
    if (lip[v] >= 0) height[static_cast<size_t>(lip[v])].push_back(distance[v]);
  // Where the head's label was cut across the neck, the bone goes on
  // beyond the mesh; beyond a lip lies soft tissue. The distance to the
  // articular points, the costly test, only for the parts that pass these.
  // The ratio alone: across 2.5-3 mm slices the socket's rim blurs to over
  // kBoneBeyondHu 3 mm beyond two of six 3 mm lips on the clinical bench.
  const std::vector<signed char> beyond =
      whatLiesBeyond(V, outward_normal, ct, lip, lips, std::numeric_limits<double>::infinity());
  std::vector<char> is_lip(static_cast<size_t>(lips), 0);
  for (size_t p = 0; p < is_lip.size(); ++p)
    is_lip[p] = beyond[p] == kSoftTissue && percentile(height[p], 0.5) >= kLipMinHeightMm;
  std::vector<char> near_points(static_cast<size_t>(lips), 0);
  for (size_t v = 0; v < lip.size(); ++v) {
    if (lip[v] < 0 || !is_lip[static_cast<size_t>(lip[v])] || near_points[static_cast<size_t>(lip[v])]) continue;
    const Eigen::RowVector3d x = V.row(static_cast<Eigen::Index>(v));
    near_points[static_cast<size_t>(lip[v])] = (points.rowwise() - x).rowwise().squaredNorm().minCoeff() <= kLipReachMm * kLipReachMm;
  }
  for (size_t p = 0; p < is_lip.size(); ++p) is_lip[p] = is_lip[p] && near_points[p];
  for (size_t v = 0; v < lip.size(); ++v)
    if (lip[v] >= 0 && is_lip[static_cast<size_t>(lip[v])]) part[v] = first + lip[v];
  return first;
}

}  // namespace

namespace {
// The largest area among `regions` of a kind `of` admits departing by
// kFindingDepthMm or more (0 if none).
template <class Kinds>
double largestDeepMm2(const std::vector<DepartingRegion>& regions, Kinds of) {
  double largest = 0;
  for (const auto& r : regions)
    if (of(r.kind) && r.depth_mm >= kFindingDepthMm) largest = std::max(largest, r.area_mm2);
  return largest;
}
}  // namespace

double CapDepartures::largestFindingMm2() const {
  return largestDeepMm2(regions, [](const std::string& kind) { return kind == "inward" || kind == "outward"; });
}

double CapDepartures::largestBoneBeyondMm2() const {
  return largestDeepMm2(regions, [](const std::string& kind) { return kind == "bone_beyond"; });
}

nlohmann::json CapDepartures::toJson() const {
  nlohmann::json list = nlohmann::json::array();
  for (const auto& r : regions)
    list.push_back({{"kind", r.kind},
                    {"area_mm2", r.area_mm2},
                    {"depth_mm", r.depth_mm},
                    {"centre_mm", {r.centre[0], r.centre[1], r.centre[2]}},
                    {"direction", {r.direction[0], r.direction[1], r.direction[2]}},
                    {"from_cap_axis_deg", r.from_cap_axis_deg},
                    {"where", r.where}});
  return {{"cap_axis", {cap_axis[0], cap_axis[1], cap_axis[2]}},
          {"cap_half_angle_deg", cap_half_angle_deg},
          {"rim_extension_deg", rim_extension_deg},
          {"threshold_mm", threshold_mm},
          {"cap_area_mm2", cap_area_mm2},
          {"min_region_mm2", kMinDepartingRegionMm2},
          {"regions", list}};
}

CapDepartures capDepartures(const CapDepartureInput& in) {
  if (in.points.rows() < 4) throw InputError("cap departures need at least 4 articular points");
  if (in.triangles.rows() == 0) throw InputError("cap departures need the bone's mesh with its triangles");
  CapDepartures out;
  const Eigen::Vector3d c = in.model.center;
  Eigen::MatrixX3d u = in.points.rowwise() - c.transpose();
  u.rowwise().normalize();
  out.cap_axis = u.colwise().mean().transpose().normalized();
  std::vector<double> angles(static_cast<size_t>(u.rows()));
  for (Eigen::Index i = 0; i < u.rows(); ++i) angles[static_cast<size_t>(i)] = degrees(u.row(i).transpose(), out.cap_axis);
  out.cap_half_angle_deg = percentile(angles, 0.98);
  out.rim_extension_deg = kRimExtensionDeg;
  // A hip's neck leaves its head laterally and downwards.
  std::optional<Eigen::Vector3d> neck_side;
  if (in.medial) neck_side = (-*in.medial - Eigen::Vector3d::UnitZ()).normalized();
  const CapDirections cap = capDirections(u, neck_side);

  // The points' own scatter about the model: a departure must exceed it.
  const Eigen::VectorXd residual = distance::signedDistances(in.model, in.points);
  std::vector<double> r(residual.data(), residual.data() + residual.size());
  const double median = percentile(r, 0.5);
  for (double& v : r) v = std::abs(v - median);
  const double robust_sd = 1.4826 * percentile(r, 0.5);
  out.threshold_mm = std::max({kThresholdFloorMm, 3 * robust_sd, 0.3 * in.voxel_mm});

  // The vertices over the cap and its rim, near the head's surface, facing
  // outwards (a cavity's walls inside the label face other ways).
  const Eigen::MatrixX3d& V = in.vertices;
  Eigen::VectorXd area;
  Eigen::MatrixX3d normal;
  vertexAreasAndNormals(V, in.triangles, area, normal);
  const double radius = in.model.radii.maxCoeff();
  std::vector<int> zone;
  std::vector<char> zone_place, past_zone(static_cast<size_t>(V.rows()), 0);
  Eigen::Index facing_out = 0, facing_in = 0;
  for (Eigen::Index v = 0; v < V.rows(); ++v) {
    const Eigen::Vector3d d = V.row(v).transpose() - c;
    const double reach = d.norm();
    past_zone[static_cast<size_t>(v)] = reach > kZoneOuter * radius;
    if (reach < kZoneInner * radius || reach > kZoneOuter * radius) continue;
    const double facing = normal.row(v).dot(d);
    facing_out += facing > 0;
    facing_in += facing < 0;
    zone.push_back(static_cast<int>(v));
    zone_place.push_back(cap.place[static_cast<size_t>(cap.nearest(d / reach))]);
  }
  const double outward_sign = facing_out >= facing_in ? 1.0 : -1.0;  // the mesh's winding, whichever it is
  Eigen::MatrixX3d zone_points(static_cast<Eigen::Index>(zone.size()), 3);
  for (size_t i = 0; i < zone.size(); ++i) zone_points.row(static_cast<Eigen::Index>(i)) = V.row(zone[i]);
  const Eigen::VectorXd distance = distance::signedDistances(in.model, zone_points);

  std::vector<char> inward(static_cast<size_t>(V.rows()), 0), outward(static_cast<size_t>(V.rows()), 0),
      beyond_rim(static_cast<size_t>(V.rows()), 0);
  std::vector<double> vertex_distance(static_cast<size_t>(V.rows()), 0);
  for (size_t i = 0; i < zone.size(); ++i) {
    const int v = zone[i];
    if (outward_sign * normal.row(v).dot(V.row(v) - c.transpose()) <= 0) continue;
    const bool on_cap = zone_place[i] == CapDirections::kCap;
    if (on_cap) out.cap_area_mm2 += area[v];
    const double distance_mm = distance[static_cast<Eigen::Index>(i)];
    vertex_distance[static_cast<size_t>(v)] = distance_mm;
    beyond_rim[static_cast<size_t>(v)] = zone_place[i] == CapDirections::kBeyond;
    // Inwards only over the cap: beyond it the neck curves in by nature.
    if (on_cap && distance_mm < -out.threshold_mm) inward[static_cast<size_t>(v)] = 1;
    if (distance_mm > out.threshold_mm) outward[static_cast<size_t>(v)] = 1;
  }

  std::vector<int> region_of_vertex(static_cast<size_t>(V.rows()), -1);
  for (const bool is_inward : {true, false}) {
    std::vector<int> part = geometry::connectedParts(is_inward ? inward : outward, in.triangles);
    const int first_lip = is_inward || !in.ct || !in.seek_junction_lip ? std::numeric_limits<int>::max()
                                              : splitLipsFromNeck(V, normal * outward_sign, c, in.points, beyond_rim, in.triangles, *in.ct, vertex_distance, part);
    std::vector<DepartingRegion> regions;
    std::vector<char> reaches_beyond, runs_out;
    for (size_t v = 0; v < part.size(); ++v) {
      if (part[v] < 0) continue;
      if (static_cast<size_t>(part[v]) >= regions.size()) {
        regions.resize(static_cast<size_t>(part[v]) + 1);
        reaches_beyond.resize(regions.size(), 0);
        runs_out.resize(regions.size(), 0);
      }
      reaches_beyond[static_cast<size_t>(part[v])] |= beyond_rim[v];
      DepartingRegion& region = regions[static_cast<size_t>(part[v])];
      const double a = area[static_cast<Eigen::Index>(v)];
      region.area_mm2 += a;
      region.centre += a * V.row(static_cast<Eigen::Index>(v)).transpose();
      region.depth_mm = std::max(region.depth_mm, std::abs(vertex_distance[v]));
    }
    // With the CT, a region with bone going on beyond it is no departure of
    // the head's bone: outwards, the surface run into a neighbouring bone (at
    // the dome, the socket across a gap the CT does not resolve: a narrowed
    // joint, or slices too thick for the gap); inwards, a surface left short
    // of a dome the CT does not part from the socket (at 2.5 mm slices over
    // a 2 mm gap the slices there read 430 HU, the head's edge smeared into
    // the socket's). Inwards the CT is read just past the model's surface:
    // over a flattened dome that is the widened gap, which a fixed 3 mm can
    // overshoot into the socket.
    // Outwards, a region whose surface runs on past the zone's outer reach
    // (half a radius out) leaves the head: no osteophyte stands that high;
    // it is another bone the label took in (the socket's roof merged
    // across a gap the slices do not resolve, the pelvis beyond it).
    if (!is_inward)
      for (Eigen::Index t = 0; t < in.triangles.rows(); ++t) {
        bool past = false;
        for (int k = 0; k < 3; ++k) past = past || past_zone[static_cast<size_t>(in.triangles(t, k))];
        if (!past) continue;
        for (int k = 0; k < 3; ++k)
          if (const int p = part[static_cast<size_t>(in.triangles(t, k))]; p >= 0) runs_out[static_cast<size_t>(p)] = 1;
      }
    std::vector<double> out_mm;
    if (is_inward)
      for (const double d : vertex_distance) out_mm.push_back(std::abs(d) + kPastModelMm);
    const std::vector<signed char> beyond =
        !in.ct ? std::vector<signed char>() : whatLiesBeyond(V, normal * outward_sign, *in.ct, part, static_cast<int>(regions.size()), kBoneBeyondHu, out_mm);
    std::vector<int> kept_as(regions.size(), -1);
    for (size_t k = 0; k < regions.size(); ++k) {
      DepartingRegion& region = regions[k];
      // Outwards, a region that runs on beyond the rim is the neck rising
      // out of the head's surface (or a bone beyond it); a lip on the neck
      // at the junction has been given a part of its own above.
      if (region.area_mm2 < kMinDepartingRegionMm2 || (reaches_beyond[k] && static_cast<int>(k) < first_lip)) continue;
      region.centre /= region.area_mm2;
      region.direction = (region.centre - c).normalized();
      region.from_cap_axis_deg = degrees(region.direction, out.cap_axis);
      region.where = anatomicalWords(region.direction, in.medial);
      region.kind = is_inward ? "inward" : "outward";
      // A lip has soft tissue beyond it by the ratio (splitLipsFromNeck).
      const bool lip = static_cast<int>(k) >= first_lip;
      if ((!beyond.empty() && beyond[k] == kBone && !lip) || runs_out[k]) region.kind = "bone_beyond";
      // A hip's fovea capitis: a small pit at the head's medial pole, where
      // the ligament of the head attaches; every femoral head has one.
      if (is_inward && in.medial && degrees(region.direction, *in.medial) <= kFoveaMaxAngleDeg &&
          region.area_mm2 <= kFoveaMaxAreaMm2 && region.depth_mm <= kFoveaMaxDepthMm)
        region.kind = "fovea";
      kept_as[k] = static_cast<int>(out.regions.size());
      out.regions.push_back(region);
    }
    for (size_t v = 0; v < part.size(); ++v)
      if (part[v] >= 0 && kept_as[static_cast<size_t>(part[v])] >= 0) region_of_vertex[v] = kept_as[static_cast<size_t>(part[v])];
  }
  // Largest first, the vertices' region indices following.
  std::vector<int> order(out.regions.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&out](int a, int b) { return out.regions[static_cast<size_t>(a)].area_mm2 > out.regions[static_cast<size_t>(b)].area_mm2; });
  std::vector<int> rank(order.size());
  std::vector<DepartingRegion> sorted;
  for (size_t k = 0; k < order.size(); ++k) {
    rank[static_cast<size_t>(order[k])] = static_cast<int>(k);
    sorted.push_back(out.regions[static_cast<size_t>(order[k])]);
  }
  out.regions = std::move(sorted);
  for (int& region : region_of_vertex)
    if (region >= 0) region = rank[static_cast<size_t>(region)];
  out.region_of_vertex = std::move(region_of_vertex);
  return out;
}

}  // namespace articula::checks
