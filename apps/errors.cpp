// `articula errors` / articula-errors: signed Euclidean distances from the
// points to every fitted model (fits.json), with thesis tables 3.3-3.4
// (summary.csv/.json), per-point errors.csv, the histograms of fig. 3.5
// (histogram.svg), points coloured as fig. 3.4 (PLY, and flat maps in
// error_map.svg) and each fitted surface (PLY).
#include <cmath>
#include <iomanip>
#include <sstream>

#include <Eigen/Geometry>

#include "articula/cli/command.hpp"
#include "articula/core/json_file.hpp"
#include "articula/core/atomic_file.hpp"
#include "articula/core/error.hpp"
#include "articula/core/output_paths.hpp"
#include "articula/core/log.hpp"
#include "articula/core/provenance.hpp"
#include "articula/distance/signed_distance.hpp"
#include "articula/fit/fits_json.hpp"
#include "articula/geometry/surface.hpp"
#include "articula/points/point_io.hpp"
#include "articula/report/error_map_svg.hpp"
#include "articula/report/error_statistics.hpp"
#include "articula/report/histogram_svg.hpp"
#include "articula/mesh/mesh.hpp"
#include "articula/pipeline/stage_options_cli.hpp"
#include "articula/report/ply_writers.hpp"

namespace articula::apps {
namespace {

// The fitted surface over the points' angular extent: the triangles of an
// exact sample whose vertices all lie within the largest angle, seen from the
// shape's centre, between the points and their mean direction (plus 5 degrees).
geometry::SurfaceMesh surfacePatch(const geometry::PosedSurface& s, const Eigen::MatrixX3d& points, int resolution) {
  const geometry::SurfaceMesh full = s.sample(resolution, resolution / 2);
  const Eigen::Vector3d c = s.pose().translation;
  Eigen::Vector3d axis = Eigen::Vector3d::Zero();
  for (Eigen::Index i = 0; i < points.rows(); ++i) axis += (points.row(i).transpose() - c).normalized();
  if (axis.norm() < 1e-9 * static_cast<double>(points.rows())) return full;  // points all round: whole surface
  axis.normalize();
  double max_angle = 0.0;
  for (Eigen::Index i = 0; i < points.rows(); ++i)
    max_angle = std::max(max_angle, std::acos(std::clamp(axis.dot((points.row(i).transpose() - c).normalized()), -1.0, 1.0)));
  const double limit = std::cos(std::min(M_PI, max_angle + 5.0 * M_PI / 180.0));
  std::vector<int> keep_vertex(static_cast<size_t>(full.vertices.rows()), -1);
  std::vector<Eigen::Vector3i> tris;
  for (Eigen::Index f = 0; f < full.triangles.rows(); ++f) {
    bool inside = true;
    for (int k = 0; k < 3; ++k)
      inside = inside && axis.dot((full.vertices.row(full.triangles(f, k)).transpose() - c).normalized()) >= limit;
    if (inside) tris.emplace_back(full.triangles.row(f).transpose());
  }
  geometry::SurfaceMesh patch;
  std::vector<Eigen::Vector3d> verts;
  patch.triangles.resize(static_cast<Eigen::Index>(tris.size()), 3);
  for (size_t t = 0; t < tris.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      int& id = keep_vertex[static_cast<size_t>(tris[t][k])];
      if (id < 0) {
        id = static_cast<int>(verts.size());
        verts.emplace_back(full.vertices.row(tris[t][k]).transpose());
      }
      patch.triangles(static_cast<Eigen::Index>(t), k) = id;
    }
  patch.vertices.resize(static_cast<Eigen::Index>(verts.size()), 3);
  for (size_t v = 0; v < verts.size(); ++v) patch.vertices.row(static_cast<Eigen::Index>(v)) = verts[v].transpose();
  return patch;
}

class ErrorsCommand : public cli::Command {
 public:
  std::string name() const override { return "errors"; }
  std::string description() const override {
    return "Signed Euclidean distances to the fitted models: tables 3.3-3.4, errors.csv, histogram.svg, error_map.svg, "
           "coloured PLY";
  }
  std::string example() const override { return "articula-errors -i head.ply --fits fits.json -o errors/"; }
  void declare(CLI::App& app) override {
    app.add_option("-i,--input", input_, "The points that were fitted (LPS mm)")->required();
    app.add_option("--fits", fits_, "fits.json written by articula-fit")->required();
    app.add_option("-o,--output", output_, "Output folder")->required();
    pipeline::addStageOptions(app, name(), settings_);
  }

