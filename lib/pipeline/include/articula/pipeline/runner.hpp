#pragma once
// One subject through the stage table (stages.hpp): segment -> mesh ->
// sample -> fit -> errors -> report, in this process, each stage being its
// registered command (cli/command.hpp) run with the arguments its executable
// would get, so the subject's folder holds exactly the files the stage apps
// write. A stage whose outputs exist and whose inputs (SHA-256), arguments
// and articula build are unchanged is skipped (stamps in
// <output>/.articula/<stage>.json). The CT is read once: the stages that
// take it get it from the run's memory (core/run_memory.hpp, handed to each
// stage's command as cli::CommonOptions::memory). `articula run` is its
// command line; the stage commands must be linked in (apps/, as the
// `articula` executable links them).
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "articula/pipeline/stages.hpp"

namespace articula::pipeline {

/// One subject's run: its files, the stages to run, the options given for
/// them, and the standard options every stage gets.
struct SubjectRun {
  std::filesystem::path input;   // the CT: a DICOM folder or an image file
  std::filesystem::path output;  // the subject's folder, one file per stage output
  std::string joint = "hip";     // hip or shoulder
  std::string side = "right";    // right or left
  /// First and last stage to run (empty: the table's first and last). A
  /// stage named by `from` is rerun even when up to date.
  std::string from, until;
  /// The options given for each stage, by stage name, as its command line
  /// takes them (stage_options_cli.hpp's forwardedArguments).
  std::map<std::string, std::vector<std::string>> stage_options;
  long long seed = 42;
  int threads = 1;      // worker threads of each stage
  int verbosity = 1;    // of each stage: 0 quiet, 1 normal, 2 verbose
  bool force = false;   // rerun every stage; replace files that no run wrote
};

/// Where a stage reads and writes in the subject's folder (the table's file
/// names; "CT" is the run's input) and the arguments its command gets.
struct StagePlan {
  std::string stage;
  std::vector<std::string> arguments;
  std::vector<std::filesystem::path> inputs, outputs;
};

/// The plan of one stage of the table.
StagePlan planStage(const SubjectRun& run, const StageDescription& stage);

/// The plans of the stages from `run.from` to `run.until`, in run order.
/// Throws UsageError for a name that is no stage, or a `from` after `until`.
std::vector<StagePlan> planStages(const SubjectRun& run);

/// The first stage whose arguments its command would refuse ("the fit
/// stage: ..."), every stage of the table parsed as its command parses them;
/// empty when they all parse.
std::string argumentsProblem(const SubjectRun& run);

/// What a run refuses before any work, thrown: the stage range and the
/// stages' arguments (UsageError), an input that is missing or neither a
/// file nor a folder (InputError), an output that is a file (UsageError).
void checkSubjectRun(const SubjectRun& run);

/// SHA-256 of a file, or of every file of a folder (a DICOM series) in name order.
std::string hashInput(const std::filesystem::path& path);

/// Hashes already taken in one run, by path: the run holds its folder's lock,
/// so a file it hashed (the CT, a stage's output) is not changed under it,
/// and each is read once rather than by every stage that takes it.
using KnownHashes = std::map<std::string, std::string>;

/// The stamp a stage of this plan would leave: the articula build, its
/// arguments and its inputs' hashes (the inputs must exist); `known`, when
/// given, supplies hashes taken before and keeps those taken now.
nlohmann::json stageStamp(const StagePlan& plan, KnownHashes* known = nullptr);

/// Whether the stage need not run: its outputs exist, and the stamp it left
/// at `stamp_path` names the same build, arguments and input hashes as
/// `stamp` (stageStamp) and the outputs' present hashes (through `known`, as
/// stageStamp).
bool isUpToDate(const StagePlan& plan, const nlohmann::json& stamp, const std::filesystem::path& stamp_path,
                KnownHashes* known = nullptr);

/// Where a stage's stamp is kept in the subject's folder.
std::filesystem::path stampPath(const std::filesystem::path& output, const std::string& stage);

/// What the run did with each stage it reached, in run order.
enum class StageOutcome { Ran, UpToDate, Failed };

struct StageRecord {
  std::string stage;
  StageOutcome outcome = StageOutcome::Ran;
  double seconds = 0;  // the stage's own time (0 when up to date)
};

struct RunRecord {
  std::vector<StageRecord> stages;  // up to the first that failed
  int exit_code = 0;                // the failed stage's (it said why on stderr), else 0
  /// The names of the stages with that outcome, in run order.
  std::vector<std::string> stagesThat(StageOutcome outcome) const;
};

/// Checks the run (checkSubjectRun), takes the output folder's lock
/// (core/output_lock.hpp), refuses unless `force` a stage's file there that
/// no stamp names, removes unfinished files of an interrupted run, and runs
/// the stages from..until, skipping those up to date. Stops at the first
/// stage that fails (its exit code in the record); a run that wrote nothing
/// leaves no lock or stamp behind.
RunRecord runSubject(const SubjectRun& run);

}  // namespace articula::pipeline
