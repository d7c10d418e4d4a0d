#include "articula/pipeline/stages.hpp"

#include "articula/core/error.hpp"

namespace articula::pipeline {

const std::vector<StageDescription>& stages() {
  static const std::vector<StageDescription> table = {
      {"segment",
       "Segment the joint head from a CT (label image)",
       {"seed-point", "series-uid", "hu-min", "hu-max", "roi", "level-set"},
       {"CT"},
       {"label.nii.gz"}},
      // The CT too: the surface moves onto its bone edge (sub-voxel).
      {"mesh",
       "Marching cubes and smoothing of the label, moved onto the CT's bone edge",
       {"series-uid", "smoothing", "smooth-iterations", "relaxation", "decimate"},
       {"label.nii.gz", "CT"},
       {"bone.vtp"}},
      {"sample",
       "Articular surface of the mesh, Gaussian-downsampled to points with normals",
       {"select", "ball-radius", "ratio"},
       {"bone.vtp"},
       {"points.ply"}},
      {"fit", "The shape-model hierarchy fitted to the points", {"models", "objective"}, {"points.ply"},
       {"fits.json", "fits.csv"}},
      {"errors",
       "Signed Euclidean errors of every fitted model",
       {},
       {"points.ply", "fits.json"},
       {"errors/summary.json", "errors/histogram.svg", "errors/error_map.svg"}},
      {"report",
       "Results, the selected model and the head's checks from the stage outputs",
       {"selection-tolerance", "selection-floor"},
       {"fits.json", "errors/summary.json", "points.ply"},
       {"results.json", "results.csv", "head.mrk.json"}},
  };
  return table;
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

nlohmann::json stagesJson() {
  nlohmann::json list = nlohmann::json::array();
  for (const auto& s : stages())
    list.push_back({{"name", s.name},
                    {"description", s.description},
                    {"options", s.options},
                    {"inputs", s.inputs},
                    {"outputs", s.outputs}});
  return {{"stages", list}};
}

}  // namespace articula::pipeline
