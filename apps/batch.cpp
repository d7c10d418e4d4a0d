// `articula batch MANIFEST.csv -o STUDYDIR [-j N] [--validate]`: a morphology
// study over many subjects. Each subject runs `articula run` in its own
// process; failures are recorded and the others go on; a rerun resumes.
#include <unistd.h>

#include <filesystem>
#include <optional>
#include <vector>

#include <nlohmann/json.hpp>

#include "articula/cli/command.hpp"
#include "articula/core/error.hpp"
#include "articula/core/excerpt.hpp"
#include "articula/core/json_file.hpp"
#include "articula/core/log.hpp"
#include "articula/core/output_lock.hpp"
#include "articula/core/provenance.hpp"
#include "articula/pipeline/batch.hpp"
#include "articula/pipeline/manifest.hpp"
#include "articula/study/study.hpp"

namespace articula::apps {
namespace {

namespace fs = std::filesystem;

fs::path selfExecutable() {
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  if (ec) throw ProcessingError("cannot locate the articula executable: " + ec.message());
  return self;
}

class BatchCommand : public cli::Command {
 public:
  std::string name() const override { return "batch"; }
  bool holdsVolumes() const override { return true; }
  std::string description() const override {
    return "Run the pipeline on every subject of a manifest (subject,input,joint,side[,options...]) and "
           "write study tables";
  }
  std::string example() const override { return "articula batch study.csv -o study/ -j 2"; }
  void declare(CLI::App& app) override {
    app.add_option("manifest", manifest_, "CSV with columns subject,input,joint,side, then optional options")
        ->required();
    app.add_option("-o,--output", study_dir_, "Study folder (subjects/<id>/ and the study tables)")->required();
    app.add_option("-j,--jobs", jobs_, "Subjects run in parallel")->check(CLI::PositiveNumber)->capture_default_str();
    app.add_flag("--validate", validate_only_, "Check the manifest and the inputs, run nothing");
    app.add_flag("--gather-only", gather_only_, "Only rebuild the study tables from the subjects' folders");
    app.add_flag("--list", list_,
                 "Print the manifest's subjects as JSON (id, input, joint, side, the options each subject's run "
                 "gets from its columns) once its cells are checked, and run nothing (the Snakemake workflow reads it)");
    app.add_option("--subject-config", subject_config_, "CLI11 config file passed to every subject's run");
  }

  int run(const cli::CommonOptions& common) override {
    const auto subjects = pipeline::readManifest(manifest_);
    pipeline::BatchOptions options;
    options.study_dir = study_dir_;
    options.seed = common.seed;
    if (!subject_config_.empty()) options.extra_args = {"--config", fs::absolute(subject_config_).string()};
    // Every subject's command line must parse before any subject runs: a bad
    // option column would otherwise fail each of them in turn.
    for (const auto& s : subjects) {
      const std::string problem = cli::argumentProblem("run", pipeline::runArguments(s, options));
      if (!problem.empty())
        throw InputError(manifest_.string() + ":" + std::to_string(s.line) + ": subject " + s.id +
                         ": its options do not parse as 'articula run' options: " + excerpt(problem, 200));
    }
    if (list_) {
      nlohmann::json listed = nlohmann::json::array();
      for (const auto& s : subjects)
        listed.push_back({{"id", s.id}, {"input", s.input.string()}, {"joint", s.joint}, {"side", s.side},
                          {"options", s.options}, {"line", s.line}});
      cli::printJson({{"manifest", manifest_.string()}, {"subjects", listed}});
      return 0;
    }
    int problems = 0;
    for (const auto& s : subjects)
      for (const auto& p : pipeline::checkSubjectInput(s, validate_only_)) {
        log::warn(manifest_.string() + ":" + std::to_string(s.line) + ": subject " + s.id + ": " + p);
        ++problems;
      }
    if (validate_only_) {
      if (common.json) cli::printJson({{"subjects", subjects.size()}, {"problems", problems}});
      if (problems) throw InputError(std::to_string(problems) + " subject input problem(s) in " + manifest_.string());
      log::info("manifest ok: " + std::to_string(subjects.size()) + " subjects");
      return 0;
    }
    options.executable = selfExecutable();
    options.jobs = jobs_;
    options.quiet = common.verbosity == 0;
    options.rerun_finished = common.force;
    if (gather_only_) options.jobs = 1;
    if (fs::exists(study_dir_) && !fs::is_directory(study_dir_))
      throw UsageError("output '" + study_dir_.string() + "' is a file: expected the study folder");
    // One batch per study folder at a time (each subject's run locks its own).
    OutputLock lock(study_dir_, "articula batch");
    try {
      if (!common.force) refuseTablesNotOurs();
      if (!common.force && !gather_only_)
        cli::refuseToOverwrite(pipeline::subjectFilesNotOurs(subjects, study_dir_),
                               ", which articula batch did not write (use --force, or another --output)");
    } catch (...) {
      lock.removeIfUnused();
      throw;
    }
    pipeline::BatchSummary summary;
    if (gather_only_) {
      summary = pipeline::gatherOutcomes(subjects, study_dir_);
    } else {
      log::info("batch: " + std::to_string(subjects.size()) + " subjects, " + std::to_string(jobs_) + " at a time");
      summary = pipeline::runBatch(subjects, options);
    }
    Provenance provenance;
    provenance.inputs = {manifest_};
    provenance.seed = common.seed;
    provenance.parameters = {{"jobs", jobs_}};
    const auto study = study::writeStudyTables(study_dir_, subjects, summary, provenanceJson(provenance));
    log::info("batch: " + std::to_string(summary.succeeded) + " ok (" + std::to_string(summary.resumed) +
              " from an earlier run), " + std::to_string(summary.failed) + " failed, " +
              std::to_string(static_cast<int>(summary.seconds)) + " s");
    if (common.json) cli::printJson(study);
    return summary.failed ? static_cast<int>(ExitCode::ProcessingFailed) : 0;
  }

 private:
  // Refuses, before any subject runs, study tables in the study folder that
  // no earlier batch wrote (its study.json, written first, says which did).
  void refuseTablesNotOurs() const {
    const std::optional<nlohmann::json> earlier = readJsonFileIfValid(study_dir_ / "study.json");
    const bool ours = earlier && earlier->contains("provenance") && earlier->contains("subjects");
    if (ours) return;
    std::vector<std::string> others;
    for (const char* table : {"study.csv", "study_summary.csv", "study_status.csv", "study.json", "study.svg", "study.html"})
      if (fs::exists(study_dir_ / table)) others.push_back((study_dir_ / table).string());
    cli::refuseToOverwrite(others, ", which articula batch did not write (use --force, or another --output)");
  }

  fs::path manifest_, study_dir_, subject_config_;
  int jobs_ = 1;
  bool validate_only_ = false, gather_only_ = false, list_ = false;
};

ARTICULA_REGISTER_COMMAND(BatchCommand)

}  // namespace
}  // namespace articula::apps
