#include "articula/pipeline/runner.hpp"

#include <algorithm>
#include <chrono>
#include <optional>

#include "articula/cli/command.hpp"
#include "articula/core/atomic_file.hpp"
#include "articula/core/error.hpp"
#include "articula/core/json_file.hpp"
#include "articula/core/log.hpp"
#include "articula/core/output_lock.hpp"
#include "articula/core/provenance.hpp"
#include "articula/core/version.hpp"
#include "articula/imaging/io.hpp"

namespace articula::pipeline {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

std::string hashOnce(const fs::path& path, KnownHashes* known) {
  if (!known) return hashInput(path);
  const auto [it, added] = known->try_emplace(path.string());
  if (added) it->second = hashInput(path);
  return it->second;
}

// The table's index of a stage, by name (UsageError naming the stages when none).
int stageIndex(const std::string& name) {
  const auto& table = stages();
  const StageDescription& stage = stageNamed(name);
  return static_cast<int>(&stage - table.data());
}

struct Range {
  int first, last;
};

Range stageRange(const SubjectRun& run) {
  const int first = run.from.empty() ? 0 : stageIndex(run.from);
  const int last = run.until.empty() ? static_cast<int>(stages().size()) - 1 : stageIndex(run.until);
  if (first > last) throw UsageError("--from " + run.from + " comes after --until " + run.until);
  return {first, last};
}

// Whether a stage's stamp names `file` (relative to the output folder)
// among its outputs (keyed by path) or its sidecars (names or patterns).
bool stampNames(const std::optional<json>& stamp, const StageDescription& stage, const std::string& file) {
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
    if (entry.is_string() && matchesFilePattern(entry.get<std::string>(), file)) return true;
  return false;
}

// Refuses, before any stage runs and unless forced, a stage's output or
// sidecar that exists but that no stamp of run names: a file run did not write.
void refuseOutputsNotOurs(const SubjectRun& run, Range range) {
  if (run.force) return;
  std::vector<std::string> others;
  for (int i = range.first; i <= range.last; ++i) {
    const StageDescription& stage = stages()[static_cast<size_t>(i)];
    const std::optional<json> stamp = readJsonFileIfValid(stampPath(run.output, stage.name));
    for (const std::string& file : stageFilesIn(stage, run.output))
      if (!stampNames(stamp, stage, file)) others.push_back((run.output / file).string());
  }
  cli::refuseToOverwrite(others, ", which articula run did not write (use --force, or another --output)");
}

// Runs the stages of `range` under the output folder's lock.
RunRecord runStages(const SubjectRun& run, Range range) {
  refuseOutputsNotOurs(run, range);
  RunMemory memory;  // the CT, read once for the stages that take it
  // The folders a run writes in: the subject's, its errors and its stamps.
  int stale = 0;
  for (const fs::path& folder : {run.output, run.output / "errors", run.output / ".articula"})
    stale += removeStaleTemporaries(folder);
  if (stale > 0) log::info("removed " + std::to_string(stale) + " unfinished file(s) of an interrupted earlier run");
  RunRecord record;
  KnownHashes known;
  for (int i = range.first; i <= range.last; ++i) {
    const StageDescription& stage = stages()[static_cast<size_t>(i)];
    const StagePlan plan = planStage(run, stage);
    for (const auto& in : plan.inputs)
      if (!fs::exists(in))
        throw InputError("stage " + stage.name + " needs '" + in.string() + "', which is missing: run the earlier stages first");
    json stamp = stageStamp(plan, &known);
    const fs::path stamp_path = stampPath(run.output, stage.name);
    const bool forced = run.force || (!run.from.empty() && i == range.first);
    if (!forced && isUpToDate(plan, stamp, stamp_path, &known)) {
      log::info("run: " + stage.name + " is up to date");
      record.stages.push_back({stage.name, StageOutcome::UpToDate, 0});
      continue;
    }
    // A stamp naming the outputs (and the sidecars' patterns) before the
    // stage writes them: they are run's own, to replace when the stage is
    // redone, even if it is killed.
    json started = {{"articula", versionString()}, {"status", "started"}, {"outputs", json::object()},
                    {"sidecars", stage.sidecars}};
    for (const auto& out : plan.outputs) started["outputs"][out.string()] = "";
    writeFileAtomically(stamp_path, started.dump(2) + "\n");
    log::info("run: [" + std::to_string(i - range.first + 1) + "/" + std::to_string(range.last - range.first + 1) + "] " +
              stage.name + " ...");
    const auto t0 = std::chrono::steady_clock::now();
    const int rc = cli::runCommandInProcess(stage.name, plan.arguments, &memory);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (rc != 0) {
      // Nothing of it written: its stamp would keep an empty folder.
      if (stageFilesIn(stage, run.output).empty()) fs::remove(stamp_path);
      record.stages.push_back({stage.name, StageOutcome::Failed, seconds});
      record.exit_code = rc;
      return record;
    }
    stamp["seconds"] = seconds;
    stamp["outputs"] = json::object();  // a damaged or replaced output reruns the stage
    for (const auto& out : plan.outputs) {
      known.erase(out.string());  // written anew
      stamp["outputs"][out.string()] = hashOnce(out, &known);
    }
    stamp["sidecars"] = json::array();
    for (const auto& file : stageFilesIn(stage, run.output))
      if (std::find(stage.outputs.begin(), stage.outputs.end(), file) == stage.outputs.end())
        stamp["sidecars"].push_back(file);
    writeFileAtomically(stamp_path, stamp.dump(2) + "\n");
    record.stages.push_back({stage.name, StageOutcome::Ran, seconds});
  }
  return record;
}

}  // namespace

