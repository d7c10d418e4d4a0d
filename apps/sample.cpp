// `articula-sample`: bone mesh -> articular points (LPS mm, with normals):
// the articular region (RANSAC sphere, or by hand), then the thesis's
// Gaussian open-ball down-sampling; counts as in thesis table 3.1.
#include <sstream>

#include "articula/cli/command.hpp"
#include "articula/core/atomic_file.hpp"
#include "articula/core/error.hpp"
#include "articula/core/output_paths.hpp"
#include "articula/core/log.hpp"
#include "articula/core/provenance.hpp"
#include "articula/mesh/mesh.hpp"
#include "articula/pipeline/stage_options_cli.hpp"
#include "articula/points/point_io.hpp"
#include "articula/sampling/downsample.hpp"
#include "articula/sampling/select.hpp"

namespace articula::apps {
namespace {

class SampleCommand : public cli::Command {
 public:
  std::string name() const override { return "sample"; }
  std::string description() const override {
    return "Select the articular surface of a bone mesh and Gaussian-downsample it to points with normals";
  }
  std::string example() const override {
    return "articula-sample -i head.vtp -o points.ply --select auto --ball-radius 1.0 --seed 42";
  }
  void declare(CLI::App& app) override {
    app.add_option("-i,--input", input_, "Mesh (.vtp, .stl, .ply, .vtk, .obj) in LPS mm")->required();
    app.add_option("-o,--output", output_, "Points (.ply, or .csv)")->required();
    pipeline::addStageOptions(app, name(), settings_);
    app.add_option("--format", format_, "ply or csv (default: from the extension)")->check(CLI::IsMember({"ply", "csv"}));
  }
  int run(const cli::CommonOptions& common) override {
    const pipeline::SampleSettings& given = settings_.sample();
    sampling::SelectOptions select_options = given.selection;
    sampling::DownsampleOptions down = given.downsampling;
    sampling::parseSelection(given.select, select_options);
    if (common.seed < 0) throw UsageError("--seed: expected a non-negative integer");
    select_options.seed = down.seed = static_cast<unsigned long long>(common.seed);
    down.validate();
    if (!format_.empty()) output_.replace_extension(format_);
    const std::string ext = output_.extension().string();
    if (ext != ".ply" && ext != ".csv") throw UsageError("--output: expected a .ply or .csv file, found '" + output_.string() + "'");
    refuseOutputsOverInputs({output_, output_.string() + ".json"}, {input_});
    checkOutputTarget(output_);
    cli::refuseExistingOutputs({output_, output_.string() + ".json"}, common.force);

    const mesh::TriangleMesh m = mesh::readMesh(input_);
    const sampling::Selection sel = sampling::selectArticular(m.vertices, m.normals, m.triangles, select_options, m.cut_through_bone);
    nlohmann::json warnings = nlohmann::json::array();
    if (sel.cut_through_bone_kept > 0) {
      warnings.push_back(std::to_string(sel.cut_through_bone_kept) + " of " + std::to_string(sel.indices.size()) +
                         " articular vertices lie where the label ends inside bone (no edge in the CT), and "
                         "without them fewer than " + std::to_string(select_options.min_points) +
                         " would remain: all are kept, and the cut where the head was cut from its neck may be among them");
      log::warn("sample: " + warnings.back().get<std::string>());
    }
    // A count of the mesh's marks, null for a mesh without them.
    const auto marked = [&m](int count) { return m.cut_through_bone.empty() ? nlohmann::json(nullptr) : nlohmann::json(count); };
    Eigen::MatrixX3d P(static_cast<Eigen::Index>(sel.indices.size()), 3), Nsel(P.rows(), 3);
    for (size_t i = 0; i < sel.indices.size(); ++i) {
      P.row(static_cast<Eigen::Index>(i)) = m.vertices.row(sel.indices[i]);
      if (m.normals.rows() == m.vertices.rows()) Nsel.row(static_cast<Eigen::Index>(i)) = m.normals.row(sel.indices[i]);
    }
    sampling::DownsampleSummary ds;
    const std::vector<int> kept = sampling::gaussianDownsample(P, down, &ds);
    if (static_cast<int>(kept.size()) < select_options.min_points)
      throw ProcessingError("down-sampling left " + std::to_string(kept.size()) + " articular points; expected at least " +
                       std::to_string(select_options.min_points) + " (reduce --ball-radius)");
    points::PointCloud cloud;
    cloud.positions.resize(static_cast<Eigen::Index>(kept.size()), 3);
    if (m.normals.rows() == m.vertices.rows()) cloud.normals.resize(cloud.positions.rows(), 3);
    for (size_t i = 0; i < kept.size(); ++i) {
      cloud.positions.row(static_cast<Eigen::Index>(i)) = P.row(kept[i]);
      if (cloud.normals.rows()) cloud.normals.row(static_cast<Eigen::Index>(i)) = Nsel.row(kept[i]);
    }
    std::ostringstream note;
    note << "articula sample: " << ds.original << " selected, " << ds.reduced << " kept, open ball " << down.ball_radius_mm
         << " mm, seed " << common.seed;
    points::writePoints(output_, cloud, {note.str()}, true);
    log::info("sample: " + note.str().substr(std::string("articula sample: ").size()) + " (" + ds.termination + ")");

    nlohmann::json params = {{"select", given.select},
                             {"ball_radius_mm", down.ball_radius_mm},
                             {"ratio", down.ratio},
                             {"min_radius_mm", select_options.min_radius_mm},
                             {"max_radius_mm", select_options.max_radius_mm},
                             {"band_mm", select_options.band_mm}};
    nlohmann::json summary = {
        {"input", input_.string()},
        {"output", output_.string()},
        {"mesh_vertices", m.vertices.rows()},
        {"selected_points", ds.original},
        {"duplicates_removed", ds.duplicates},
        {"outliers_removed", ds.outliers},
        {"reduced_points", ds.reduced},
        {"percentage", ds.original ? 100.0 * static_cast<double>(ds.reduced) / static_cast<double>(ds.original) : 0.0},
        {"termination", ds.termination},
        {"cut_through_bone_left_out", marked(sel.cut_through_bone_left_out)},
        {"cut_through_bone_kept", marked(sel.cut_through_bone_kept)},
        {"warnings", warnings},
        {"provenance", provenanceJson({params, {input_}, common.seed})}};
    if (select_options.mode == sampling::SelectOptions::Mode::Auto)
      summary["sphere"] = {{"center_mm", {sel.sphere_center[0], sel.sphere_center[1], sel.sphere_center[2]}},
                           {"radius_mm", sel.sphere_radius},
                           {"rms_mm", sel.sphere_rms_mm},
                           {"ransac_spheres_in_range", sel.ransac_spheres},
                           {"concave_vertices_left_out", sel.concave_left_out}};
    writeFileAtomically(output_.string() + ".json", summary.dump(2) + "\n", true);
    if (common.json) cli::printJson(summary);
    return 0;
  }

 private:
  std::filesystem::path input_, output_;
  std::string format_;
  pipeline::StageSettings settings_;
};

ARTICULA_REGISTER_COMMAND(SampleCommand)

}  // namespace
}  // namespace articula::apps
