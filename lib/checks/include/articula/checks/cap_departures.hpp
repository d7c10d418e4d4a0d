#pragma once
// Where the bone departs from the fitted head: what the articular selection
// leaves out, measured instead of dropped. The selection keeps the vertices
// within a band of the head's own surface, so a flattened weight-bearing
// dome, an erosion or an osteophyte on the cap's rim falls outside the
// points and the fit never sees it. Here every vertex of the bone's mesh
// over the articular cap (and, outwards, a rim beyond it) is measured
// against the fitted model, and the connected regions that depart by more
// than the points' own scatter are reported with their area, depth and place.
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "articula/geometry/shape.hpp"
#include "articula/imaging/image.hpp"

namespace articula::checks {

struct DepartingRegion {
  // "inward", "outward", "fovea" (a hip's inward pit at the medial pole:
  // normal anatomy) or "bone_beyond" (outward, with the CT's bone going on
  // beyond it or the surface running on past half a radius out: the surface
  // run into a neighbouring bone, such as the socket across a joint gap the
  // CT does not resolve).
  std::string kind;
  double area_mm2 = 0;     // the mesh area of its vertices
  double depth_mm = 0;     // its largest distance from the model (positive, in either direction)
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();     // area-weighted mean of its vertices (LPS mm)
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();  // from the model's centre to `centre`, unit (LPS)
  double from_cap_axis_deg = 0;                         // angle of `direction` from the cap's axis
  std::string where;       // anatomical words for `direction`, e.g. "superior, lateral"
};

struct CapDepartures {
  Eigen::Vector3d cap_axis = Eigen::Vector3d::Zero();  // the articular points' mean direction from the centre
  double cap_half_angle_deg = 0;                       // 98th percentile of the points' angles from it
  double rim_extension_deg = 0;                        // outward departures are sought this far beyond the cap
  double threshold_mm = 0;                             // a vertex departs beyond this distance
  double cap_area_mm2 = 0;                             // mesh area measured within the cap
  std::vector<DepartingRegion> regions;                // area at least kMinDepartingRegionMm2, largest first
  std::vector<int> region_of_vertex;                   // per mesh vertex: its index in `regions`, or -1
  /// The largest area among inward and outward regions departing by
  /// kFindingDepthMm or more (0 if none): the bone's own departures.
  double largestFindingMm2() const;
  /// The same among "bone_beyond" regions.
  double largestBoneBeyondMm2() const;
  nlohmann::json toJson() const;
};

/// Regions smaller than this (mm^2) are left out: specks of the mesh's noise.
inline constexpr double kMinDepartingRegionMm2 = 10.0;
/// A region departing less deeply is listed but is no finding. On the
/// clinical bench's 246 phantom cases a dome flattened by a tenth of the
/// radius (1.8-2.8 mm) departs by 1.72-2.7 mm over 94-370 mm^2, a 3 mm lip
/// by up to 5; of 70 correct heads at 0.6 mm to 1.5 x 1.5 x 3 mm voxels one
/// (1.5 x 1.5 x 3 mm) has a region 1.7-2 mm deep over more than 40 mm^2.
inline constexpr double kFindingDepthMm = 1.7;

struct CapDepartureInput {
  Eigen::MatrixX3d vertices;   // the bone's mesh (LPS mm)
  Eigen::MatrixX3i triangles;
  geometry::ShapeParameters model;  // the selected fit
  Eigen::MatrixX3d points;     // the articular points it was fitted to
  double voxel_mm = 0;         // the CT's largest spacing, if known: the threshold is at least 0.3 voxel
  std::optional<Eigen::Vector3d> medial;  // a hip's medial direction (towards the body's middle): where its fovea lies
  const imaging::Volume* ct = nullptr;    // the CT the mesh came from, if known: lips at the junction and bone beyond are told only with it
  // A hip: a lip at the head-neck junction is sought (with the CT). Not on
  // a shoulder, where the tuberosities beside the anatomical neck stand out
  // from the head as a lip would.
  bool seek_junction_lip = false;
};

/// Measures the mesh's vertices over the cap (angle from the cap's axis up to
/// its half-angle; inwards) and its rim (up to rim_extension beyond;
/// outwards), within 0.5-1.5 model radii of the centre and facing outwards,
/// against the model's exact signed distance. A vertex departs beyond
/// max(0.75 mm, 3 x the points' robust residual SD, 0.3 voxel). Outward
/// regions that run on beyond the rim (the neck) are left out, but for a
/// lip on them at a hip's junction, which is sought with the CT. With the
/// CT, an outward region with bone beyond it is of kind "bone_beyond"; so,
/// with or without it, is one whose surface runs on past 1.5 model radii.
CapDepartures capDepartures(const CapDepartureInput& input);

}  // namespace articula::checks
