#pragma once
// The project's one PLY writer: vertices with named double or uchar
// properties, optional triangles, comments (first always "SPACE=LPS", as 3D
// Slicer reads a mesh's frame, and "coordinates LPS, units mm"), ASCII or binary
// little-endian. Hand-written: a PLY header is a few lines, and VTK's writer
// would bring VTK into every module that writes points.
#include <string>
#include <vector>

#include <Eigen/Core>

namespace articula::points {

struct PlyProperty {
  std::string name;
  bool uchar = false;  // else double
};

struct PlyData {
  std::vector<std::string> comments;         // each on its own header line
  std::vector<PlyProperty> vertex_properties;
  Eigen::MatrixXd vertex_values;             // one row per vertex, one column per property
  Eigen::MatrixX3i faces;                    // triangles, 0-based; no rows: no face element
};

enum class PlyFormat { Ascii, BinaryLittleEndian };

/// The file's bytes. Doubles in ASCII have 12 significant digits (printf's
/// %.12g); uchar values are rounded and clamped to 0-255.
std::string plyText(const PlyData& data, PlyFormat format);

}  // namespace articula::points
