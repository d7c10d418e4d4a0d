#pragma once
// The pipeline's stages in run order, in one table: what each stage reads
// and writes in a subject's folder, its command line there, and the options
// a user may give for it through `articula run`, a batch manifest column or
// the Snakemake workflow (declared in stage_options.hpp). The runner
// (runner.hpp, `articula run`) chains the stages from it, `articula stages
// --json` prints it, and pipelines/Snakefile makes one rule per stage from
// that print.
//
// The pipeline's own six stages are listed in stages.cpp, their options in
// stage_options.cpp. A stage may also come in one file of its own: its
// command, its settings struct, a function returning its row (its options
// bound with stageOption and ARTICULA_STAGE_FIELD) and the line
// ARTICULA_REGISTER_STAGE(Command, describe). It takes its place in the run
// order by the files it reads and writes, and run, stages --json, manifests
// and the Snakefile take it from the table.
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "articula/cli/command.hpp"
#include "articula/pipeline/stage_options.hpp"

namespace articula::pipeline {

struct StageDescription {
  std::string name;                  // also the command: articula <name>, articula-<name>
  std::string description;
  std::vector<StageOption> options;  // what a user may set (stage_options.hpp)
  std::vector<std::string> inputs;   // in the subject folder; "CT" is the subject's input
  std::vector<std::string> outputs;  // in the subject folder
  /// Its command line in a subject's folder, without the standard options:
  /// {CT} the subject's input, {folder} its folder, {joint} and {side}.
  std::vector<std::string> arguments;
  /// What it writes beside its outputs (provenance .json, tables, per-model
  /// files; '*' for a model's name), in the subject folder: neither inputs
  /// of later stages nor Snakemake targets, but replaced by a rerun all the
  /// same, so `articula run` checks them as it checks the outputs.
  std::vector<std::string> sidecars;
  int threads = 1;       // worker threads a job of it uses (a scheduler's request)
  int memory_mb = 1000;  // memory a job of it needs on a clinical-size CT (a scheduler's request)
};

/// The arguments with {CT}, {folder}, {joint} and {side} replaced.
std::vector<std::string> expandArguments(const StageDescription& stage, const std::string& ct, const std::string& folder,
                                         const std::string& joint, const std::string& side);

/// Every stage in run order (inRunOrder of the pipeline's own, then those
/// registered, by name): segment, mesh, sample, fit, errors, report, and
/// those registered where their inputs place them.
const std::vector<StageDescription>& stages();

/// `listed` in an order that runs each stage after those that write its
/// inputs: of the stages ready to run, the one listed first. Throws
/// ProcessingError for a file two stages write, an input ("CT" aside) no
/// stage writes, two stages of one name, or a cycle.
std::vector<StageDescription> inRunOrder(std::vector<StageDescription> listed);

/// The pipeline's own stages, in their order.
std::vector<StageDescription> pipelineStages();

/// Adds a stage declared in its own file to the table (before main: through
/// ARTICULA_REGISTER_STAGE, with its command of the same name).
bool registerStage(StageDescription (*describe)());

#define ARTICULA_REGISTER_STAGE(Class, describe) \
  ARTICULA_REGISTER_COMMAND(Class)               \
  [[maybe_unused]] const bool articula_registered_stage_##Class = ::articula::pipeline::registerStage(describe);

/// The named stage; throws UsageError naming the stages when there is none.
const StageDescription& stageNamed(const std::string& name);

/// The stage names joined by ", " (for help texts).
std::string stageNames();

/// Whether `file` matches a sidecar's name, '*' standing for any part of
/// one path component.
bool matchesFilePattern(const std::string& pattern, const std::string& file);

/// Whether `file` (relative to the subject folder, '/'-separated) is one of
/// the stage's outputs or matches one of its sidecars.
bool isStageFile(const StageDescription& stage, const std::string& file);

/// The stage's outputs and sidecars that exist in `folder`, relative to it, sorted.
std::vector<std::string> stageFilesIn(const StageDescription& stage, const std::filesystem::path& folder);

/// {"stages": [{"name", "description", "options", "inputs", "outputs", "arguments", "sidecars", "threads",
/// "memory_mb"}, ...]}, each option as StageOption::json().
nlohmann::json stagesJson();

}  // namespace articula::pipeline
