#pragma once
// The report's 3-D view of a subject (report/web_3d_view.hpp) from its
// folder: the bone mesh near the head (bone.vtp), the articular points with
// their signed distances to every model (errors/errors.csv) and the fitted
// surfaces (errors/surface_<model>.ply).
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "articula/geometry/shape.hpp"
#include "articula/points/mesh_file.hpp"
#include "articula/report/web_3d_view.hpp"

namespace articula::subject {

/// The triangles of `mesh` that `keep` (given a triangle's row) keeps, with
/// their vertices re-indexed: a part of the bone for the view.
report::ViewSurface meshPart(const points::MeshFile& mesh, const std::string& name,
                             const std::function<bool(Eigen::Index)>& keep);

/// The view, turning about the selected model's centre. Throws InputError
/// when errors/errors.csv is missing or unreadable (bone.vtp and the
/// surfaces are shown when they are there).
report::View3d loadHeadView(const std::filesystem::path& folder, const std::vector<geometry::ShapeParameters>& shapes,
                            const std::string& selected_model);

}  // namespace articula::subject
