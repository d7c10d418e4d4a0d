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
#include <optional>
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

  /// Osteoporotic bone: cortex 0.8 mm at 700 HU, cancellous 190 +- 90 HU.
  void makeOsteoporotic();
  /// Throws UsageError naming the first invalid option.
  void validate() const;
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
};

struct Phantom {
  imaging::Volume ct;                 // HU
  imaging::Label femur;               // truth: head, neck and shaft (voxel centre inside); both hips: 1 and 2
  geometry::ShapeParameters head;     // the requested side's head (hips[0].head)
  Eigen::Vector3d neck_axis;          // unit, from the head centre along the neck
  std::vector<Hip> hips;              // the requested side first
  nlohmann::json truth;               // everything above, for truth.json
};

/// Builds the phantom; deterministic for a given options.seed.
Phantom makePhantom(const PhantomOptions& options);

/// Signed distance (mm, negative inside the bone) from x to a hip's true
/// articular surface: the head, less the fovea pit where there is one.
double headSurfaceDistance(const Hip& hip, double head_distance_mm, const Eigen::Vector3d& x);

}  // namespace articula::phantom
