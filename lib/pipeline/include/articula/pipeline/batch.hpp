#pragma once
// Batch studies: every subject of a manifest runs `articula run` in its own
// process (a crash or an out-of-memory in one subject cannot take the batch
// down), up to `jobs` at a time. A subject's outcome is recorded in
// STUDYDIR/subjects/<id>/status.json; a rerun skips subjects already ok.
#include <filesystem>
#include <string>
#include <vector>

#include "articula/pipeline/manifest.hpp"

namespace articula::pipeline {

struct BatchOptions {
  std::filesystem::path study_dir;
  std::filesystem::path executable;       // the `articula` driver
  int jobs = 1;
  long long seed = 42;
  std::vector<std::string> extra_args;    // passed to every subject's run (e.g. --config FILE)
  bool rerun_finished = false;            // --force: redo subjects already ok
  bool quiet = false;
};

struct SubjectOutcome {
  std::string id;
  std::string status;  // "ok", "failed"
  int exit_code = 0;
  std::string message; // the subject's error message when failed
  double seconds = 0.0;
  bool resumed = false;  // finished in an earlier run, not redone
};

struct BatchSummary {
  std::vector<SubjectOutcome> outcomes;  // in manifest order
  int succeeded = 0, failed = 0, resumed = 0;
  double seconds = 0.0;
};

/// The folder of one subject's outputs.
std::filesystem::path subjectDir(const std::filesystem::path& study_dir, const std::string& id);

/// The arguments of a subject's `articula run` (without the program and the
/// command name).
std::vector<std::string> runArguments(const Subject& subject, const BatchOptions& options);

/// Runs every subject; never throws for a failing subject.
/// The files a batch writes beside each subject's run (run.log, status.json)
/// that exist but that no batch wrote: a status.json that is not a batch's
/// record of that subject, a run.log in a folder with neither such a record
/// nor run's stamps (.articula). Full paths, for refuseToOverwrite.
std::vector<std::string> subjectFilesNotOurs(const std::vector<Subject>& subjects,
                                             const std::filesystem::path& study_dir);

BatchSummary runBatch(const std::vector<Subject>& subjects, const BatchOptions& options);

/// The outcomes recorded in the subjects' folders (status.json; a subject
/// with results.json but no status, as Snakemake leaves it, counts as ok),
/// without running anything.
BatchSummary gatherOutcomes(const std::vector<Subject>& subjects, const std::filesystem::path& study_dir);

}  // namespace articula::pipeline
