#include "articula/subject/head_view.hpp"

#include <vector>

#include "articula/core/csv.hpp"
#include "articula/core/error.hpp"
#include "articula/points/mesh_file.hpp"

namespace articula::subject {
namespace {

namespace fs = std::filesystem;

// The triangles with a corner within `radius` of `centre`: the head and the
// start of its neck, not a whole femur, keep the page small.
report::ViewSurface boneNear(const points::MeshFile& mesh, const Eigen::Vector3d& centre, double radius) {
  return meshPart(mesh, "bone", [&](Eigen::Index f) {
    bool near = false;
    for (int k = 0; k < 3; ++k) near = near || (mesh.vertices.row(mesh.triangles(f, k)).transpose() - centre).norm() <= radius;
    return near;
  });
}

double cell(const CsvTable& table, size_t row, int column, const fs::path& path) {
  try {
    return std::stod(table.rows[row].at(static_cast<size_t>(column)));
  } catch (const std::exception&) {
    throw InputError("'" + path.string() + "' line " + std::to_string(table.row_lines[row]) + ": not a number");
  }
}

}  // namespace

report::ViewSurface meshPart(const points::MeshFile& mesh, const std::string& name,
                             const std::function<bool(Eigen::Index)>& keep) {
  std::vector<int> new_index(static_cast<size_t>(mesh.vertices.rows()), -1);
  std::vector<Eigen::Vector3i> kept;
  int n_vertices = 0;
  for (Eigen::Index f = 0; f < mesh.triangles.rows(); ++f) {
    if (!keep(f)) continue;
    Eigen::Vector3i t;
    for (int k = 0; k < 3; ++k) {
      int& index = new_index[static_cast<size_t>(mesh.triangles(f, k))];
      if (index < 0) index = n_vertices++;
      t[k] = index;
    }
    kept.push_back(t);
  }
  report::ViewSurface part{name, Eigen::MatrixX3d(n_vertices, 3), Eigen::MatrixX3i(static_cast<Eigen::Index>(kept.size()), 3)};
  for (size_t v = 0; v < new_index.size(); ++v)
    if (new_index[v] >= 0) part.vertices.row(new_index[v]) = mesh.vertices.row(static_cast<Eigen::Index>(v));
  for (size_t f = 0; f < kept.size(); ++f) part.triangles.row(static_cast<Eigen::Index>(f)) = kept[f].transpose();
  return part;
}

report::View3d loadHeadView(const fs::path& folder, const std::vector<geometry::ShapeParameters>& shapes,
                            const std::string& selected_model) {
  report::View3d view;
  view.selected_model = selected_model;
  for (const auto& shape : shapes)
    if (geometry::modelName(shape.model) == selected_model) {
      view.centre = shape.center;
      view.radius_mm = shape.radii.maxCoeff();
    }
  if (fs::exists(folder / "bone.vtp"))
    view.bone = boneNear(points::readMeshFile(folder / "bone.vtp"), view.centre, 2.5 * view.radius_mm);

  const fs::path errors_csv = folder / "errors" / "errors.csv";
  if (!fs::exists(errors_csv)) throw InputError("'" + errors_csv.string() + "' is missing");
  const CsvTable table = readCsv(errors_csv);
  const int x = table.column("x_mm"), y = table.column("y_mm"), z = table.column("z_mm");
  if (x < 0 || y < 0 || z < 0) throw InputError("'" + errors_csv.string() + "' has no x_mm, y_mm, z_mm columns");
  const auto n = static_cast<Eigen::Index>(table.rows.size());
  view.points.resize(n, 3);
  for (Eigen::Index i = 0; i < n; ++i)
    view.points.row(i) << cell(table, static_cast<size_t>(i), x, errors_csv), cell(table, static_cast<size_t>(i), y, errors_csv),
        cell(table, static_cast<size_t>(i), z, errors_csv);
  for (const auto& shape : shapes) {
    const std::string model = geometry::modelName(shape.model);
    const int column = table.column("d_" + model + "_mm");
    if (column >= 0) {
      report::ViewModelDistances d{model, Eigen::VectorXd(n)};
      for (Eigen::Index i = 0; i < n; ++i) d.signed_distance_mm[i] = cell(table, static_cast<size_t>(i), column, errors_csv);
      view.distances.push_back(std::move(d));
    }
    const fs::path surface = folder / "errors" / ("surface_" + model + ".ply");
    if (fs::exists(surface)) {
      const points::MeshFile m = points::readMeshFile(surface);
      view.fitted.push_back({model, m.vertices, m.triangles});
    }
  }
  return view;
}

}  // namespace articula::subject
