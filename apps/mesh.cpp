// `articula-mesh`: label image -> smoothed triangle surface in LPS mm
// (VTP, STL or PLY by extension), with a JSON sidecar.
#include "articula/cli/command.hpp"
#include "articula/core/atomic_file.hpp"
#include "articula/core/error.hpp"
#include "articula/core/output_paths.hpp"
#include "articula/core/log.hpp"
#include "articula/core/provenance.hpp"
#include "articula/imaging/io.hpp"
#include "articula/mesh/mesh.hpp"

namespace articula::apps {
namespace {

class MeshCommand : public cli::Command {
 public:
  std::string name() const override { return "mesh"; }
  std::string description() const override {
    return "Mesh a label image (flying edges, Laplacian smoothing, largest surface, normals) in LPS mm";
  }
  std::string example() const override { return "articula-mesh -i head.nii.gz -o head.vtp --smooth-iterations 20"; }
  void declare(CLI::App& app) override {
    app.add_option("-i,--input", input_, "Label image (.nii.gz, .nrrd, .mha); non-zero = bone")->required();
    app.add_option("-o,--output", output_, "Mesh (.vtp, .stl or .ply)")->required();
    app.add_option("--smoothing", smoothing_, "laplacian, sinc (windowed sinc) or none")
        ->check(CLI::IsMember({"laplacian", "sinc", "none"}))->capture_default_str();
    app.add_option("--smooth-iterations", options_.smooth_iterations, "Smoothing iterations")->capture_default_str();
    app.add_option("--relaxation", options_.relaxation, "Laplacian relaxation factor")->capture_default_str();
    app.add_option("--passband", options_.passband, "Windowed sinc pass band")->capture_default_str();
    app.add_option("--decimate", options_.decimate, "Fraction of triangles to remove (0 = none)")->capture_default_str();
    app.add_flag("--all-components", all_components_, "Keep every connected surface, not only the largest");
    app.add_option("--ct", ct_,
                   "The CT the label came from (DICOM folder or image file): vertices move along their normals onto "
                   "its bone edge (sub-voxel; without it the surface is the label's smoothed voxel boundary)");
    app.add_option("--series-uid", series_uid_, "With --ct: the DICOM series to read when the folder holds several (empty: the series whose UID is empty)");
    app.add_option("--edge-search", snap_.search_mm,
                   "With --ct: edge search either side of a vertex, mm (0: 1.5 voxels, at least 1.5 mm)")
        ->check(CLI::Range(0.0, 10.0))
        ->capture_default_str();
    app.add_option("--edge-model", edge_model_,
                   "With --ct: 'steepest' puts each edge on the steepest HU fall (a cortex thinner than about three "
                   "point-spreads pulls it outwards); 'cortex' on the outer surface of a blurred-cortex model fitted to "
                   "the voxels about the normal, with one point-spread for the CT; 'auto' the cortex model on CTs "
                   "whose voxels are at most 1 mm within the slices and 3 mm across them, the steepest fall beyond")
        ->check(CLI::IsMember({"auto", "cortex", "steepest"}))
        ->capture_default_str();
    app.add_option("--point-spread", snap_.point_spread_mm,
                   "With --ct and the cortex model: the scanner's Gaussian point-spread (standard deviation) within "
                   "the slices, mm (0: this and the slices' estimated from the CT's edges)")
        ->check(CLI::Range(0.0, 3.0))
        ->capture_default_str();
    app.add_option("--slice-point-spread", snap_.slice_point_spread_mm,
                   "With --point-spread: the point-spread across the slices (the slice profile's standard deviation), "
                   "mm (0: as within the slices)")
        ->check(CLI::Range(0.0, 3.0))
        ->capture_default_str();
  }
  int run(const cli::CommonOptions& common) override {
    imaging::limitImagingThreads(common.threadCount());
    options_.smoothing = smoothing_ == "laplacian" ? mesh::Smoothing::Laplacian
                         : smoothing_ == "sinc"    ? mesh::Smoothing::WindowedSinc
                                                   : mesh::Smoothing::None;
    options_.largest_component = !all_components_;
    options_.validate();
    const std::string ext = output_.extension().string();
    if (ext != ".vtp" && ext != ".stl" && ext != ".ply")
      throw UsageError("--output: expected a .vtp, .stl or .ply file, found '" + output_.string() + "'");
    cli::refuseExistingOutputs({output_, output_.string() + ".json"}, common.force);
    snap_.edge_model = edge_model_ == "cortex"     ? mesh::EdgeModel::Cortex
                       : edge_model_ == "steepest" ? mesh::EdgeModel::SteepestFall
                                                   : mesh::EdgeModel::Automatic;
    snap_.validate();
    refuseOutputsOverInputs({output_, output_.string() + ".json"}, {input_, ct_});
    checkOutputTarget(output_);
    const imaging::Label label = imaging::readLabel(input_);
    mesh::MeshSummary s;
    mesh::TriangleMesh m = mesh::extractSurface(label, options_, &s);
    nlohmann::json edges = nullptr;
    if (!ct_.empty()) {
      imaging::ReadOptions read;
      read.series_uid = series_uid_;
      const std::shared_ptr<const imaging::Volume> ct = imaging::readSharedVolume(ct_, read);
      mesh::EdgeSnapSummary snapped;
      mesh::snapToEdges(m, *ct, snap_, &snapped);
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
    nlohmann::json params = {{"smoothing", smoothing_}, {"smooth_iterations", options_.smooth_iterations},
                             {"relaxation", options_.relaxation}, {"passband", options_.passband},
                             {"decimate", options_.decimate}, {"largest_component", options_.largest_component},
                             {"edge_search_mm", snap_.search_mm}, {"edge_model", edge_model_},
                             {"point_spread_mm", snap_.point_spread_mm},
                             {"slice_point_spread_mm", snap_.slice_point_spread_mm}};
    nlohmann::json summary = {{"input", input_.string()},       {"output", output_.string()},
                              {"label_voxels", s.label_voxels}, {"raw_triangles", s.raw_triangles},
                              {"triangles", s.triangles},       {"vertices", s.vertices},
                              {"ct_edges", edges},
                              {"provenance", provenanceJson({params, ct_.empty() || std::filesystem::is_directory(ct_)
                                                                          ? std::vector<std::filesystem::path>{input_}
                                                                          : std::vector<std::filesystem::path>{input_, ct_},
                                                                      -1})}};
    writeFileAtomically(output_.string() + ".json", summary.dump(2) + "\n", true);
    if (common.json) cli::printJson(summary);
    return 0;
  }

 private:
  std::filesystem::path input_, output_, ct_;
  std::string smoothing_ = "laplacian", series_uid_, edge_model_ = "auto";
  mesh::EdgeSnapOptions snap_;
  bool all_components_ = false;
  mesh::MeshOptions options_;
};

ARTICULA_REGISTER_COMMAND(MeshCommand)

}  // namespace
}  // namespace articula::apps