StagePlan planStage(const SubjectRun& run, const StageDescription& stage) {
  StagePlan p;
  p.stage = stage.name;
  for (const auto& in : stage.inputs) p.inputs.push_back(in == "CT" ? run.input : run.output / in);
  for (const auto& out : stage.outputs) p.outputs.push_back(run.output / out);
  p.arguments = expandArguments(stage, run.input.string(), run.output.string(), run.joint, run.side);
  if (const auto given = run.stage_options.find(stage.name); given != run.stage_options.end())
    p.arguments.insert(p.arguments.end(), given->second.begin(), given->second.end());
  p.arguments.insert(p.arguments.end(), {"--seed", std::to_string(run.seed), "--threads", std::to_string(run.threads),
                                         "--force"});
  if (run.verbosity == 0) p.arguments.push_back("--quiet");
  if (run.verbosity == 2) p.arguments.push_back("--verbose");
  return p;
}

std::vector<StagePlan> planStages(const SubjectRun& run) {
  const Range range = stageRange(run);
  std::vector<StagePlan> plans;
  for (int i = range.first; i <= range.last; ++i) plans.push_back(planStage(run, stages()[static_cast<size_t>(i)]));
  return plans;
}

std::string argumentsProblem(const SubjectRun& run) {
  for (const auto& stage : stages()) {
    const std::string problem = cli::argumentProblem(stage.name, planStage(run, stage).arguments);
    if (!problem.empty()) return "the " + stage.name + " stage: " + problem;
  }
  return "";
}

void checkSubjectRun(const SubjectRun& run) {
  stageRange(run);
  if (const std::string problem = argumentsProblem(run); !problem.empty()) throw UsageError(problem);
  if (!fs::exists(run.input))
    throw InputError("input '" + run.input.string() + "' does not exist: expected a DICOM folder or a CT image file");
  // Checked before it is hashed: reading a device or a pipe would never end.
  if (!fs::is_regular_file(run.input) && !fs::is_directory(run.input))
    throw InputError("input '" + run.input.string() + "' is neither a file nor a folder (a device, pipe or socket): "
                     "expected a DICOM folder or a CT image file");
  if (fs::exists(run.output) && !fs::is_directory(run.output))
    throw UsageError("output '" + run.output.string() + "' is a file: expected a folder for the stages' outputs");
}

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

json stageStamp(const StagePlan& plan, KnownHashes* known) {
  // Another build of articula reruns every stage: its outputs may differ.
  // How much a stage logs does not change them: --quiet and --verbose are
  // no part of its stamp.
  std::vector<std::string> args;
  for (const std::string& a : plan.arguments)
    if (a != "--quiet" && a != "--verbose") args.push_back(a);
  json stamp = {{"articula", versionString()}, {"args", args}, {"inputs", json::object()}};
  for (const auto& in : plan.inputs) stamp["inputs"][in.string()] = hashOnce(in, known);
  return stamp;
}

bool isUpToDate(const StagePlan& plan, const json& stamp, const fs::path& stamp_path, KnownHashes* known) {
  for (const auto& out : plan.outputs)
    if (!fs::exists(out)) return false;
  const std::optional<json> old = readJsonFileIfValid(stamp_path);
  if (!old) return false;
  try {
    if (!(old->value("articula", "") == stamp.at("articula") && old->at("args") == stamp.at("args") &&
          old->at("inputs") == stamp.at("inputs")))
      return false;
    for (const auto& out : plan.outputs)
      if (old->at("outputs").value(out.string(), "") != hashOnce(out, known)) return false;
    return true;
  } catch (const json::exception&) {
    return false;
  }
}

fs::path stampPath(const fs::path& output, const std::string& stage) {
  return output / ".articula" / (stage + ".json");
}

std::vector<std::string> RunRecord::stagesThat(StageOutcome outcome) const {
  std::vector<std::string> names;
  for (const StageRecord& s : stages)
    if (s.outcome == outcome) names.push_back(s.stage);
  return names;
}

RunRecord runSubject(const SubjectRun& run) {
  // The run's messages as its stages' (each stage sets the level it is given).
  log::setLevel(static_cast<log::Level>(run.verbosity));
  checkSubjectRun(run);
  const Range range = stageRange(run);
  // One run per output folder at a time; a run that fails before any stage
  // has written leaves no trace of itself there.
  OutputLock lock(run.output, "articula run");
  RunRecord record;
  try {
    record = runStages(run, range);
  } catch (...) {
    lock.removeIfUnused();
    throw;
  }
  if (record.exit_code != 0) lock.removeIfUnused();
  return record;
}

}  // namespace articula::pipeline
