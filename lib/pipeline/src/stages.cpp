#include "articula/pipeline/stages.hpp"

#include <fnmatch.h>

#include <algorithm>
#include <map>

#include <system_error>
#include <utility>

#include "articula/core/error.hpp"

namespace articula::pipeline {

namespace {

std::vector<StageDescription (*)()>& registeredStages() {
  static std::vector<StageDescription (*)()> list;
  return list;
}

}  // namespace

std::vector<StageDescription> inRunOrder(std::vector<StageDescription> listed) {
  std::map<std::string, size_t> writer;
  for (size_t i = 0; i < listed.size(); ++i) {
    for (const std::string& file : listed[i].outputs) {
      const auto [at, added] = writer.emplace(file, i);
      if (!added)
        throw ProcessingError("stages '" + listed[at->second].name + "' and '" + listed[i].name + "' both write " + file);
    }
    for (size_t j = 0; j < i; ++j)
      if (listed[j].name == listed[i].name) throw ProcessingError("two stages are named '" + listed[i].name + "'");
  }
  std::vector<std::vector<size_t>> after(listed.size());  // the stages each one waits for
  for (size_t i = 0; i < listed.size(); ++i)
    for (const std::string& file : listed[i].inputs) {
      if (file == "CT") continue;
      const auto at = writer.find(file);
      if (at == writer.end()) throw ProcessingError("stage '" + listed[i].name + "' reads " + file + ", which no stage writes");
      after[i].push_back(at->second);
    }
  std::vector<StageDescription> ordered;
  std::vector<char> placed(listed.size(), 0);
  while (ordered.size() < listed.size()) {
    size_t next = listed.size();
    for (size_t i = 0; i < listed.size() && next == listed.size(); ++i)
      if (!placed[i] && std::all_of(after[i].begin(), after[i].end(), [&placed](size_t j) { return placed[j] != 0; }))
        next = i;
    if (next == listed.size()) throw ProcessingError("the stages' inputs and outputs form a cycle");
    placed[next] = 1;
    ordered.push_back(listed[next]);
  }
  return ordered;
}

bool registerStage(StageDescription (*describe)()) {
  registeredStages().push_back(describe);
  return true;
}

const std::vector<StageDescription>& stages() {
  static const std::vector<StageDescription> table = [] {
    std::vector<StageDescription> listed = pipelineStages();
    std::vector<StageDescription> added;
    for (const auto describe : registeredStages()) added.push_back(describe());
    std::sort(added.begin(), added.end(), [](const StageDescription& a, const StageDescription& b) { return a.name < b.name; });
    listed.insert(listed.end(), added.begin(), added.end());
    return inRunOrder(std::move(listed));
  }();
  return table;
}

std::vector<StageDescription> pipelineStages() {
  // Threads and memory: what a job of the stage needs on a clinical CT
  // (512 x 512 x 400 voxels: segment, mesh and report peak at 1.1-1.2 GB,
  // the CT read as floats; sample, fit and errors at 60 MB with 4,000 points,
  // fit 670 MB with 10^6), rounded up.
  return {
      {"segment",
       "Segment the joint head from a CT (label image)",
       stageOptions("segment"),
       {"CT"},
       {"label.nii.gz"},
       {"-i", "{CT}", "-o", "{folder}/label.nii.gz", "--joint", "{joint}", "--side", "{side}"},
       {"label.nii.gz.json"},
       2, 2000},
      // The CT too: the surface moves onto its bone edge (sub-voxel).
      {"mesh",
       "Marching cubes and smoothing of the label, moved onto the CT's bone edge",
       stageOptions("mesh"),
       {"label.nii.gz", "CT"},
       {"bone.vtp"},
       {"-i", "{folder}/label.nii.gz", "-o", "{folder}/bone.vtp", "--ct", "{CT}"},
       {"bone.vtp.json"},
       2, 2000},
      {"sample",
       "Articular surface of the mesh, Gaussian-downsampled to points with normals",
       stageOptions("sample"),
       {"bone.vtp"},
       {"points.ply"},
       {"-i", "{folder}/bone.vtp", "-o", "{folder}/points.ply"},
       {"points.ply.json"},
       1, 500},
      {"fit",
       "The shape-model hierarchy fitted to the points",
       stageOptions("fit"),
       {"points.ply", "label.nii.gz"},
       {"fits.json", "fits.csv"},
       // The label for its voxel grid, which sizes the intervals' edge offset.
       {"-i", "{folder}/points.ply", "-o", "{folder}/fits.json", "--grid", "{folder}/label.nii.gz"},
       {},
       2, 1000},
      {"errors",
       "Signed Euclidean errors of every fitted model",
       stageOptions("errors"),
       {"points.ply", "fits.json"},
       {"errors/summary.json", "errors/histogram.svg", "errors/error_map.svg"},
       {"-i", "{folder}/points.ply", "--fits", "{folder}/fits.json", "-o", "{folder}/errors"},
       {"errors/summary.csv", "errors/errors.csv", "errors/points_*.ply", "errors/points_*.vtp", "errors/surface_*.ply",
        "errors/.errors-incomplete"},
       2, 1000},
      {"report",
       "Results, the selected model and the head's checks from the stage outputs",
       stageOptions("report"),
       {"fits.json", "errors/summary.json", "points.ply", "bone.vtp"},
       {"results.json", "results.csv", "head.mrk.json", "report.html", "scene.mrml"},
       {"-i", "{folder}", "--ct", "{CT}", "--joint", "{joint}", "--side", "{side}"},
       {"slicer/*.mrk.json"},
       1, 2000},
  };
}

const StageDescription& stageNamed(const std::string& name) {
  for (const auto& s : stages())
    if (s.name == name) return s;
  throw UsageError("unknown stage '" + name + "': expected one of " + stageNames());
}

std::string stageNames() {
  std::string names;
  for (const auto& s : stages()) names += (names.empty() ? "" : ", ") + s.name;
  return names;
}

std::vector<std::string> expandArguments(const StageDescription& stage, const std::string& ct, const std::string& folder,
                                         const std::string& joint, const std::string& side) {
  const std::pair<std::string, std::string> fields[] = {{"{CT}", ct}, {"{folder}", folder}, {"{joint}", joint}, {"{side}", side}};
  std::vector<std::string> out;
  for (const std::string& argument : stage.arguments) {
    // One pass: a path that itself holds "{side}" stays as it is.
    std::string expanded;
    for (size_t at = 0; at < argument.size();) {
      bool replaced = false;
      for (const auto& [key, value] : fields)
        if (argument.compare(at, key.size(), key) == 0) {
          expanded += value;
          at += key.size();
          replaced = true;
          break;
        }
      if (!replaced) expanded += argument[at++];
    }
    out.push_back(expanded);
  }
  return out;
}

bool matchesFilePattern(const std::string& pattern, const std::string& file) {
  return ::fnmatch(pattern.c_str(), file.c_str(), FNM_PATHNAME) == 0;
}

bool isStageFile(const StageDescription& stage, const std::string& file) {
  for (const auto& out : stage.outputs)
    if (out == file) return true;
  for (const auto& pattern : stage.sidecars)
    if (matchesFilePattern(pattern, file)) return true;
  return false;
}

std::vector<std::string> stageFilesIn(const StageDescription& stage, const std::filesystem::path& folder) {
  namespace fs = std::filesystem;
  std::vector<std::string> found;
  std::error_code ec;
  std::vector<fs::path> places = {folder};
  for (const auto& name : stage.outputs) places.push_back((folder / name).parent_path());
  for (const auto& name : stage.sidecars) places.push_back((folder / name).parent_path());
  std::sort(places.begin(), places.end());
  places.erase(std::unique(places.begin(), places.end()), places.end());
  for (const fs::path& place : places)
    for (auto it = fs::directory_iterator(place, ec); !ec && it != fs::directory_iterator(); it.increment(ec)) {
      const std::string name = it->path().lexically_relative(folder).generic_string();
      if (isStageFile(stage, name)) found.push_back(name);
    }
  std::sort(found.begin(), found.end());
  return found;
}

nlohmann::json stagesJson() {
  nlohmann::json list = nlohmann::json::array();
  for (const auto& s : stages()) {
    nlohmann::json options = nlohmann::json::array();
    for (const auto& option : s.options) options.push_back(option.json());
    list.push_back({{"name", s.name},
                    {"description", s.description},
                    {"options", options},
                    {"inputs", s.inputs},
                    {"outputs", s.outputs},
                    {"arguments", s.arguments},
                    {"sidecars", s.sidecars},
                    {"threads", s.threads},
                    {"memory_mb", s.memory_mb}});
  }
  return {{"stages", list}};
}

}  // namespace articula::pipeline
