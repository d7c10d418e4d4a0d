#pragma once
// Point files: reading points (with optional normals) from point clouds and
// meshes, writing them back, and checking a cloud can carry a model fit.
// Coordinates are physical LPS millimetres throughout.
#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <vector>

namespace articula::points {

struct PointCloud {
  Eigen::MatrixX3d positions;  // #P x 3, LPS millimetres
  Eigen::MatrixX3d normals;    // #P x 3 unit normals, or 0 rows when the file has none
};

/// Reads points by extension (case-insensitive): .ply (ASCII and binary little/big endian, with or without
/// nx,ny,nz; any PLY scalar type, float or double), .csv / .xyz / .txt (columns x,y,z[,nx,ny,nz]; header row
/// optional and used to pick the columns when it names x,y,z; comma, semicolon, tab or space separated; blank
/// lines and lines starting with '#' skipped), and the vertices of .stl / .obj / .vtp meshes (VTK readers;
/// normals from the file or none). Normals read are scaled to unit length.
/// Throws InputError (exit code 3) with what was expected, what was found and where (file, line) for: a
/// missing or empty file, an unknown extension, a non-numeric row (give the line number), NaN or Inf (give the
/// line/index), a zero-length normal, a malformed PLY header or truncated PLY data.
PointCloud readPoints(const std::filesystem::path& path);

/// Writes .ply (binary little endian, double x,y,z and nx,ny,nz when present, with a `comment` line saying
/// "coordinates LPS, units mm" plus the caller's comment lines) or .csv (header x_mm,y_mm,z_mm[,nx,ny,nz],
/// shortest round-trip decimal values), atomically (articula::AtomicFile); `overwrite` false refuses to
/// replace an existing file (UsageError). Another extension is a UsageError.
void writePoints(const std::filesystem::path& path, const PointCloud& cloud,
                 const std::vector<std::string>& comments = {}, bool overwrite = true);

/// Checks a cloud is usable to fit a model with `min_points` parameters; throws InputError naming `where` for:
/// fewer than min_points points; NaN/Inf; all points duplicates of one; all collinear; all coplanar (relative
/// tolerance on the singular values of the centred cloud: second/largest or smallest/largest < 1e-6, loose
/// enough to catch a plane stored in single precision).
void checkFittable(const PointCloud& cloud, int min_points, const std::string& where);

}  // namespace articula::points
