// `articula-report -i SUBJECT_DIR`: the report stage. results.json,
// results.csv and head.mrk.json from the folder's stage outputs (fits.json,
// errors/summary.json, points.ply, label.nii.gz.json); exit 1 when the head's
// checks fail (the files are still written, with the reasons in "qc").
#include "articula/cli/command.hpp"
#include "articula/core/error.hpp"
#include "articula/core/log.hpp"
#include "articula/pipeline/stage_options_cli.hpp"
#include "articula/pipeline/stages.hpp"
#include "articula/subject/subject_report.hpp"

namespace articula::apps {
namespace {

class ReportCommand : public cli::Command {
 public:
  std::string name() const override { return "report"; }
  bool holdsVolumes() const override { return true; }
  std::string description() const override {
    return "Write a subject's results, selected model and head checks from its stage outputs";
  }
  std::string example() const override { return "articula-report -i out/subject01 --ct ct/ --joint hip --side right"; }
  void declare(CLI::App& app) override {
    app.add_option("-i,--input", options_.folder, "Subject folder holding fits.json, errors/summary.json and points.ply")
        ->required();
    app.add_option("--ct", options_.ct, "The subject's CT (recorded in results.json; hashed when it is a file)");
    app.add_option("--joint", options_.joint, "hip or shoulder (recorded)")
        ->check(CLI::IsMember({"hip", "shoulder"}))
        ->capture_default_str();
    app.add_option("--side", options_.side, "right or left (recorded)")
        ->check(CLI::IsMember({"right", "left"}))
        ->capture_default_str();
    pipeline::addStageOptions(app, name(), settings_);
  }
  int run(const cli::CommonOptions& common) override {
    if (!std::filesystem::is_directory(options_.folder))
      throw InputError("--input: expected a subject folder, found '" + options_.folder.string() + "'");
    // Every file the stage writes (the stage table's outputs and sidecars).
    std::vector<std::filesystem::path> existing;
    for (const std::string& file : pipeline::stageFilesIn(pipeline::stageNamed(name()), options_.folder))
      existing.push_back(options_.folder / file);
    cli::refuseExistingOutputs(existing, common.force);
    options_.seed = common.seed;
    options_.memory = common.memory;
    const checks::QcReport qc = subject::writeSubjectReport(options_);
    for (const std::string& reason : qc.reasons()) log::warn("qc " + reason);
    if (qc.status == "fail") {
      std::string failed;
      for (const std::string& reason : qc.reasons())
        if (reason.rfind("fail: ", 0) == 0) failed += (failed.empty() ? "" : "; ") + reason.substr(6);
      throw ProcessingError("the head failed its checks (results.json, \"qc\"): " + failed);
    }
    return 0;
  }

 private:
  pipeline::StageSettings settings_;
  subject::SubjectReportOptions& options_ = settings_.report();
};

ARTICULA_REGISTER_COMMAND(ReportCommand)

}  // namespace
}  // namespace articula::apps
