#pragma once
// Study tables gathered from every subject's results.json (written by
// `articula run`):
//   study.csv          one row per subject x model: parameters and error statistics
//   study_summary.csv  per model: mean and sd of RMS across subjects, how often
//                      it is selected and how often least by RMS, AIC, BIC, mean AIC/BIC difference to
//                      the sphere, and the paired Wilcoxon signed-rank p-value of
//                      its RMS against the sphere's
//   study_status.csv   one row per subject: status, exit code, message, and
//                      the reviewer's decision and note (ratings.hpp); the
//                      tables leave the excluded subjects out
//   study_steps.csv    per step of the hierarchy (sphere -> ellipsoid, ...):
//                      how many subjects need the richer model, Fisher's
//                      combination of their p-values and a sign test of
//                      their decisions (statistics::cohortStep)
//   study.json         all of the above, with provenance
//   study.svg          RMS per model for each subject, with the per-model means
//                      (when at least one subject succeeded)
#include <filesystem>
#include <vector>

#include <nlohmann/json.hpp>

#include "articula/pipeline/batch.hpp"

namespace articula::study {

/// Reads subjects' results and writes the study tables into `study_dir`
/// (atomically); returns study.json's content.
nlohmann::json writeStudyTables(const std::filesystem::path& study_dir, const std::vector<pipeline::Subject>& subjects,
                                const pipeline::BatchSummary& batch, const nlohmann::json& provenance);

}  // namespace articula::study
