#pragma once
// Checks that reveal a wrong structure taken for a joint head: the fitted
// head's radius against plausible heads, the angular extent of the
// articular cap, the share of point normals pointing away from the head's
// centre (a socket's inner surface points towards it), the points' spread
// about their sphere, the agreement of the head search with the fit,
// whether the search could tell the joint's side, and whether the CT shows
// the bone's edge where the points are (a label cut inside the head, where
// a faint cortex fell below the bone window, has points inside the bone).
// At coarser voxels, where the CT's edges are checked no more, a label much
// thinner than its head's radius (a shell: cancellous bone below the bone
// window) must still have its points on the CT's edge. A femoral head sits
// in its acetabulum: beyond a good share of its articular surface, across
// the joint gap, the CT rises again (a socket's outer surface, taken for a
// head where a faint head merged with it, has soft tissue beyond).
// One check is of the surface's accuracy, not of the structure: whether
// the cortex still shows across the slices (where a thin cortex is blurred
// away there, the edge found lies outside the bone's surface).
// Each check passes, warns (doubtful) or fails (the result is not a head).
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "articula/imaging/image.hpp"

namespace articula::checks {

struct PointsOnCtEdge {
  double on_edge = 0;      // share of the points with the bone's edge within half a voxel (at least 0.5 mm)
  double inside_bone = 0;  // share with the edge further out: the points lie inside the bone
};

struct HeadQcInput {
  Eigen::MatrixX3d points;                   // articular points (LPS mm)
  Eigen::MatrixX3d normals;                  // their outward normals (may be empty: that check is skipped)
  Eigen::Vector3d sphere_center = Eigen::Vector3d::Zero();  // the fitted sphere
  double sphere_radius_mm = 0;
  std::optional<Eigen::Vector3d> search_center;  // the segmentation's head, if it searched
  double search_radius_mm = 0;
  std::optional<bool> side_verified;             // the search's side check, if it searched
  std::optional<bool> found_by_edges;            // the search's head: a sphere through bone edges, else its fallback
  std::optional<PointsOnCtEdge> ct_edges;        // where the CT's bone edge is about the points, if a CT was given
  double ct_voxel_mm = 0;                        // the CT's largest spacing: its edge checks apply up to 2 mm
  std::optional<double> label_depth_mm;          // the segmentation's label: the depth of its deepest voxel
  std::optional<double> socket_facing_share;     // socketFacing's share, for a hip where measurable
  std::optional<double> joint_space_mm;          // socketFacing's joint space, for a hip where measurable
  std::optional<double> cortex_contrast_across_slices;  // cortexContrastAcrossSlices, where measurable
  std::optional<double> head_outside_volume_share;  // headOutsideVolumeShare, where a CT was given
  std::optional<double> metal_near_head_mm3;     // metalNearHead, where a CT was given
  std::optional<double> ct_noise_hu;             // the segmentation's measure of the CT's noise (imaging/noise.hpp)
  std::optional<double> cap_departure_mm2;       // CapDepartures::largestFindingMm2, where the bone's mesh was given
  std::optional<double> cap_bone_beyond_mm2;     // CapDepartures::largestBoneBeyondMm2, where the mesh was given
  std::vector<std::string> stage_warnings;       // what the stages warned of (the segmentation's summary: reading, search)
  std::optional<bool> surface_on_ct_edges;       // the mesh stage moved the surface onto the CT's edges (else the label's staircase)
  std::optional<double> points_on_cut_share;     // the sample stage's articular points kept on the label's cut (no bone edge), of all
  std::string joint;                             // "hip" or "shoulder", for the head's distance from the body's middle
  std::optional<double> body_middle_x_mm;        // the search's body middle (LPS x), if it judged the side by one
  double min_radius_mm = 15, max_radius_mm = 35;  // plausible joint heads
  std::optional<double> head_beyond_fov_mm;      // headBeyondFieldOfView, where a CT was given
};

struct QcCheck {
  std::string name, status;  // status: pass, warn or fail
  double value = 0;
  std::string rule, reason;  // the limits; why it warned or failed (empty on pass)
  bool of_structure = true;  // a doubt about the structure taken (two such warnings fail the head)
};

struct QcReport {
  std::string status = "pass";  // the worst of the checks
  std::vector<QcCheck> checks;
  std::vector<std::string> reasons() const;  // of every check that did not pass
  nlohmann::json toJson() const;
};

/// Where the bone's edge in the CT (imaging::firstEdgeAlongRay: the first
/// fall of at least 150 HU from bone going out along each outward normal
/// from 3 mm inside) lies about `points`: the shares of the points within
/// half a voxel (at least 0.5 mm) of it and inside the bone.
PointsOnCtEdge pointsOnCtEdge(const imaging::Volume& ct, const Eigen::MatrixX3d& points, const Eigen::MatrixX3d& normals);

/// How much of the cortex's contrast over the cancellous bone survives the
/// blur across the slices: on lines along the outward normals, the median
/// of (the highest HU from 3 mm inside to 0.5 mm outside the point, less
/// the HU 4 mm inside) on lines that cross the slices (|normal . slice
/// axis| > 0.8), over the same on lines within a slice (< 0.3). About 1
/// where the cortex is thicker than the blur across the slices; near 0
/// where it is blurred into the cancellous bone there. Empty where it cannot
/// be measured: fewer than 20 lines in either group, or a contrast within a
/// slice below 100 HU (no cortex shows even there). The slice axis is the
/// voxel axis of the largest spacing (the third on a tie).
std::optional<double> cortexContrastAcrossSlices(const imaging::Volume& ct, const Eigen::MatrixX3d& points,
                                                 const Eigen::MatrixX3d& normals);

/// The share of the points whose outward normal, within a slice (|normal .
/// slice axis| <= 0.5, where a joint gap is resolved best), meets a rise of
/// at least 100 HU over the lowest HU before it, from 0.5 to 8 mm outside
/// the point: a socket across a joint gap of up to about 5 mm. Empty where
/// the voxels within a slice exceed 2 mm (a gap is not resolved) or fewer
/// than 20 such lines lie within the grid.
struct SocketFacing {
  double share = 0;                      // of the lines within the grid, those that meet a socket
  std::optional<double> joint_space_mm;  // the median distance, on those, from the point to the socket's half rise (20 lines at least)
};
std::optional<SocketFacing> socketFacing(const imaging::Volume& ct, const Eigen::MatrixX3d& points,
                                         const Eigen::MatrixX3d& normals);

/// The share of the fitted sphere's surface that lies outside the CT's
/// field of view (beyond its outermost voxel centres), over the directions
/// from its centre more than 45 degrees from the neck (the opposite of the
/// articular points' mean direction): a head the field of view clips. Its
/// points then cover only what is in view, and the fit extrapolates the rest.
double headOutsideVolumeShare(const imaging::ImageGeometry& grid, const Eigen::MatrixX3d& points,
                              const Eigen::Vector3d& center, double radius_mm);

/// How far (mm) the fitted sphere reaches beyond the CT's outermost voxel
/// centres on its farthest side, the neck's side included (0: wholly in
/// view): a field of view that ends inside the head, also where the share
/// above misses it (a face on the neck's side clips the head's margin by
/// the neck, within the cone that share leaves out).
double headBeyondFieldOfView(const imaging::ImageGeometry& grid, const Eigen::Vector3d& center, double radius_mm);

/// The volume (mm^3) of the voxels above 2,500 HU (metal: screws, stems,
/// wires; cortical bone stays below) within twice the head's radius of its
/// centre: streaks and dark bands from metal can bias the head's surface.
double metalNearHead(const imaging::Volume& ct, const Eigen::Vector3d& center, double radius_mm);

/// Runs every check that its inputs allow; throws InputError for fewer than 4 points.
QcReport checkHead(const HeadQcInput& input);

}  // namespace articula::checks
