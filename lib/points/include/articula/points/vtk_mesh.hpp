#pragma once
// VTK's polygon data as the project's mesh arrays, for the two modules that
// hold VTK (lib/points reads mesh files, lib/mesh makes meshes): the one
// copy of its vertices, normals and polygons into Eigen.
#include "articula/points/mesh_file.hpp"

class vtkPolyData;

namespace articula::points {

/// Vertices, point normals as the data has them (0 rows without), polygons
/// as triangles (vertices kept in their order).
MeshFile meshFromPolyData(vtkPolyData* poly);

}  // namespace articula::points
