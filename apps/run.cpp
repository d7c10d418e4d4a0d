// `articula run -i INPUT -o OUTDIR`: segment -> mesh -> sample -> fit ->
// errors -> report for one subject, skipping stages that are up to date: the
// command line of pipeline::runSubject (pipeline/runner.hpp), which holds
// the stamps, the stage range and the chaining.
#include <chrono>
#include <filesystem>
#include <iostream>
#include <map>

#include <nlohmann/json.hpp>

#include "articula/cli/command.hpp"
#include "articula/core/json_file.hpp"
#include "articula/core/log.hpp"
#include "articula/core/number_text.hpp"
#include "articula/pipeline/runner.hpp"
#include "articula/pipeline/stage_options_cli.hpp"
#include "articula/pipeline/stages.hpp"

namespace articula::apps {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// An argument as a POSIX shell reads it back: bare when it holds only
// characters no shell treats specially, else in single quotes.
std::string shellWord(const std::string& arg) {
  if (!arg.empty() && arg.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_./,:=+-@%") ==
                          std::string::npos)
    return arg;
  std::string quoted = "'";
  for (const char c : arg) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

std::string number(double v) {
  std::string text;
  appendNumber(text, v, 10);
  return text;
}

class RunCommand : public cli::Command {
 public:
  std::string name() const override { return "run"; }
  bool holdsVolumes() const override { return true; }
  std::string description() const override {
    return "Run segment -> mesh -> sample -> fit -> errors -> report on one CT, skipping stages that are up to date";
  }
  std::string example() const override {
    return "articula run -i ct/ -o out/subject01 --joint hip --side right";
  }
  void declare(CLI::App& app) override {
    std::vector<std::string> names;
    for (const auto& stage : pipeline::stages()) names.push_back(stage.name);
    app.add_option("-i,--input", input_, "DICOM folder or .nii/.nii.gz/.nrrd/.mha CT")->required();
    app.add_option("-o,--output", output_, "Output folder, one file per stage output")->required();
    app.add_option("--joint", joint_, "hip or shoulder")->check(CLI::IsMember({"hip", "shoulder"}))->capture_default_str();
    app.add_option("--side", side_, "right or left")->check(CLI::IsMember({"right", "left"}))->capture_default_str();
    app.add_option("--from", from_, "First stage to run (earlier outputs must exist): " + pipeline::stageNames())
        ->check(CLI::IsMember(names));
    app.add_option("--until", until_, "Last stage to run")->check(CLI::IsMember(names));
    app.add_flag("--dry-run", dry_run_,
                 "Print each stage's command line (from --from to --until) and run nothing; with --json as JSON");
    // Every stage's options (pipeline/stage_options.hpp), typed and checked
    // here, then passed to the stages that take them.
    stage_options_ = pipeline::addRunOptions(app, settings_);
  }

  std::string argumentsProblem(const cli::CommonOptions& common) const override {
    return pipeline::argumentsProblem(subjectRun(common));
  }

  int run(const cli::CommonOptions& common) override {
    const auto start = std::chrono::steady_clock::now();
    const pipeline::SubjectRun subject = subjectRun(common);
    if (dry_run_) {
      pipeline::checkSubjectRun(subject);
      printPlan(pipeline::planStages(subject), common.json);
      return 0;
    }
    const pipeline::RunRecord record = pipeline::runSubject(subject);
    if (record.exit_code != 0) return record.exit_code;
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    log::info("run: done in " + number(seconds) + " s: " + (output_ / "results.json").string());
    if (common.json && fs::exists(output_ / "results.json")) cli::printJson(readJsonFile(output_ / "results.json", "run"));
    return 0;
  }

 private:
  // The run as the library takes it: the options given for each stage, the
  // standard options every stage gets.
  pipeline::SubjectRun subjectRun(const cli::CommonOptions& common) const {
    pipeline::SubjectRun subject;
    subject.input = input_;
    subject.output = output_;
    subject.joint = joint_;
    subject.side = side_;
    subject.from = from_;
    subject.until = until_;
    for (const auto& stage : pipeline::stages())
      subject.stage_options[stage.name] = pipeline::forwardedArguments(stage.name, stage_options_);
    subject.seed = common.seed;
    subject.threads = common.threadCount();
    subject.verbosity = common.verbosity;
    subject.force = common.force;
    return subject;
  }

  // --dry-run: each stage's command line, as a shell would take it, or as JSON.
  static void printPlan(const std::vector<pipeline::StagePlan>& plans, bool as_json) {
    json plan = json::array();
    for (const pipeline::StagePlan& stage : plans) {
      if (as_json) {
        plan.push_back({{"stage", stage.stage}, {"arguments", stage.arguments}});
        continue;
      }
      std::string line = "articula " + stage.stage;
      for (const std::string& arg : stage.arguments) line += " " + shellWord(arg);
      std::cout << line << "\n";
    }
    if (as_json) cli::printJson({{"stages", plan}});
  }

  fs::path input_, output_;
  std::string joint_ = "hip", side_ = "right", from_, until_;
  bool dry_run_ = false;
  pipeline::StageSettings settings_;  // run's values of the stage options (only those given are passed on)
  std::map<std::string, CLI::Option*> stage_options_;
};

ARTICULA_REGISTER_COMMAND(RunCommand)

}  // namespace
}  // namespace articula::apps