  int run(const cli::CommonOptions& common) override {
    const pipeline::ErrorsSettings& given = settings_.errors();
    const points::PointCloud cloud = points::readPoints(input_);
    points::checkFittable(cloud, 1, input_.string());
    const nlohmann::json doc = readJsonFile(fits_, "--fits");
    const std::vector<geometry::ShapeParameters> shapes = fit::shapesFromFitsJson(doc, fits_.string());
    if (std::filesystem::exists(output_) && !std::filesystem::is_directory(output_))
      throw UsageError("--output: expected a folder, found the file '" + output_.string() + "'");
    // Every file this stage writes, checked before any is: none an input, none left over without --force.
    std::vector<std::filesystem::path> outputs;
    for (const char* f : {"summary.csv", "summary.json", "errors.csv", "histogram.svg", "error_map.svg"})
      outputs.push_back(output_ / f);
    for (const auto& shape : shapes)
      for (const char* kind : {"points_", "surface_"})
        outputs.push_back(output_ / (kind + geometry::modelName(shape.model) + ".ply"));
    for (const auto& shape : shapes) outputs.push_back(output_ / ("points_" + geometry::modelName(shape.model) + ".vtp"));
    refuseOutputsOverInputs(outputs, {input_, fits_});
    // An interrupted run of this stage left its marker (removed once
    // summary.json, written last, is in place): its files are redone
    // without --force. Any other existing output needs --force.
    const std::filesystem::path marker = output_ / ".errors-incomplete";
    const bool interrupted = std::filesystem::exists(marker);
    for (const auto& f : outputs)
      if (!interrupted && std::filesystem::exists(f) && !common.force)
        throw UsageError("output '" + f.string() + "' exists (use --force to overwrite)");
    if (std::filesystem::is_directory(output_)) removeStaleTemporaries(output_);
    const bool overwrite = common.force || interrupted;
    std::error_code ec;
    std::filesystem::create_directories(output_, ec);
    if (ec) throw InputError("--output: cannot create the folder '" + output_.string() + "': " + ec.message());
    writeFileAtomically(marker, "articula errors: writing; this folder is incomplete until summary.json is written\n", true);

    const Eigen::MatrixX3d& P = cloud.positions;
    std::vector<report::ErrorStatistics> rows;
    std::vector<report::Series> series;
    Eigen::MatrixXd all(P.rows(), static_cast<Eigen::Index>(shapes.size()));
    Eigen::MatrixX3d feet;  // each model's closest points: guesses for the next (exact all the same)
    for (size_t m = 0; m < shapes.size(); ++m) {
      const std::string name = geometry::modelName(shapes[m].model);
      Eigen::VectorXd d;
      distance::SignedDistance(shapes[m], common.threadCount()).evaluate(P, d, feet, distance::SignedDistance::Start::WarmExact);
      all.col(static_cast<Eigen::Index>(m)) = d;
      rows.push_back(report::errorStatistics(name, d));
      series.push_back({name, d, rows.back().gauss_mu_mm, rows.back().gauss_sigma_mm});
      log::info(name + ": rms " + std::to_string(rows.back().rms_mm) + " mm");
      const std::string comment = "articula errors: " + name + " signed Euclidean distances (mm), points " +
                                  input_.filename().string();
      writeFileAtomically(output_ / ("points_" + name + ".ply"),
                          report::colouredPointsPly(P, d, given.band_mm, comment), overwrite);
      mesh::writePointValues(output_ / ("points_" + name + ".vtp"), P, "signed_distance_mm", d, overwrite);
      const auto surface = geometry::makeSurface(shapes[m]);
      const geometry::SurfaceMesh patch = surfacePatch(*surface, P, given.resolution);
      writeFileAtomically(output_ / ("surface_" + name + ".ply"),
                          report::meshPly(patch.vertices, patch.triangles, "articula fitted " + name), overwrite);
    }

    nlohmann::json params = {{"fits", fits_.string()}, {"band_mm", given.band_mm}, {"resolution", given.resolution}};
    const nlohmann::json provenance = provenanceJson({params, {input_, fits_}, -1, common.threadCount()});
    writeFileAtomically(output_ / "summary.csv", report::summaryCsv(rows), overwrite);
    std::vector<std::string> model_names;
    for (const auto& shape : shapes) model_names.push_back(geometry::modelName(shape.model));
    report::writeErrorsCsv(output_ / "errors.csv", P, model_names, all, overwrite);
    writeFileAtomically(output_ / "histogram.svg",
                        report::histogramSvg(series, "Signed Euclidean distances of the points to each model"),
                        overwrite);
    // Maps about the least-RMS model's centre (fits.json's least_rms_model, or
    // best_model in files before it, else the least RMS here).
    const std::string key = doc.contains("least_rms_model") ? "least_rms_model" : "best_model";
    size_t best = 0;
    for (size_t m = 0; m < shapes.size(); ++m)
      if (doc.contains(key) ? geometry::modelName(shapes[m].model) == doc[key] : rows[m].rms_mm < rows[best].rms_mm)
        best = m;
    std::vector<report::ErrorMapPanel> panels;
    for (size_t m = 0; m < shapes.size(); ++m) panels.push_back({rows[m].model, all.col(static_cast<Eigen::Index>(m))});
    report::ErrorMapOptions map_options;
    map_options.max_points = given.map_points;
    map_options.highlight = rows[best].model;
    writeFileAtomically(output_ / "error_map.svg",
                        report::errorMapSvg(report::azimuthalEqualArea(P, shapes[best].center), panels, map_options,
                                            "Signed distances to the fitted surfaces"),
                        overwrite);
    // Last: summary.json, then the marker goes: the folder is complete.
    writeFileAtomically(output_ / "summary.json",
                        nlohmann::json({{"coordinate_system", "LPS"},
                                        {"units", "mm"},
                                        {"models", report::summaryJson(rows)},
                                        {"provenance", provenance}})
                                .dump(2) +
                            "\n",
                        true);
    std::filesystem::remove(marker);
    if (common.json) cli::printJson({{"output", output_.string()}, {"models", report::summaryJson(rows)}});
    return 0;
  }

 private:
  std::filesystem::path input_, fits_, output_;
  pipeline::StageSettings settings_;
};

ARTICULA_REGISTER_COMMAND(ErrorsCommand)

}  // namespace
}  // namespace articula::apps
