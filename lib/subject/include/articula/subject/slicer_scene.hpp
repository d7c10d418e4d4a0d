#pragma once
// A 3D Slicer scene (scene.mrml) over a subject's files, so that one
// double-click opens them as the report shows them: the bone mesh, the
// articular points of every model with their signed distances in the
// reports' diverging colours over a symmetric range (the selected model's
// shown), the fitted surfaces (hidden) and the head's markups. Every file
// states LPS, in the file (VTP field data SPACE, PLY comment) and in the
// scene's storage nodes. Attribute names and values as Slicer 5's MRML
// readers parse them (booleans are the word "true"; a model storage node
// without coordinateSystem means RAS).
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "articula/subject/markups.hpp"

namespace articula::subject {

struct SlicerSceneContent {
  bool bone = true;                                // bone.vtp is there
  std::vector<std::string> models;                 // fitted models, in order
  std::string selected_model;                      // its points and surface shown
  std::map<std::string, double> colour_range_mm;   // per model: the colouring spans +-range
  std::vector<MarkupFile> markups;                 // in slicer/, one markup each
};

/// The scene's XML; files named relative to the subject's folder
/// (bone.vtp, errors/points_<model>.vtp, errors/surface_<model>.ply,
/// slicer/<markup>).
std::string slicerSceneXml(const SlicerSceneContent& content);

}  // namespace articula::subject
