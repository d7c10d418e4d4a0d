#pragma once
// A synthetic hip CT with a known femoral head, the embedded default input of
// the pipeline and its tests. The head is an exact shape model of
// lib/geometry (sphere ... superovoid, varied by seed), on a neck and a shaft,
// with a cortical rim and cancellous interior, facing an acetabulum across a
// joint gap of chosen width; partial volume (supersampled voxels), Gaussian
// blur and Gaussian noise. All coordinates LPS mm.
//
// The variety of real hips is optional and seeded: head radius, a congruent
// acetabular shell or a spherical socket of a larger radius (the gap then
// widens towards the rim), socket wall and HU, osteoporotic bone (thin, faint
// cortex, cancellous HU that varies in space), a fovea capitis pit, and both
// hips in one field of view with a pelvis-like frame (ilium and pubic rami
// joining the sockets to a sacrum and a pubic symphysis).
//
// What clinical CT adds, each optional (all off by default, so that a seed
// keeps its CT): the changes of an arthritic hip on the requested side's head
// (a flattened dome, osteophytes at the head-neck junction, subchondral cysts,
// a joint space narrowed over a superior patch), recorded in truth.json as
// departures of the true articular surface from the head's model; and the
// scan's (a field of view that clips the head, a screw or a stem with metal
// streaks, soft or sharp kernels, a contrast-filled vessel, the patient
// table, slices thicker than their spacing).
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "articula/geometry/shape.hpp"
#include "articula/imaging/image.hpp"

namespace articula::phantom {

struct PhantomOptions {
  unsigned long long seed = 1;
  std::optional<geometry::ShapeModel> model;                // default: chosen by seed
  Eigen::Vector3d spacing = Eigen::Vector3d(0.7, 0.7, 1.5); // mm
  double gap_mm = 3.0;                                      // joint gap, head to socket
  bool right = true;                                        // patient side (right hip: x < 0)
  bool ras_storage = false;  // store with direction diag(-1,-1,1), like a NIfTI saved RAS
  double noise_hu = 20.0;    // standard deviation of the Gaussian noise
  double blur_mm = 0.5;      // standard deviation of the Gaussian point-spread
  double cortical_hu = 1300, cancellous_hu = 350, soft_tissue_hu = 40;
  double cortical_mm = 1.5;  // cortical thickness
  /// The cortex, the joint gap and the congruent socket's wall measured along
  /// the exact distance to the head (lib/distance), so that they have the
  /// stated widths. Off (the original phantom, kept so that a seed keeps its
  /// CT): along the first-order distance -F / |grad F|, which widens the gap
  /// and the wall (on a 21 mm sphere a 3 mm gap is 3.2 mm, a 12 mm wall
  /// 16.6 mm) and thins the cortex (1.5 -> 1.45 mm). The head surface itself
  /// is exact either way.
  bool exact_depth = false;
  /// Amplitude of a smooth spatial variation of the cancellous HU (wavelength
  /// about 30 mm, phases by seed); 0 keeps it uniform.
  double cancellous_variation_hu = 0.0;

  /// The head's mean radius r0 (the radii of non-spheres vary +-6 % about it):
  /// drawn uniformly from head_radius_range_mm unless head_radius_mm is given.
  std::optional<double> head_radius_mm;
  Eigen::Vector2d head_radius_range_mm = Eigen::Vector2d(20.0, 25.0);

  /// Congruent: a shell following the head at gap_mm. Otherwise a spherical
  /// socket of inner radius (head's largest radius + gap + socket_excess_mm),
  /// its pole gap_mm from the head's bounding sphere, wider towards the rim.
  bool congruent_socket = true;
  double socket_excess_mm = 3.0;
  double socket_wall_mm = 12.0;  // acetabular wall thickness
  std::optional<double> socket_cortical_hu, socket_cancellous_hu;  // default: the femur's

  /// A fovea capitis: a spherical pit of this radius and depth on the head,
  /// medial, a little posterior and inferior.
  bool fovea = false;
  double fovea_radius_mm = 5.0, fovea_depth_mm = 2.0;

