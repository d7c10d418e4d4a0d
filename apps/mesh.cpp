// `articula-mesh`: label image -> smoothed triangle surface in LPS mm
// (VTP, STL or PLY by extension), with a JSON sidecar.
#include "articula/cli/command.hpp"
#include "articula/core/atomic_file.hpp"
#include "articula/core/error.hpp"
#include "articula/core/json_file.hpp"
#include "articula/core/output_paths.hpp"
#include "articula/core/log.hpp"
#include "articula/core/provenance.hpp"
#include "articula/imaging/io.hpp"
#include "articula/mesh/mesh.hpp"
#include "articula/pipeline/stage_options_cli.hpp"

namespace articula::apps {
namespace {

class MeshCommand : public cli::Command {
 public:
  std::string name() const override { return "mesh"; }
  bool holdsVolumes() const override { return true; }
  std::string description() const override {
    return "Mesh a label image (flying edges, Laplacian smoothing, largest surface, normals) in LPS mm";
  }
  std::string example() const override { return "articula-mesh -i head.nii.gz -o head.vtp --smooth-iterations 20"; }
  void declare(CLI::App& app) override {
    app.add_option("-i,--input", input_, "Label image (.nii.gz, .nrrd, .mha); non-zero = bone")->required();
    app.add_option("-o,--output", output_, "Mesh (.vtp, .stl or .ply)")->required();
    app.add_option("--ct", ct_,
                   "The CT the label came from (DICOM folder or image file): vertices move along their normals onto "
                   "its bone edge (sub-voxel; without it the surface is the label's smoothed voxel boundary)");
    pipeline::addStageOptions(app, name(), settings_);
  }
  int run(const cli::CommonOptions& common) override {
    const pipeline::MeshSettings& given = settings_.mesh();
    mesh::MeshOptions options = given.surface;
    mesh::EdgeSnapOptions snap = given.edges;
    imaging::limitImagingThreads(common.threadCount());
    options.smoothing = given.smoothing == "laplacian" ? mesh::Smoothing::Laplacian
                         : given.smoothing == "sinc"    ? mesh::Smoothing::WindowedSinc
                                                   : mesh::Smoothing::None;
    options.largest_component = !given.all_components;
    options.validate();
    const std::string ext = output_.extension().string();
    if (ext != ".vtp" && ext != ".stl" && ext != ".ply")
      throw UsageError("--output: expected a .vtp, .stl or .ply file, found '" + output_.string() + "'");
    cli::refuseExistingOutputs({output_, output_.string() + ".json"}, common.force);
    snap.edge_model = given.edge_model == "cortex"     ? mesh::EdgeModel::Cortex
                       : given.edge_model == "steepest" ? mesh::EdgeModel::SteepestFall
                                                   : mesh::EdgeModel::Automatic;
    snap.threads = common.threadCount();
    snap.validate();
    refuseOutputsOverInputs({output_, output_.string() + ".json"}, {input_, ct_});
    checkOutputTarget(output_);
    // articula's segmentation marks its cut through bone in the label and
    // counts those voxels in the label's sidecar; in any other label every
    // value but 0 is bone.
    const std::optional<nlohmann::json> sidecar = readJsonFileIfValid(input_.string() + ".json");
    const bool marks_its_cut = sidecar && sidecar->is_object() && sidecar->contains("cut_through_bone_voxels");
    const imaging::Label label = imaging::readLabel(input_, marks_its_cut, common.memory);
    mesh::MeshSummary s;
    mesh::TriangleMesh m = mesh::extractSurface(label, options, &s);
    nlohmann::json edges = nullptr;
    if (!ct_.empty()) {
      imaging::ReadOptions read;
      read.series_uid = given.series_uid;
      const std::shared_ptr<const imaging::Volume> ct = imaging::readSharedVolume(ct_, read, nullptr, common.memory);
      mesh::EdgeSnapSummary snapped;
      mesh::snapToEdges(m, *ct, snap, &snapped);
      const double share = snapped.vertices ? static_cast<double>(snapped.on_edge) / snapped.vertices : 0.0;
      edges = {{"ct", ct_.string()},
               {"moved", snapped.moved},
               {"vertices_on_edge", snapped.on_edge},
               {"share_on_edge", share},
               {"mean_shift_mm", snapped.mean_shift_mm},
               {"mean_abs_shift_mm", snapped.mean_abs_shift_mm},
               {"edge_model", snapped.cortex_model ? "cortex" : "steepest"},
               {"point_spread_mm", snapped.point_spread_mm},
               {"slice_point_spread_mm", snapped.slice_point_spread_mm},
               {"point_spread_estimated", snapped.point_spread_estimated},
               {"point_spread_applied", snapped.point_spread_on_voxel_grid ? "voxel_grid" : "scanner"},
               {"cortex_held_across_slices", snapped.cortex_held_across_slices},
               {"slice_thickness_mm", snapped.slice_thickness_mm},
               {"ct_noise_hu", snapped.ct_noise_hu},
               {"line_radius_mm", snapped.line_radius_mm},
               {"vertices_on_cortex_model", snapped.on_cortex_model},
               {"mean_model_shift_mm", snapped.mean_model_shift_mm}};
      if (!snapped.cortex_model_note.empty()) {
        edges["cortex_model_note"] = snapped.cortex_model_note;
        log::warn("mesh: " + snapped.cortex_model_note);
      }
      if (snapped.moved)
        log::info("mesh: " + std::to_string(snapped.on_edge) + " of " + std::to_string(snapped.vertices) +
                  " vertices on the CT's edge (mean shift " + std::to_string(snapped.mean_shift_mm) + " mm)");
      if (!snapped.moved)
        log::warn("mesh: only " + std::to_string(static_cast<int>(100 * share)) +
                  " % of the vertices found a bone edge in the CT (coarse or lossy voxels, or not the CT the label "
                  "was made from): the surface stays the label's");
    }
    mesh::writeMesh(output_, m, true);
    log::info("mesh: " + std::to_string(s.vertices) + " vertices, " + std::to_string(s.triangles) + " triangles");
    nlohmann::json params = {{"smoothing", given.smoothing}, {"smooth_iterations", options.smooth_iterations},
                             {"relaxation", options.relaxation}, {"passband", options.passband},
                             {"decimate", options.decimate}, {"largest_component", options.largest_component},
                             {"edge_search_mm", snap.search_mm}, {"edge_model", given.edge_model},
                             {"point_spread_mm", snap.point_spread_mm},
                             {"slice_point_spread_mm", snap.slice_point_spread_mm},
                             {"slice_thickness_mm", snap.slice_thickness_mm}};
    nlohmann::json summary = {{"input", input_.string()},       {"output", output_.string()},
                              {"label_voxels", s.label_voxels}, {"raw_triangles", s.raw_triangles},
                              {"triangles", s.triangles},       {"vertices", s.vertices},
                              {"ct_edges", edges},
                              {"provenance", provenanceJson({params, ct_.empty() || std::filesystem::is_directory(ct_)
                                                                          ? std::vector<std::filesystem::path>{input_}
                                                                          : std::vector<std::filesystem::path>{input_, ct_},
                                                                      -1, common.threadCount()})}};
    writeFileAtomically(output_.string() + ".json", summary.dump(2) + "\n", true);
    if (common.json) cli::printJson(summary);
    return 0;
  }

 private:
  std::filesystem::path input_, output_, ct_;
  pipeline::StageSettings settings_;
};

ARTICULA_REGISTER_COMMAND(MeshCommand)

}  // namespace
}  // namespace articula::apps
