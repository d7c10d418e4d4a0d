// `articula run -i INPUT -o OUTDIR`: segment -> mesh -> sample -> fit ->
// errors -> report for one subject, in this process, in the order of the
// stage table (pipeline/stages.hpp). Each stage is the registered stage
// command itself, run with the arguments its executable would get, so OUTDIR
// holds exactly the files the stage apps write. A stage
// whose outputs exist and whose inputs (SHA-256) and arguments are unchanged
// is skipped (stamps in OUTDIR/.articula/). The CT is read once: the stages
// that take it get it from memory (imaging::VolumeMemory).
#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <optional>

#include <nlohmann/json.hpp>

#include "articula/cli/command.hpp"
#include "articula/core/json_file.hpp"
#include "articula/core/atomic_file.hpp"
#include "articula/core/error.hpp"
#include "articula/core/number_text.hpp"
#include "articula/core/output_lock.hpp"
#include "articula/core/log.hpp"
#include "articula/core/provenance.hpp"
#include "articula/core/version.hpp"
#include "articula/imaging/io.hpp"
#include "articula/pipeline/stage_options_cli.hpp"
#include "articula/pipeline/stages.hpp"

namespace articula::apps {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// SHA-256 of a file, or of every file of a folder (a DICOM series) in name order.
std::string hashInput(const fs::path& path) {
  if (!fs::is_directory(path)) return sha256File(path);
  std::vector<fs::path> files;
  for (const auto& e : fs::recursive_directory_iterator(path))
    if (e.is_regular_file()) files.push_back(e.path());
  std::sort(files.begin(), files.end());
  std::string all;
  for (const auto& f : files) all += fs::relative(f, path).string() + ":" + sha256File(f) + "\n";
  return sha256String(all);
}

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
    for (const auto& stage : pipeline::stages()) {
      const std::string problem = cli::argumentProblem(stage.name, stagePlan(stage, common).args);
      if (!problem.empty()) return "the " + stage.name + " stage: " + problem;
    }
    return "";
  }

  int run(const cli::CommonOptions& common) override {
    const auto start = std::chrono::steady_clock::now();
    const auto& table = pipeline::stages();
    const int first = from_.empty() ? 0 : index(from_);
    const int last = until_.empty() ? static_cast<int>(table.size()) - 1 : index(until_);
    if (first > last) throw UsageError("--from " + from_ + " comes after --until " + until_);
    if (const std::string problem = argumentsProblem(common); !problem.empty()) throw UsageError(problem);
    if (!fs::exists(input_)) throw InputError("input '" + input_.string() + "' does not exist: expected a DICOM folder or a CT image file");
    // Checked before it is hashed: reading a device or a pipe would never end.
    if (!fs::is_regular_file(input_) && !fs::is_directory(input_))
      throw InputError("input '" + input_.string() + "' is neither a file nor a folder (a device, pipe or socket): "
                       "expected a DICOM folder or a CT image file");
    if (fs::exists(output_) && !fs::is_directory(output_))
      throw UsageError("output '" + output_.string() + "' is a file: expected a folder for the stages' outputs");
    if (dry_run_) {
      printPlan(first, last, common);
      return 0;
    }
    // One run per output folder at a time; a run that fails before any
    // stage has written leaves no trace of itself there.
    OutputLock lock(output_, "articula run");
    int rc = 0;
    try {
      rc = runStages(first, last, common);
    } catch (...) {
      lock.removeIfUnused();
      throw;
    }
    if (rc != 0) {
      lock.removeIfUnused();
      return rc;
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    log::info("run: done in " + number(seconds) + " s: " + (output_ / "results.json").string());
    if (common.json && fs::exists(output_ / "results.json")) cli::printJson(readJsonFile(output_ / "results.json", "run"));
    return 0;
  }

 private:
  struct Plan {
    std::vector<std::string> args;
    std::vector<fs::path> inputs, outputs;
  };

  static int index(const std::string& stage) {
    const auto& table = pipeline::stages();
    return static_cast<int>(std::find_if(table.begin(), table.end(), [&](const auto& s) { return s.name == stage; }) -
                            table.begin());
  }

  // Where a stage reads and writes in OUTDIR (the table's file names), and the
  // arguments its command gets: its files, the options given for it, the
  // standard options.
  Plan stagePlan(const pipeline::StageDescription& stage, const cli::CommonOptions& common) const {
    Plan p;
    for (const auto& in : stage.inputs) p.inputs.push_back(in == "CT" ? input_ : output_ / in);
    for (const auto& out : stage.outputs) p.outputs.push_back(output_ / out);
    p.args = pipeline::expandArguments(stage, input_.string(), output_.string(), joint_, side_);
    const std::vector<std::string> given = pipeline::forwardedArguments(stage.name, stage_options_);
    p.args.insert(p.args.end(), given.begin(), given.end());
    p.args.insert(p.args.end(), {"--seed", std::to_string(common.seed), "--threads", std::to_string(common.threadCount()),
                                 "--force"});
    if (common.verbosity == 0) p.args.push_back("--quiet");
    if (common.verbosity == 2) p.args.push_back("--verbose");
    return p;
  }

  // --dry-run: each stage's command line, as a shell would take it, or as JSON.
  void printPlan(int first, int last, const cli::CommonOptions& common) const {
    json plan = json::array();
    for (int i = first; i <= last; ++i) {
      const pipeline::StageDescription& stage = pipeline::stages()[static_cast<size_t>(i)];
      const std::vector<std::string> args = stagePlan(stage, common).args;
      if (common.json) {
        plan.push_back({{"stage", stage.name}, {"arguments", args}});
        continue;
      }
      std::string line = "articula " + stage.name;
      for (const std::string& arg : args) line += " " + shellWord(arg);
      std::cout << line << "\n";
    }
    if (common.json) cli::printJson({{"stages", plan}});
  }

  // Runs stages first..last under the output folder's lock; a stage's exit
  // code when it fails (it has said why on stderr).
  int runStages(int first, int last, const cli::CommonOptions& common) const {
    const auto& table = pipeline::stages();
    refuseOutputsNotOurs(first, last, common);
    const imaging::VolumeMemory read_once;
    // The folders a run writes in: the subject's, its errors and its stamps.
    int stale = 0;
    for (const fs::path& folder : {output_, output_ / "errors", output_ / ".articula"})
      stale += removeStaleTemporaries(folder);
    if (stale > 0)
      log::info("removed " + std::to_string(stale) + " unfinished file(s) of an interrupted earlier run");
    for (int i = first; i <= last; ++i) {
      const pipeline::StageDescription& stage = table[static_cast<size_t>(i)];
      const Plan plan = stagePlan(stage, common);
      for (const auto& in : plan.inputs)
        if (!fs::exists(in))
          throw InputError("stage " + stage.name + " needs '" + in.string() + "', which is missing: run the earlier stages first");
      // Another build of articula reruns every stage: its outputs may differ.
      json stamp = {{"articula", versionString()}, {"args", plan.args}, {"inputs", json::object()}};
      for (const auto& in : plan.inputs) stamp["inputs"][in.string()] = hashInput(in);
      const fs::path stamp_path = output_ / ".articula" / (stage.name + ".json");
      const bool forced = common.force || (!from_.empty() && i == first);
      if (!forced && upToDate(plan, stamp, stamp_path)) {
        log::info("run: " + stage.name + " is up to date");
        continue;
      }
      // A stamp naming the outputs (and the sidecars' patterns) before the
      // stage writes them: they are run's own, to replace when the stage is
      // redone, even if it is killed.
      json started = {{"articula", versionString()}, {"status", "started"}, {"outputs", json::object()},
                      {"sidecars", stage.sidecars}};
      for (const auto& out : plan.outputs) started["outputs"][out.string()] = "";
      writeFileAtomically(stamp_path, started.dump(2) + "\n");
      log::info("run: [" + std::to_string(i - first + 1) + "/" + std::to_string(last - first + 1) + "] " + stage.name + " ...");
      const auto t0 = std::chrono::steady_clock::now();
      const int rc = cli::runCommandInProcess(stage.name, plan.args);
      if (rc != 0) {
        // Nothing of it written: its stamp would keep an empty folder.
        if (pipeline::stageFilesIn(stage, output_).empty()) fs::remove(stamp_path);
        return rc;
      }
      stamp["seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      stamp["outputs"] = json::object();  // a damaged or replaced output reruns the stage
      for (const auto& out : plan.outputs) stamp["outputs"][out.string()] = hashInput(out);
      stamp["sidecars"] = json::array();
      for (const auto& file : pipeline::stageFilesIn(stage, output_))
        if (std::find(stage.outputs.begin(), stage.outputs.end(), file) == stage.outputs.end())
          stamp["sidecars"].push_back(file);
      writeFileAtomically(stamp_path, stamp.dump(2) + "\n");
    }
    return 0;
  }

  // Refuses, before any stage runs and unless --force, a stage's output or
  // sidecar that exists but that no stamp of run names: a file run did not
  // write.
  void refuseOutputsNotOurs(int first, int last, const cli::CommonOptions& common) const {
    if (common.force) return;
    std::vector<std::string> others;
    const auto& table = pipeline::stages();
    for (int i = first; i <= last; ++i) {
      const pipeline::StageDescription& stage = table[static_cast<size_t>(i)];
      const std::optional<json> stamp = readJsonFileIfValid(output_ / ".articula" / (stage.name + ".json"));
      for (const std::string& file : pipeline::stageFilesIn(stage, output_))
        if (!stampNames(stamp, stage, file)) others.push_back((output_ / file).string());
    }
    cli::refuseToOverwrite(others, ", which articula run did not write (use --force, or another --output)");
  }

  // Whether a stage's stamp names `file` (relative to the output folder)
  // among its outputs (keyed by path) or its sidecars (names or patterns).
  static bool stampNames(const std::optional<json>& stamp, const pipeline::StageDescription& stage,
                         const std::string& file) {
    if (!stamp || !stamp->is_object()) return false;
    if (stamp->contains("outputs") && stamp->at("outputs").is_object())
      for (const auto& [written, hash] : stamp->at("outputs").items())
        if (written == file || (written.size() > file.size() &&
                                written.compare(written.size() - file.size() - 1, std::string::npos, "/" + file) == 0))
          return true;
    if (std::find(stage.outputs.begin(), stage.outputs.end(), file) != stage.outputs.end()) return false;
    // Stamps of earlier versions listed no sidecars: those beside their outputs are theirs.
    if (!stamp->contains("sidecars")) return true;
    if (!stamp->at("sidecars").is_array()) return false;
    for (const auto& entry : stamp->at("sidecars"))
      if (entry.is_string() && pipeline::matchesFilePattern(entry.get<std::string>(), file)) return true;
    return false;
  }

  static bool upToDate(const Plan& plan, const json& stamp, const fs::path& stamp_path) {
    for (const auto& out : plan.outputs)
      if (!fs::exists(out)) return false;
    const std::optional<json> old = readJsonFileIfValid(stamp_path);
    if (!old) return false;
    try {
      if (!(old->value("articula", "") == stamp.at("articula") && old->at("args") == stamp.at("args") &&
            old->at("inputs") == stamp.at("inputs")))
        return false;
      for (const auto& out : plan.outputs)
        if (old->at("outputs").value(out.string(), "") != hashInput(out)) return false;
      return true;
    } catch (const json::exception&) {
      return false;
    }
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