  /// Both hips in one field of view (heads about 184-196 mm apart) with a
  /// pelvis-like frame; `right` names the side whose head is the top-level
  /// truth and label 1 (the other femur is label 2).
  bool both_hips = false;

  /// Arthritis, on the requested side's head (the other hip stays normal).
  /// A flattened dome: the head cut by a plane this fraction of its mean
  /// radius below its top along the weight-bearing (superior, +z) direction,
  /// the cut covered by new cortex; 0: none.
  double flattened_dome = 0.0;
  /// Osteophytes: a bony lip of this height (mm) along the head-neck
  /// junction, a partial ring (about 150 degrees) on its superior side; 0: none.
  double osteophytes_mm = 0.0;
  /// Subchondral cysts: three fluid-filled spheres 2-5 mm across just under
  /// the cortex of the superior cap.
  bool cysts = false;
  /// The joint space narrowed to this width (mm) over a superior patch of
  /// the cap (full within 20 degrees of superior, back to gap_mm at 32); 0: none.
  double narrow_gap_mm = 0.0;
  double cyst_hu = 20.0;  // fluid and fibrous tissue

  /// A field of view that clips the requested side's head: the stored grid
  /// ends (its last voxel centres) at a plane across fov_face (a unit LPS
  /// axis: +x left, -x right, +y posterior, -y anterior, +z superior, -z
  /// inferior), the head reaching fov_cut x its mean radius beyond it (0:
  /// tangent). Negative: the whole field.
  double fov_cut = -1.0;
  Eigen::Vector3d fov_face = Eigen::Vector3d::UnitZ();

  /// Metal on the requested side: a lag screw (6.5 mm) along the femoral
  /// neck into the head, or a stem (12 mm) in the femoral shaft, at
  /// metal_hu; with streaks (seeded bright and dark lines through the metal
  /// in each axial slice, fading with distance) and dark bands along the
  /// metal's long chords and between its parts; the CT then clipped to the
  /// scanner's range [-1024, 3071] HU.
  enum class Metal { None, Screw, Stem };
  Metal metal = Metal::None;
  double metal_hu = 8000.0;

  /// The reconstruction kernel, applied within the slices to the blurred
  /// tissues and their noise: soft smooths (a further Gaussian of 0.6 mm),
  /// sharp enhances edges (unsharp masking, sigma 0.8 mm, gain 1: an
  /// overshoot at each edge and noise about twice as strong, correlated).
  enum class Kernel { Standard, Soft, Sharp };
  Kernel kernel = Kernel::Standard;
  /// A contrast-filled vessel, 6 mm across at vessel_hu, running superior to
  /// inferior anterior-medial to the requested head, its wall 5 mm from the
  /// head's bounding sphere, like the femoral artery of a CT angiogram.
  bool contrast_vessel = false;
  double vessel_hu = 300.0;
  /// The patient table: a curved slab (radius 400 mm, 6 mm thick, 700 HU)
  /// under the patient's back, posterior, with air beyond it; the grid grows
  /// 26 mm posteriorly to hold it.
  bool table = false;
  /// Slices thicker than their spacing: each slice averages the tissues over
  /// a box this wide (mm) across the slices, before the blur; 0 or up to
  /// spacing[2]: the slice's own width.
  double slice_thickness_mm = 0.0;

