#pragma once
// Iso-surface of a label image with VTK (flying edges), Laplacian or
// windowed-sinc smoothing, the largest connected surface, optional
// decimation and normals, in the label's physical LPS millimetres; and
// triangle-mesh file I/O (VTP, STL, PLY by extension).
#include <filesystem>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "articula/imaging/image.hpp"

namespace articula::mesh {

/// #V x 3 vertices (LPS mm), #V x 3 unit outward normals (may be empty), #F x 3 triangles.
struct TriangleMesh {
  Eigen::MatrixX3d vertices;
  Eigen::MatrixX3d normals;
  Eigen::MatrixX3i triangles;
  /// Per vertex, 1 where the label ends inside bone, 0 elsewhere; empty
  /// when not known. From the label (extractSurface: the nearest voxel is
  /// imaging::kLabelCutThroughBone, the segmentation's cut) or, once
  /// snapToEdges has moved the surface on voxels up to
  /// imaging::kSeparateEdgesMaxVoxelMm, instead from the CT (no bone edge
  /// along the normal, as where the head was cut from its neck). Written to
  /// and read from a .vtp as the point array points::kCutThroughBoneArray.
  std::vector<unsigned char> cut_through_bone;
};

enum class Smoothing { Laplacian, WindowedSinc, None };

struct MeshOptions {
  Smoothing smoothing = Smoothing::Laplacian;
  int smooth_iterations = 20;
  double relaxation = 0.1;         // Laplacian step (vtkSmoothPolyDataFilter)
  double passband = 0.1;           // windowed sinc pass band
  bool largest_component = true;
  double decimate = 0.0;           // fraction of triangles to remove, 0 = none
  /// Throws UsageError naming the first invalid option.
  void validate() const;
};

struct MeshSummary {
  long long label_voxels = 0;
  long long raw_triangles = 0;      // after flying edges
  long long triangles = 0;          // final
  long long vertices = 0;
};

/// Extracts the boundary of label > 0 as an oriented triangle mesh with
/// outward normals, its vertices on the label's cut through bone marked.
/// Throws InputError if the label has no voxel set.
TriangleMesh extractSurface(const imaging::Label& label, const MeshOptions& options, MeshSummary* summary = nullptr);

enum class EdgeModel { Automatic, SteepestFall, Cortex };

/// The coarsest voxels on which the automatic edge model is the
/// blurred-cortex model: in-plane voxels up to kCortexModelMaxInPlaneMm and
/// slices up to kCortexModelMaxSliceMm. There the model's surface lay within
/// 0.05 mm of the true one on average on 65 of 84 heads of three phantom
/// generators at 0.6-1 mm in-plane and within 0.1 mm on 82, thin cortices
/// included, where the steepest fall lay 0.04-0.42 mm outside; at 1.2-1.5 mm
/// in-plane within 0.05 mm on 23 of 28 and within 0.17 on all, where the
/// steepest fall lay 0.08-1.04 mm outside (docs/benchmarks.md, "Surface bias
/// by voxel size").
constexpr double kCortexModelMaxInPlaneMm = 1.5, kCortexModelMaxSliceMm = 3.0;

struct EdgeSnapOptions {
  double search_mm = 0;         // edge search either side of a vertex (0: 1.5 voxels inwards, at least 1.5 mm; a quarter voxel outwards, at least 0.75 mm)
  double min_contrast_hu = 150; // least fall across an edge (see imaging/edges.hpp)
  double min_inside_hu = 200;   // the bone side of an edge reaches at least this
  int smoothing_passes = 2;     // neighbour averages of the shifts (CT noise)
  /// Where the edge is put: on the steepest fall, or moved from it onto the
  /// outer surface of a blurred-cortex model fitted to the voxels about the
  /// normal (imaging/cortex_edge.hpp), which a thin cortex does not pull
  /// outwards; Automatic: the model on CTs whose voxels are at most
  /// kCortexModelMaxInPlaneMm within the slices and kCortexModelMaxSliceMm
  /// across them, the steepest fall beyond.
  EdgeModel edge_model = EdgeModel::Automatic;
  /// The scanner's Gaussian point-spread for the model, mm, within the
  /// slices and across them (0: both estimated from the CT's own edges;
  /// the slice width 0: as within the slices).
  double point_spread_mm = 0, slice_point_spread_mm = 0;
  /// What a voxel averages over across the slices, mm, where the CT does not
  /// say (a NIfTI file holds no slice thickness); 0: the CT's own
  /// (imaging::ImageGeometry::voxelExtent).
  double slice_thickness_mm = 0;
  int threads = 1;  // worker threads of the cortex model's fits (0: every hardware thread)
  /// Throws UsageError naming the first invalid option.
  void validate() const;
};

struct EdgeSnapSummary {
  long long vertices = 0, on_edge = 0;  // vertices, those with an edge found along their normal
  bool moved = false;                   // false: too few edges, the surface is the label's
  double mean_shift_mm = 0;             // mean signed shift along the outward normal
  double mean_abs_shift_mm = 0;
  /// The blurred-cortex model: whether it placed the edges, the point-spread
  /// it used (estimated or given; 0 when none), the vertices it placed and
  /// their mean shift from the steepest fall (negative: inwards).
  bool cortex_model = false;
  double point_spread_mm = 0, slice_point_spread_mm = 0;  // within the slices, across them
  bool point_spread_estimated = false;
  bool point_spread_on_voxel_grid = false;  // the blur was an image filter's on the voxels (imaging::PointSpread::Kind)
  bool cortex_held_across_slices = false;   // the lines across the slices held the cortex of the lines within them
  double ct_noise_hu = 0;                   // the CT's noise voxel to voxel (imaging::noiseHu), which widens the model's lines
  double line_radius_mm = 0;                // the model's lines' radius within the slices (imaging::lineRadiusFor)
  double slice_thickness_mm = 0;            // what a voxel was taken to average over across the slices
  long long on_cortex_model = 0;
  double mean_model_shift_mm = 0;
  std::string cortex_model_note;  // why the model was not used, when it was asked for
};

/// Moves every vertex along its normal onto the CT's bone edge (the
/// steepest HU fall, imaging::locateEdge; where the window holds none, the
/// first fall going out through bone, within 3 mm, for voxels up to 2 mm;
/// with the cortex model, the outer surface of the blurred cortex), so that the surface lies where
/// the cortex meets soft tissue at sub-voxel precision and not where the
/// label's voxels end; shifts averaged over neighbours against CT noise,
/// vertices without an edge (a cut through bone) follow their neighbours
/// and, on voxels up to imaging::kSeparateEdgesMaxVoxelMm, are marked in
/// mesh.cut_through_bone in place of the label's marks. Normals are
/// recomputed. The CT's grid may differ from the label's. When fewer than a
/// quarter of the vertices find an edge, nothing moves (summary tells).
void snapToEdges(TriangleMesh& mesh, const imaging::Volume& ct, const EdgeSnapOptions& options,
                 EdgeSnapSummary* summary = nullptr);

/// Writes .vtp, .stl or .ply (chosen by extension) atomically.
void writeMesh(const std::filesystem::path& path, const TriangleMesh& mesh, bool overwrite = true);
/// Points with one value each (say signed distances) as a .vtp point cloud
/// whose active scalars are the values under `name`: 3D Slicer and ParaView
/// colour it by the values themselves (a PLY would hand them RGB only).
/// Written uncompressed (raw appended data), for speed on large clouds.
void writePointValues(const std::filesystem::path& path, const Eigen::MatrixX3d& points, const std::string& name,
                      const Eigen::VectorXd& values, bool overwrite = true);
/// Reads .vtp, .stl, .ply, .vtk or .obj; computes normals if the file has none.
/// Throws InputError for a missing or unreadable file or a mesh with no triangles.
TriangleMesh readMesh(const std::filesystem::path& path);

}  // namespace articula::mesh
