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

namespace articula::apps {
namespace {

nlohmann::json vec(const Eigen::Vector3d& v) { return {v[0], v[1], v[2]}; }

class SegmentCommand : public cli::Command {
 public:
  std::string name() const override { return "segment"; }
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
    app.add_option("--seed-point", seed_point_, "A point inside the head, X,Y,Z in LPS mm (skips the search)")
        ->delimiter(',')->expected(3);
    app.add_option("--series-uid", series_uid_, "DICOM series to read when the folder holds several (empty: the series whose Series Instance UID is empty)");
    app.add_option("--hu-min", options_.hu_min, "Lower end of the bone window (HU)")->capture_default_str();
    app.add_option("--hu-max", options_.hu_max, "Upper end of the bone window (HU)")->capture_default_str();
    app.add_option("--surface-hu", options_.surface_hu, "Level of the head's final surface (HU)")->capture_default_str();
    app.add_option("--level-set", options_.level_set_iterations,
                   "Refine the head's surface by a geodesic active contour of this many iterations (0: off)")->capture_default_str();
    app.add_option("--close-radius", options_.close_radius_mm,
                   "Closing radius before hole filling, mm (bridges speckled cancellous bone; 0: off)")->capture_default_str();
    app.add_option("--midline-margin", options_.midline_margin_mm,
                   "Least distance (mm) of an automatically found head from the volume's mid-sagittal plane "
                   "(-1: 40 mm when the field of view spans 250 mm or more left-right, else 0)")->capture_default_str();
    app.add_option("--min-coverage", options_.min_coverage,
                   "Least share (0-1) of an automatically found head's sphere that is bone surface")->capture_default_str();
    app.add_option("--roi", roi_, "Box xmin,ymin,zmin,xmax,ymax,zmax in LPS mm")->delimiter(',')->expected(6);
    app.add_option("--min-radius", options_.min_head_radius_mm, "Smallest plausible head radius (mm)")->capture_default_str();
    app.add_option("--max-radius", options_.max_head_radius_mm, "Largest plausible head radius (mm)")->capture_default_str();
    app.add_option("--label", label_,
                   "A label map in the CT's grid (a femur or humerus mask from another tool): the head is cut from its bone");
    app.add_option("--label-value", label_value_, "The label's value of the bone (default: every non-zero voxel)")
        ->check(CLI::Range(1, 65535));
  }
  int run(const cli::CommonOptions& common) override {
    imaging::limitImagingThreads(common.threadCount());
    options_.joint = joint_ == "hip" ? imaging::Joint::Hip : imaging::Joint::Shoulder;
    options_.side = side_ == "right" ? imaging::Side::Right : imaging::Side::Left;
    if (!seed_point_.empty()) options_.seed_point = Eigen::Vector3d(seed_point_[0], seed_point_[1], seed_point_[2]);
    if (!roi_.empty()) {
      options_.roi_min = Eigen::Vector3d(roi_[0], roi_[1], roi_[2]);
      options_.roi_max = Eigen::Vector3d(roi_[3], roi_[4], roi_[5]);
    }
    options_.validate();
    refuseOutputsOverInputs({output_, output_.string() + ".json"}, {input_, label_});
    checkOutputTarget(output_);
    cli::refuseExistingOutputs({output_, output_.string() + ".json"}, common.force);

    imaging::ReadOptions read;
    read.series_uid = series_uid_;
    imaging::ReadReport report;
    const std::shared_ptr<const imaging::Volume> shared_ct = imaging::readSharedVolume(input_, read, &report);
    std::optional<imaging::Volume> labelled_bone;
    if (!label_.empty()) {
      labelled_bone = imaging::keepLabelledBone(*shared_ct, label_, label_value_ ? std::optional<int>(label_value_) : std::nullopt);
      options_.one_bone = true;
    }
    const imaging::Volume& ct = labelled_bone ? *labelled_bone : *shared_ct;
    for (const auto& w : report.warnings) log::warn(w);
    const auto& g = ct.geometry;
    log::info("read " + input_.string() + ": " + std::to_string(g.size[0]) + "x" + std::to_string(g.size[1]) + "x" +
              std::to_string(g.size[2]) + " voxels");
    imaging::SegmentSummary s;
    const imaging::Label label = imaging::segmentHead(ct, options_, &s);
    for (const auto& w : s.warnings) log::warn(w);
    imaging::writeLabel(output_, label, true);

    nlohmann::json params = {{"joint", joint_}, {"side", side_}, {"hu_min", options_.hu_min},
                             {"hu_max", options_.hu_max}, {"surface_hu", options_.surface_hu}, {"series_uid", series_uid_},
                             {"min_radius_mm", options_.min_head_radius_mm},
                             {"max_radius_mm", options_.max_head_radius_mm},
                             {"close_radius_mm", options_.close_radius_mm}, {"min_coverage", options_.min_coverage},
                             {"midline_margin_mm", options_.midline_margin_mm},
                             {"level_set_iterations", options_.level_set_iterations}};
    if (options_.seed_point) params["seed_point_mm"] = vec(*options_.seed_point);
    if (options_.roi_min) params["roi_mm"] = {vec(*options_.roi_min), vec(*options_.roi_max)};
    std::vector<std::filesystem::path> inputs;
    if (std::filesystem::is_regular_file(input_)) inputs.push_back(input_);
    if (!label_.empty()) {
      params["label"] = label_.string();
      if (label_value_) params["label_value"] = label_value_;
      inputs.push_back(label_);
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
        {"hu_window", {options_.hu_min, options_.hu_max}},
        {"seed_source", s.seed_source},
        {"label", label_.empty() ? nlohmann::json(nullptr) : nlohmann::json(label_.string())},
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
        {"warnings", warnings},
        {"provenance", provenanceJson({params, inputs, -1})}};
    writeFileAtomically(output_.string() + ".json", summary.dump(2) + "\n", true);
    if (common.json) cli::printJson(summary);
    return 0;
  }

 private:
  std::filesystem::path input_, output_, label_;
  int label_value_ = 0;
  std::string joint_ = "hip", side_ = "right", series_uid_;
  std::vector<double> seed_point_, roi_;
  imaging::SegmentOptions options_;
};

ARTICULA_REGISTER_COMMAND(SegmentCommand)

}  // namespace
}  // namespace articula::apps
