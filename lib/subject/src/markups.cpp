#include "articula/subject/markups.hpp"

#include <nlohmann/json.hpp>

#include "articula/core/atomic_file.hpp"

namespace articula::subject {

namespace {
nlohmann::json point(const std::string& id, const std::string& label, const Eigen::Vector3d& p) {
  return {{"id", id}, {"label", label}, {"position", {p[0], p[1], p[2]}}, {"positionStatus", "defined"}};
}
nlohmann::json markup(const std::string& type, const std::string& name, nlohmann::json control_points) {
  return {{"type", type},
          {"name", name},
          {"coordinateSystem", "LPS"},
          {"coordinateUnits", "mm"},
          {"locked", true},
          {"controlPoints", std::move(control_points)}};
}

// The @schema Slicer 5.0 and later accept (5.0 matches this spelling exactly).
void writeMarkupsDocument(const std::filesystem::path& path, nlohmann::json markups) {
  const nlohmann::json doc = {
      {"@schema",
       "https://raw.githubusercontent.com/slicer/slicer/master/Modules/Loadable/Markups/Resources/Schema/"
       "markups-schema-v1.0.3.json#"},
      {"markups", std::move(markups)}};
  writeFileAtomically(path, doc.dump(2) + "\n");
}

nlohmann::json pointList(const std::string& name, const std::vector<Landmark>& points) {
  nlohmann::json cps = nlohmann::json::array();
  for (size_t i = 0; i < points.size(); ++i) cps.push_back(point(std::to_string(i + 1), points[i].label, points[i].position));
  return markup("Fiducial", name, cps);
}

nlohmann::json lineMarkup(const LandmarkLine& line) {
  return markup("Line", line.label, {point("1", line.label + "_start", line.start), point("2", line.label + "_end", line.end)});
}

}  // namespace

void writeSlicerMarkups(const std::filesystem::path& path, const std::string& name,
                        const std::vector<Landmark>& points, const std::vector<LandmarkLine>& lines) {
  nlohmann::json markups = nlohmann::json::array({pointList(name, points)});
  for (const auto& line : lines) markups.push_back(lineMarkup(line));
  writeMarkupsDocument(path, markups);
}

std::vector<MarkupFile> writeSlicerMarkupsPerNode(const std::filesystem::path& folder, const std::string& name,
                                                  const std::vector<Landmark>& points,
                                                  const std::vector<LandmarkLine>& lines) {
  std::filesystem::create_directories(folder);
  std::vector<MarkupFile> files = {{name, "points.mrk.json", false}};
  writeMarkupsDocument(folder / files.back().file_name, nlohmann::json::array({pointList(name, points)}));
  for (const auto& line : lines) {
    files.push_back({line.label, line.label + ".mrk.json", true});
    writeMarkupsDocument(folder / files.back().file_name, nlohmann::json::array({lineMarkup(line)}));
  }
  return files;
}

}  // namespace articula::subject
