// `articula phantom`: writes a synthetic hip CT of known femoral head shape
// (NIfTI and a DICOM series) with its truth, the default input of the tests.
#include <cstdio>
#include <filesystem>
#include <regex>
#include <string>
#include <vector>

#include "articula/cli/command.hpp"
#include "articula/core/atomic_file.hpp"
#include "articula/core/error.hpp"
#include "articula/core/log.hpp"
#include "articula/core/provenance.hpp"
#include "articula/imaging/io.hpp"
#include "articula/phantom/phantom.hpp"

namespace articula::apps {
namespace {

class PhantomCommand : public cli::Command {
 public:
  std::string name() const override { return "phantom"; }
  bool holdsVolumes() const override { return true; }
  std::string description() const override {
    return "Write a synthetic hip CT (NIfTI + DICOM series) with a femoral head of known shape (or both hips), and truth.json";
  }
  std::string example() const override {
    return "articula phantom -o phantom --seed 3 --model ellipsoid --gap 2\n"
           "  articula phantom -o pelvis --both-hips --radius-range 17,30 --gap 1.5 --spacing 1.5,1.5,3 --fovea --osteoporotic\n"
           "  articula phantom -o arthritic --seed 2 --flattened-dome 0.15 --osteophytes 2 --cysts --narrow-gap 0.8";
  }
  void declare(CLI::App& app) override {
    app.add_option("-o,--output", output_, "Output folder (phantom.nii.gz, dicom/, truth.json)")->required();
    app.add_option("--model", model_, "Head shape: sphere, ellipsoid, superellipsoid, ovoid, superovoid (default: by seed)");
    app.add_option("--spacing", spacing_, "Voxel spacing x,y,z in mm")->delimiter(',')->expected(3)->capture_default_str();
    app.add_option("--gap", gap_, "Joint gap between head and socket (mm)")->capture_default_str();
    app.add_option("--side", side_, "Hip side: right or left")->check(CLI::IsMember({"right", "left"}))->capture_default_str();
    app.add_option("--noise", noise_, "Noise standard deviation (HU)")->capture_default_str();
    app.add_option("--blur", blur_, "Point-spread standard deviation (mm)")->capture_default_str();
    app.add_flag("--ras", ras_, "Store the grid RAS (direction diag(-1,-1,1)), like many NIfTI files");
    radius_option_ = app.add_option("--radius", radius_, "Head's mean radius in mm (default: drawn by seed from --radius-range)");
    app.add_option("--radius-range", radius_range_, "Range LO,HI (mm) of the seed-drawn head radius")
        ->delimiter(',')->expected(2)->capture_default_str();
    app.add_option("--socket", socket_, "Acetabulum: congruent (a shell at the gap) or spherical (larger radius, gap widening to the rim)")
        ->check(CLI::IsMember({"congruent", "spherical"}))->capture_default_str();
    app.add_option("--socket-excess", options_.socket_excess_mm, "Spherical socket: inner radius minus (head's largest radius + gap), mm")
        ->capture_default_str();
    app.add_option("--socket-wall", options_.socket_wall_mm, "Acetabular wall thickness (mm)")->capture_default_str();
    socket_cortical_ = app.add_option("--socket-cortical-hu", socket_cortical_hu_, "Socket cortex HU (default: the femur's)");
    socket_cancellous_ = app.add_option("--socket-cancellous-hu", socket_cancellous_hu_, "Socket cancellous HU (default: the femur's)");
    app.add_flag("--osteoporotic", osteoporotic_,
                 "Osteoporotic bone: cortex 0.8 mm at 700 HU, cancellous 190 +- 90 HU (the options below override)");
    cortical_hu_ = app.add_option("--cortical-hu", options_.cortical_hu, "Cortical bone HU")->capture_default_str();
    cancellous_hu_ = app.add_option("--cancellous-hu", options_.cancellous_hu, "Cancellous bone HU")->capture_default_str();
    cortical_mm_ = app.add_option("--cortical-mm", options_.cortical_mm, "Cortical thickness (mm)")->capture_default_str();
    variation_ = app.add_option("--cancellous-variation", options_.cancellous_variation_hu,
                                "Amplitude of a smooth spatial variation of the cancellous HU")->capture_default_str();
    app.add_flag("--fovea", options_.fovea, "A fovea capitis pit on the head (radius 5 mm, depth 2 mm)");
    app.add_flag("--exact", options_.exact_depth,
                 "Cortex, joint gap and socket wall of exactly the stated widths (default: the original phantom, "
                 "whose first-order distance makes a 3 mm gap 3.2 mm and a 12 mm wall 16.6 mm on a 21 mm head)");
    app.add_flag("--both-hips", options_.both_hips,
                 "Both hips in one field of view with a pelvis-like frame; --side names the head of the top-level truth");
    // Arthritis, on the --side head; truth.json's `departures` record each change.
    app.add_option("--flattened-dome", options_.flattened_dome,
                   "Arthritis: the head's weight-bearing dome flattened, cut by a plane this FRACTION (0-0.5) of its "
                   "radius below its top (superior) and covered by new cortex, as a collapsed or worn femoral head")
        ->capture_default_str();
    app.add_option("--osteophytes", options_.osteophytes_mm,
                   "Arthritis: a bony lip of this height (mm, up to 6) along the superior 150 degrees of the "
                   "head-neck junction, as the osteophytes ringing an arthritic head")
        ->capture_default_str();
    app.add_flag("--cysts", options_.cysts,
                 "Arthritis: three subchondral cysts, fluid-filled balls 2-5 mm across just under the cortex of the "
                 "superior cap");
    app.add_option("--narrow-gap", options_.narrow_gap_mm,
                   "Arthritis: the joint space narrowed to this width (mm, 0.3 up to --gap) over a superior patch of "
                   "the cap (within 20 degrees of superior, back to --gap at 32), as cartilage loss where the hip "
                   "bears weight")
        ->capture_default_str();
    // What the scan adds; truth.json records each.
    fov_cut_ = app.add_option("--fov-cut", fov_cut_value_,
                   "A field of view that clips the --side head: the stored image ends at a plane across --fov-face "
                   "with the head reaching this FRACTION of its radius beyond the last voxels (0: tangent, up to "
                   "0.9), as a scan framed too tightly");
    app.add_option("--fov-face", fov_face_,
                   "The face of the field of view that --fov-cut moves in: +x, -x, +y, -y, +z, -z (LPS: left, right, "
                   "posterior, anterior, superior, inferior; or L, R, P, A, S, I)")
        ->capture_default_str();
    app.add_option("--metal", metal_,
                   "Metal on the --side femur: screw (a 6.5 mm lag screw along the neck into the head, as after a "
                   "fixed neck fracture) or stem (a 12 mm stem in the shaft), at 8000 HU clipped to the scanner's "
                   "3071, with streaks (bright and dark lines through the metal in each slice) and dark bands "
                   "along and between its parts")
        ->check(CLI::IsMember({"screw", "stem"}));
    app.add_option("--kernel", kernel_,
                   "Reconstruction kernel, within the slices: standard; soft (a further 0.6 mm Gaussian: smoother "
                   "edges, fainter noise, as a soft-tissue kernel); sharp (edge enhancement with an overshoot at each "
                   "edge and about twice the noise, correlated, as a bone kernel)")
        ->check(CLI::IsMember({"standard", "soft", "sharp"}))->capture_default_str();
    app.add_flag("--contrast-vessel", options_.contrast_vessel,
                 "A 6 mm vessel filled with contrast (300 HU) running anterior-medial to the head, 5 mm off it, as "
                 "the femoral artery in a CT angiogram");
    app.add_flag("--table", options_.table,
                 "The patient table: a curved slab (700 HU, 6 mm) under the patient's back with air beyond it, in "
                 "the field of view (the grid grows 26 mm posteriorly)");
    app.add_option("--slice-thickness", options_.slice_thickness_mm,
                   "Slices thicker than their spacing (mm): each slice the mean over a box this wide across the "
                   "slices, as a scan reconstructed at 3 mm and stored every 1.5 mm (0: the z spacing)")
        ->capture_default_str();
    app.add_flag("--no-dicom", no_dicom_, "Skip the DICOM series");
  }
  int run(const cli::CommonOptions& common) override {
    imaging::limitImagingThreads(common.threadCount());
    phantom::PhantomOptions o;
    if (osteoporotic_) o.makeOsteoporotic();
    // Explicit bone options override the osteoporotic preset.
    if (cortical_hu_->count()) o.cortical_hu = options_.cortical_hu;
    if (cancellous_hu_->count()) o.cancellous_hu = options_.cancellous_hu;
    if (cortical_mm_->count()) o.cortical_mm = options_.cortical_mm;
    if (variation_->count()) o.cancellous_variation_hu = options_.cancellous_variation_hu;
    if (socket_cortical_->count()) o.socket_cortical_hu = socket_cortical_hu_;
    if (socket_cancellous_->count()) o.socket_cancellous_hu = socket_cancellous_hu_;
    if (!radius_range_.empty()) o.head_radius_range_mm = Eigen::Vector2d(radius_range_[0], radius_range_[1]);
    if (radius_option_->count()) o.head_radius_mm = radius_;
    o.congruent_socket = socket_ == "congruent";
    o.socket_excess_mm = options_.socket_excess_mm;
    o.socket_wall_mm = options_.socket_wall_mm;
    o.fovea = options_.fovea;
    o.both_hips = options_.both_hips;
    o.exact_depth = options_.exact_depth;
    o.flattened_dome = options_.flattened_dome;
    o.osteophytes_mm = options_.osteophytes_mm;
    o.cysts = options_.cysts;
    o.narrow_gap_mm = options_.narrow_gap_mm;
    if (!metal_.empty()) o.metal = phantom::metalFromName(metal_);
    o.kernel = phantom::kernelFromName(kernel_);
    o.contrast_vessel = options_.contrast_vessel;
    o.table = options_.table;
    o.slice_thickness_mm = options_.slice_thickness_mm;
    if (fov_cut_->count()) {
      if (!(fov_cut_value_ >= 0)) throw UsageError("--fov-cut: expected a fraction of the radius from 0 to 0.9");
      o.fov_cut = fov_cut_value_;
      o.fov_face = phantom::faceDirection(fov_face_);
    }
    if (common.seed < 0) throw UsageError("--seed: expected a non-negative integer");
    o.seed = static_cast<unsigned long long>(common.seed);
    if (!model_.empty()) o.model = geometry::modelFromName(model_);
    o.spacing = Eigen::Vector3d(spacing_[0], spacing_[1], spacing_[2]);
    o.gap_mm = gap_;
    o.right = side_ == "right";
    o.noise_hu = noise_;
    o.blur_mm = blur_;
    o.ras_storage = ras_;
    o.validate();
    const auto volume_path = output_ / "phantom.nii.gz";
    const std::vector<std::filesystem::path> old_slices = checkOutputs(common.force);

    const phantom::Phantom p = phantom::makePhantom(o);
    const auto& centre = p.truth["head_center_mm"];
    char at[96];
    std::snprintf(at, sizeof at, "(%.2f, %.2f, %.2f)", centre[0].get<double>(), centre[1].get<double>(), centre[2].get<double>());
    log::info("phantom: " + p.truth["model"].get<std::string>() + " head at " + at + " mm (LPS), grid " +
              p.truth["grid"]["size"].dump());
    imaging::writeVolume(volume_path, p.ct, true);
    imaging::writeLabel(output_ / "femur_truth.nii.gz", p.femur, true);
    if (!no_dicom_) {
      for (const auto& slice : old_slices) std::filesystem::remove(slice);
      imaging::writeDicomSeries(output_ / "dicom", p.ct, "articula phantom seed " + std::to_string(o.seed));
    }
    nlohmann::json truth = p.truth;
    truth["files"] = {{"nifti", "phantom.nii.gz"}, {"femur_label", "femur_truth.nii.gz"}};
    if (!no_dicom_) truth["files"]["dicom"] = "dicom";
    truth["provenance"] = provenanceJson({truth["parameters"], {}, common.seed, common.threadCount()});
    writeFileAtomically(output_ / "truth.json", truth.dump(2) + "\n", true);
    if (common.json) cli::printJson(truth);
    return 0;
  }

