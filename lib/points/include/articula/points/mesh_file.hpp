#pragma once
// The project's one reader of mesh files (.stl, .obj, .vtp, .vtk, .ply),
// through VTK's readers with their errors collected instead of printed and
// the checks VTK does not make (a binary STL's size, an OBJ's indices, a
// .vtp's component counts), and .ply and legacy .vtk through the project's
// own readers: the mesh stage's input and the vertices a point file may be.
// Eigen out, VTK stays inside lib/points.
#include <filesystem>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace articula::points {

struct MeshFile {
  Eigen::MatrixX3d vertices;   // #V x 3, LPS millimetres
  Eigen::MatrixX3d normals;    // #V x 3 point normals as the file has them, or 0 rows
  Eigen::MatrixX3i triangles;  // #F x 3, 0-based (polygons triangulated), possibly 0 rows
  /// Per vertex, a .vtp's (or .vtk's) point array kCutThroughBoneArray (articula mesh: 1
  /// where the label ends inside bone), or empty when the file has none.
  std::vector<unsigned char> cut_through_bone;
};

/// The .vtp (or .vtk) point array in which the mesh stage marks the vertices where the label ends inside bone.
inline constexpr const char* kCutThroughBoneArray = "CutThroughBone";

/// Reads a mesh by extension (case-insensitive). Throws InputError naming
/// the file: missing, another extension, VTK's or the project's reader's
/// first error, no vertices.
MeshFile readMeshFile(const std::filesystem::path& path);

/// The VTK version this build meshes and reads surfaces with.
std::string vtkLibraryVersion();

}  // namespace articula::points
