#pragma once
// 3D Slicer markups (.mrk.json, schema v1.0.3): the head centre as a point
// list and the fitted axes as lines, in LPS millimetres.
#include <filesystem>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace articula::subject {

struct Landmark {
  std::string label;
  Eigen::Vector3d position;  // LPS mm
};
struct LandmarkLine {
  std::string label;
  Eigen::Vector3d start, end;  // LPS mm
};

struct MarkupFile {
  std::string name, file_name;
  bool is_line = false;  // a line, else a point list
};

/// Writes one markups file holding a point list named `name` with the
/// landmarks and one line markup per axis; atomically.
void writeSlicerMarkups(const std::filesystem::path& path, const std::string& name,
                        const std::vector<Landmark>& points, const std::vector<LandmarkLine>& lines);

/// The same markups one per file in `folder` (points.mrk.json, then
/// <line label>.mrk.json), as a scene needs them: Slicer reads one markup of a
/// file into each scene node.
std::vector<MarkupFile> writeSlicerMarkupsPerNode(const std::filesystem::path& folder, const std::string& name,
                                                  const std::vector<Landmark>& points,
                                                  const std::vector<LandmarkLine>& lines);

}  // namespace articula::subject