 private:
  /// Refuses, before any work, outputs that exist (without --force) and a
  /// dicom/ folder holding anything but the slices this command writes
  /// (even with --force: those files are not ours to delete). Returns the
  /// earlier slices, which a new series replaces.
  std::vector<std::filesystem::path> checkOutputs(bool force) const {
    namespace fs = std::filesystem;
    if (fs::exists(output_) && !fs::is_directory(output_))
      throw UsageError("output '" + output_.string() + "' is a file: expected a folder for phantom.nii.gz, dicom/ and truth.json");
    std::vector<std::string> existing;
    for (const char* name : {"phantom.nii.gz", "femur_truth.nii.gz", "truth.json"})
      if (fs::exists(output_ / name)) existing.push_back((output_ / name).string());
    std::vector<fs::path> slices;
    const fs::path dicom = output_ / "dicom";
    if (!no_dicom_ && fs::exists(dicom)) {
      if (!fs::is_directory(dicom)) throw UsageError("'" + dicom.string() + "' is a file: expected the DICOM series' folder");
      static const std::regex slice_name("slice_[0-9]{4,}\\.dcm");
      for (const auto& entry : fs::directory_iterator(dicom)) {
        if (!entry.is_regular_file() || !std::regex_match(entry.path().filename().string(), slice_name))
          throw UsageError("'" + dicom.string() + "' holds '" + entry.path().filename().string() +
                           "', which articula phantom did not write: move it or choose another --output");
        slices.push_back(entry.path());
      }
      if (!slices.empty()) existing.push_back(dicom.string() + "/ (" + std::to_string(slices.size()) + " slices)");
    }
    if (!force) cli::refuseToOverwrite(existing, " (use --force)");
    return slices;
  }

  std::filesystem::path output_;
  std::string model_, side_ = "right";
  std::vector<double> spacing_ = {0.7, 0.7, 1.5};
  double gap_ = 3.0, noise_ = 20.0, blur_ = 0.5, radius_ = 0;
  bool ras_ = false, no_dicom_ = false, osteoporotic_ = false;
  std::vector<double> radius_range_ = {20.0, 25.0};
  std::string socket_ = "congruent";
  double socket_cortical_hu_ = 0, socket_cancellous_hu_ = 0;
  double fov_cut_value_ = 0;
  std::string fov_face_ = "+z", metal_, kernel_ = "standard";
  phantom::PhantomOptions options_;  // holds the parsed values of the bone and socket options
  CLI::Option *radius_option_ = nullptr, *cortical_hu_ = nullptr, *cancellous_hu_ = nullptr, *cortical_mm_ = nullptr, *variation_ = nullptr,
              *socket_cortical_ = nullptr, *socket_cancellous_ = nullptr, *fov_cut_ = nullptr;
};

ARTICULA_REGISTER_COMMAND(PhantomCommand)

}  // namespace
}  // namespace articula::apps
