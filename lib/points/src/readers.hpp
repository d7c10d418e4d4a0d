#pragma once
// Internal: one reader per file family, and the checks they share.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "articula/points/point_io.hpp"

namespace articula::points::detail {

/// Hand-written PLY reader (see ply_reader.cpp for why not vtkPLYReader).
PointCloud readPly(const std::filesystem::path& path);
/// A PLY mesh, by the same reader: its vertices (and normals), and its faces'
/// vertex indices (0-based, each a vertex the file has), face i's at
/// face_indices[face_offsets[i] .. face_offsets[i + 1]).
struct PlyMesh {
  PointCloud cloud;
  std::vector<std::int64_t> face_offsets{0}, face_indices;
};
PlyMesh readPlyMesh(const std::filesystem::path& path);
/// A legacy VTK POLYDATA mesh (.vtk), by the project's reader (see vtk_legacy_reader.cpp for why
/// not vtkPolyDataReader): its points (#P x 3), point normals (#P x 3, or 0 rows), the point array
/// CutThroughBone (#P values, or empty), and its polygons and triangle strips, cell i's point
/// indices (0-based, each a point the file has) at connectivity[offsets[i] .. offsets[i + 1]).
struct VtkLegacyMesh {
  Eigen::MatrixX3d points, normals;
  std::vector<std::int64_t> polygon_offsets{0}, polygon_connectivity;
  std::vector<std::int64_t> strip_offsets{0}, strip_connectivity;
  std::vector<double> cut_through_bone;
};
VtkLegacyMesh readVtkLegacyMesh(const std::filesystem::path& path);
/// Delimited text: .csv, .xyz, .txt.
PointCloud readTable(const std::filesystem::path& path);
/// Vertices (and point normals, if any) of .stl, .obj, .vtp meshes through VTK.
PointCloud readMeshVertices(const std::filesystem::path& path);

/// Throws InputError unless every value is finite; scales normals to unit length and throws on a
/// zero-length one. `where(i)` describes point i for the message, e.g. "line 12" or "vertex 3".
void finishCloud(PointCloud& cloud, const std::filesystem::path& path,
                 const std::function<std::string(Eigen::Index)>& where);

/// `text` in lower case (ASCII), for extensions and header names.
std::string lowercase(std::string text);

/// 'path' in quotes, for messages.
std::string quoted(const std::filesystem::path& path);

}  // namespace articula::points::detail
