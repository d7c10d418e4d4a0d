// `articula phantom`: writes a synthetic hip CT of known femoral head shape
// (NIfTI and a DICOM series) with its truth, the default input of the tests.
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
  std::string description() const override {
    return "Write a synthetic hip CT (NIfTI + DICOM series) with a femoral head of known shape, and truth.json";
  }
  std::string example() const override { return "articula phantom -o phantom --seed 3 --model ellipsoid --gap 2"; }
  void declare(CLI::App& app) override {
    app.add_option("-o,--output", output_, "Output folder (phantom.nii.gz, dicom/, truth.json)")->required();
    app.add_option("--model", model_, "Head shape: sphere, ellipsoid, superellipsoid, ovoid, superovoid (default: by seed)");
    app.add_option("--spacing", spacing_, "Voxel spacing x,y,z in mm")->delimiter(',')->expected(3)->capture_default_str();
    app.add_option("--gap", gap_, "Joint gap between head and socket (mm)")->capture_default_str();
    app.add_option("--side", side_, "Hip side: right or left")->check(CLI::IsMember({"right", "left"}))->capture_default_str();
    app.add_option("--noise", noise_, "Noise standard deviation (HU)")->capture_default_str();
    app.add_option("--blur", blur_, "Point-spread standard deviation (mm)")->capture_default_str();
    app.add_flag("--ras", ras_, "Store the grid RAS (direction diag(-1,-1,1)), like many NIfTI files");
    app.add_flag("--no-dicom", no_dicom_, "Skip the DICOM series");
  }
  int run(const cli::CommonOptions& common) override {
    phantom::PhantomOptions o;
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
    if (!common.force && std::filesystem::exists(volume_path))
      throw UsageError("refusing to overwrite " + volume_path.string() + " (use --force)");

    const phantom::Phantom p = phantom::makePhantom(o);
    log::info("phantom: " + p.truth["model"].get<std::string>() + " head at " + p.truth["head_center_mm"].dump() +
              " mm, grid " + p.truth["grid"]["size"].dump());
    imaging::writeVolume(volume_path, p.ct, true);
    imaging::writeLabel(output_ / "femur_truth.nii.gz", p.femur, true);
    if (!no_dicom_) {
      std::filesystem::remove_all(output_ / "dicom");
      imaging::writeDicomSeries(output_ / "dicom", p.ct, "articula phantom seed " + std::to_string(o.seed));
    }
    nlohmann::json truth = p.truth;
    truth["files"] = {{"nifti", "phantom.nii.gz"}, {"femur_label", "femur_truth.nii.gz"}};
    if (!no_dicom_) truth["files"]["dicom"] = "dicom";
    truth["provenance"] = provenanceJson({truth["parameters"], {}, common.seed});
    writeFileAtomically(output_ / "truth.json", truth.dump(2) + "\n", true);
    if (common.json) cli::printJson(truth);
    return 0;
  }

 private:
  std::filesystem::path output_;
  std::string model_, side_ = "right";
  std::vector<double> spacing_ = {0.7, 0.7, 1.5};
  double gap_ = 3.0, noise_ = 20.0, blur_ = 0.5;
  bool ras_ = false, no_dicom_ = false;
};

ARTICULA_REGISTER_COMMAND(PhantomCommand)

}  // namespace
}  // namespace articula::apps
