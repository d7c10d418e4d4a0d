#pragma once
// The report's 3-D view of a subject (report/web_3d_view.hpp) from its
// folder: the bone mesh near the head (bone.vtp), the articular points with
// their signed distances to every model (errors/errors.csv) and the fitted
// surfaces (errors/surface_<model>.ply).
#include <filesystem>
#include <string>
#include <vector>

#include "articula/geometry/shape.hpp"

namespace articula::pipeline {

/// The view's section, turning about the selected model's centre, or a note
/// why there is none (a stage output missing or unreadable): the view
/// shows, it decides nothing.
std::string headViewHtml(const std::filesystem::path& folder, const std::vector<geometry::ShapeParameters>& shapes,
                         const std::string& selected_model);

}  // namespace articula::pipeline
