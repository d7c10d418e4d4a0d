#pragma once
// Articular-surface selection on a bone mesh, the thesis's manual Blender
// step (section 3.2.2) made automatic: the head's spherical region found by
// CGAL's Efficient RANSAC (spheres of plausible radius), then the vertices in
// a band around that sphere whose normals point radially outwards, as the
// largest connected patch of the mesh, and last a band around that patch's
// own ellipsoid (a head is not a sphere); or a region given by hand.
#include <string>
#include <vector>

#include <Eigen/Core>

namespace articula::sampling {

struct SelectOptions {
  enum class Mode { Auto, Sphere, Box };
  Mode mode = Mode::Auto;
  Eigen::Vector3d center = Eigen::Vector3d::Zero();  // Sphere: centre (LPS mm)
  double radius = 0;                                  // Sphere: radius (mm)
  Eigen::Vector3d box_min = Eigen::Vector3d::Zero(), box_max = Eigen::Vector3d::Zero();  // Box (LPS mm)
  double min_radius_mm = 15, max_radius_mm = 35;      // Auto: plausible joint heads
  double band_mm = 1.0;                               // Auto: |distance to sphere| tolerated
  double normal_deg = 30;                             // Auto: normal vs radial direction
  int min_points = 100;                               // fewer selected: InputError
  unsigned long long seed = 42;                       // RANSAC sampling
  /// Throws UsageError naming the first invalid option.
  void validate() const;
};

/// Parses "auto", "sphere:X,Y,Z,R" or "box:XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX" into
/// options.mode and its geometry; throws UsageError on anything else.
void parseSelection(const std::string& text, SelectOptions& options);

struct Selection {
  std::vector<int> indices;                           // selected vertex rows
  Eigen::Vector3d sphere_center = Eigen::Vector3d::Zero();  // Auto: least-squares sphere of the patch
  double sphere_radius = 0;
  double sphere_rms_mm = 0;                           // RMS radial residual of the patch
  int ransac_spheres = 0;                             // spheres RANSAC found in the radius range
  int concave_left_out = 0;                           // Auto: the chosen patch's vertices where the surface is concave
  int cut_through_bone_left_out = 0;                  // vertices where the label ends inside bone, left out
  int cut_through_bone_kept = 0;                      // such vertices kept: fewer than min_points would remain
};

/// Selects the articular vertices of a mesh: #V x 3 vertices V (mm), #V x 3
/// unit outward normals N, #F x 3 triangles F (for connectivity); where
/// `cut_through_bone` holds a mark per vertex (mesh::TriangleMesh), the
/// vertices where the label ends inside bone are left out, unless fewer
/// than options.min_points would remain. Throws
/// ProcessingError (exit 1) when no sphere of plausible radius is found and
/// InputError when fewer than options.min_points are selected.
Selection selectArticular(const Eigen::MatrixX3d& V, const Eigen::MatrixX3d& N, const Eigen::MatrixX3i& F,
                          const SelectOptions& options, const std::vector<unsigned char>& cut_through_bone = {});

/// The CGAL version this build selects articular surfaces with.
std::string cgalVersion();

}  // namespace articula::sampling
