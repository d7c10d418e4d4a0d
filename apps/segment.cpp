// `articula-segment`: CT (DICOM folder or NIfTI/NRRD/MHA) -> uint8 label of
// one joint head in the input's physical space, with a JSON sidecar.
#include <sstream>

#include "articula/cli/command.hpp"
#include "articula/core/atomic_file.hpp"
#include "articula/core/error.hpp"
#include "articula/core/output_paths.hpp"
#include "articula/core/log.hpp"
#include "articula/core/provenance.hpp"
#include "articula/imaging/io.hpp"
#include "articula/imaging/label_mask.hpp"
#include "articula/imaging/segment.hpp"
#include "articula/pipeline/stage_options_cli.hpp"

namespace articula::apps {
namespace {

nlohmann::json vec(const Eigen::Vector3d& v) { return {v[0], v[1], v[2]}; }

class SegmentCommand : public cli::Command {
 public:
  std::string name() const override { return "segment"; }
  bool holdsVolumes() const override { return true; }
  std::string description() const override {
    return "Segment a femoral or humeral head from CT (DICOM folder, NIfTI, NRRD, MHA) into a uint8 label";
  }
  std::string example() const override {
    return "articula-segment -i ct/ -o head.nii.gz --joint hip --side right";
  }
  void declare(CLI::App& app) override {
    app.add_option("-i,--input", input_, "DICOM folder or .nii/.nii.gz/.nrrd/.mha file")->required();
    app.add_option("-o,--output", output_, "Label image (.nii.gz, .nrrd or .mha); sidecar <output>.json")->required();
    app.add_option("--joint", joint_, "hip or shoulder")->check(CLI::IsMember({"hip", "shoulder"}))->capture_default_str();
    app.add_option("--side", side_, "Patient side: right or left")->check(CLI::IsMember({"right", "left"}))->capture_default_str();
    pipeline::addStageOptions(app, name(), settings_);
  }
  int run(const cli::CommonOptions& common) override {
    const pipeline::SegmentSettings& given = settings_.segment();
    imaging::SegmentOptions options = given.head;
    imaging::limitImagingThreads(common.threadCount());
    options.joint = joint_ == "hip" ? imaging::Joint::Hip : imaging::Joint::Shoulder;
    options.side = side_ == "right" ? imaging::Side::Right : imaging::Side::Left;
    if (!given.seed_point.empty()) options.seed_point = Eigen::Vector3d(given.seed_point[0], given.seed_point[1], given.seed_point[2]);
    if (!given.roi.empty()) {
      options.roi_min = Eigen::Vector3d(given.roi[0], given.roi[1], given.roi[2]);
      options.roi_max = Eigen::Vector3d(given.roi[3], given.roi[4], given.roi[5]);
    }
    options.validate();
    refuseOutputsOverInputs({output_, output_.string() + ".json"}, {input_, given.label});
    checkOutputTarget(output_);
    cli::refuseExistingOutputs({output_, output_.string() + ".json"}, common.force);

    imaging::ReadOptions read;
    read.series_uid = given.series_uid;
    imaging::ReadReport report;
    const std::shared_ptr<const imaging::Volume> shared_ct = imaging::readSharedVolume(input_, read, &report, common.memory);
    std::optional<imaging::Volume> labelled_bone;
    if (!given.label.empty()) {
      labelled_bone = imaging::keepLabelledBone(*shared_ct, given.label, given.label_value ? std::optional<int>(given.label_value) : std::nullopt);
      options.one_bone = true;
    }
    const imaging::Volume& ct = labelled_bone ? *labelled_bone : *shared_ct;
    for (const auto& w : report.warnings) log::warn(w);
    const auto& g = ct.geometry;
    log::info("read " + input_.string() + ": " + std::to_string(g.size[0]) + "x" + std::to_string(g.size[1]) + "x" +
              std::to_string(g.size[2]) + " voxels");
    imaging::SegmentSummary s;
    const imaging::Label label = imaging::segmentHead(ct, options, &s);
    for (const auto& w : s.warnings) log::warn(w);
    imaging::writeLabel(output_, label, true);
    imaging::keepWrittenLabel(output_, label, common.memory);

    nlohmann::json params = {{"joint", joint_}, {"side", side_}, {"hu_min", options.hu_min},
                             {"hu_max", options.hu_max}, {"surface_hu", options.surface_hu}, {"series_uid", given.series_uid},
                             {"min_radius_mm", options.min_head_radius_mm},
                             {"max_radius_mm", options.max_head_radius_mm},
                             {"close_radius_mm", options.close_radius_mm}, {"min_coverage", options.min_coverage},
                             {"midline_margin_mm", options.midline_margin_mm},
                             {"level_set_iterations", options.level_set_iterations}};
    if (options.seed_point) params["seed_point_mm"] = vec(*options.seed_point);
    if (options.roi_min) params["roi_mm"] = {vec(*options.roi_min), vec(*options.roi_max)};
    std::vector<std::filesystem::path> inputs;
    if (std::filesystem::is_regular_file(input_)) inputs.push_back(input_);
    if (!given.label.empty()) {
      params["label"] = given.label.string();
      if (given.label_value) params["label_value"] = given.label_value;
      inputs.push_back(given.label);
    }
    nlohmann::json series = nlohmann::json::array();
    for (const auto& si : report.series)
      series.push_back({{"uid", si.uid}, {"modality", si.modality}, {"description", si.description}, {"files", si.files}});
    std::vector<std::string> warnings = report.warnings;
    warnings.insert(warnings.end(), s.warnings.begin(), s.warnings.end());
    nlohmann::json summary = {
        {"input", input_.string()},
        {"output", output_.string()},
        {"source", report.source},
        {"series_used", report.series_uid},
        {"series", series},
        {"size", {g.size[0], g.size[1], g.size[2]}},
        {"spacing_mm", vec(g.spacing)},
        {"slice_spacing_measured_mm", report.slice_spacing_mm},
        {"slice_spacing_spread_mm", report.slice_spacing_spread_mm},
        {"gantry_tilt_deg", report.gantry_tilt_deg},
        {"slice_thickness_stated_mm", report.slice_thickness_mm > 0 ? nlohmann::json(report.slice_thickness_mm)
                                                                     : nlohmann::json(nullptr)},
        {"voxel_extent_mm", vec(g.voxelExtent())},
        {"hu_window", {options.hu_min, options.hu_max}},
        {"seed_source", s.seed_source},
        {"label", given.label.empty() ? nlohmann::json(nullptr) : nlohmann::json(given.label.string())},
        {"side_check", s.side_check},
        {"body_middle_x_mm", s.body_middle_x_mm ? nlohmann::json(*s.body_middle_x_mm) : nlohmann::json(nullptr)},
        {"body_middle_from", s.body_middle_from},
        {"head_found_by", s.head_found_by},
        {"seed_mm", vec(s.seed_mm)},
        {"head_center_mm", vec(s.head_center_mm)},
        {"search_radius_mm", s.search_radius_mm},
        {"head_depth_mm", s.head_depth_mm},
        {"edge_coverage", s.edge_coverage},
        {"edge_rms_mm", s.edge_rms_mm},
        {"threshold_voxels", s.threshold_voxels},
        {"label_voxels", s.label_voxels},
        {"cut_through_bone_voxels", s.cut_through_bone_voxels},
        {"noise_hu", s.noise_hu},
        {"smoothed_sigma_mm", s.smoothed_sigma_mm},
        {"warnings", warnings},
        {"provenance", provenanceJson({params, inputs, -1, common.threadCount()})}};
    writeFileAtomically(output_.string() + ".json", summary.dump(2) + "\n", true);
    if (common.json) cli::printJson(summary);
    return 0;
  }

 private:
  std::filesystem::path input_, output_;
  std::string joint_ = "hip", side_ = "right";
  pipeline::StageSettings settings_;
};

ARTICULA_REGISTER_COMMAND(SegmentCommand)

}  // namespace
}  // namespace articula::apps