  /// Osteoporotic bone: cortex 0.8 mm at 700 HU, cancellous 190 +- 90 HU.
  void makeOsteoporotic();
  /// Throws UsageError naming the first invalid option.
  void validate() const;
};

/// A flattened dome: the head less the half-space beyond a plane, whose cut
/// the cortex follows.
struct FlatDome {
  Eigen::Vector3d point, normal;  // the plane: bone only where (x - point) . normal <= 0
  Eigen::Vector3d top;            // the model surface's support point along `normal`, the deepest cut
  double fraction = 0;            // depth over the head's mean radius
  double depth_mm = 0;            // from `top` to the plane
  double area_mm2 = 0;            // of the model surface beyond the plane (cut away)
};

/// Osteophytes: a chain of capsules of one radius whose axis lies on the
/// model surface along the head-neck junction (a lip of that height).
struct Osteophytes {
  std::vector<Eigen::Vector3d> path;  // LPS mm, on the model surface
  double radius_mm = 0;               // the lip's height
  double area_mm2 = 0;                // of the model surface the lip covers
  /// Signed distance to the lip (negative inside), exact outside it.
  double distance(const Eigen::Vector3d& x) const;
};

/// A subchondral cyst: a fluid-filled ball under the cortex.
struct Cyst {
  Eigen::Vector3d center;
  double radius_mm = 0;
};

/// A joint space narrowed over a patch of the cap: the socket advances to
/// `gap_mm` from the head within `full_deg` of `direction` (from the head's
/// centre) and returns to the joint's gap at `end_deg`.
struct NarrowGap {
  Eigen::Vector3d direction, centre;  // centre: the model surface along direction
  double gap_mm = 0, full_deg = 20, end_deg = 32;
  double area_mm2 = 0, full_area_mm2 = 0;  // of the model surface within end_deg and full_deg
  /// 1 within full_deg of the direction, falling smoothly to 0 at end_deg.
  double weight(const Eigen::Vector3d& from_head_centre) const;
};

/// One hip's truth.
struct Hip {
  bool right = true;
  geometry::ShapeParameters head;     // the head's outer (periosteal) surface
  Eigen::Vector3d neck_axis;          // unit, from the head centre along the neck
  Eigen::Vector3d socket_axis;        // unit, from the head centre to the socket's pole
  Eigen::Vector3d socket_center;      // spherical socket: its centre (congruent: the head's)
  double socket_inner_radius_mm = 0;  // spherical socket: inner radius (congruent: 0)
  bool fovea = false;
  Eigen::Vector3d fovea_center;       // centre of the pit's sphere
  double fovea_radius_mm = 0;
  // Arthritic departures (the requested side's head only):
  std::optional<FlatDome> flat_dome;
  std::optional<Osteophytes> osteophytes;
  std::vector<Cyst> cysts;
  std::optional<NarrowGap> narrow_gap;
};

struct Phantom {
  imaging::Volume ct;                 // HU
  imaging::Label femur;               // truth: head, neck and shaft (voxel centre inside); both hips: 1 and 2
  geometry::ShapeParameters head;     // the requested side's head (hips[0].head)
  Eigen::Vector3d neck_axis;          // unit, from the head centre along the neck
  std::vector<Hip> hips;              // the requested side first
  nlohmann::json truth;               // everything above, for truth.json
};

/// Metal::None, Screw or Stem from "none", "screw", "stem"; throws UsageError otherwise.
PhantomOptions::Metal metalFromName(const std::string& name);

/// Kernel::Standard, Soft or Sharp from "standard", "soft", "sharp"; throws UsageError otherwise.
PhantomOptions::Kernel kernelFromName(const std::string& name);

/// The unit LPS direction of a face of the field of view: +x, -x, +y, -y,
/// +z, -z, or the patient's L, R, P, A, S, I; throws UsageError otherwise.
Eigen::Vector3d faceDirection(const std::string& face);

/// Builds the phantom; deterministic for a given options.seed.
Phantom makePhantom(const PhantomOptions& options);

/// Signed distance (mm, negative inside the bone) from x to a hip's true
/// articular surface: the head, less the fovea pit where there is one, less
/// a flattened dome's cut, with osteophytes added; head_distance_mm is the
/// signed distance to the head's model. Exact where one of these surfaces is
/// nearest and away from the rims where they meet.
double headSurfaceDistance(const Hip& hip, double head_distance_mm, const Eigen::Vector3d& x);

/// A hip read back from its truth.json entry (the keys hipTruth writes):
/// the head, its fovea and its departures.
Hip hipFromTruth(const nlohmann::json& truth);

}  // namespace articula::phantom
