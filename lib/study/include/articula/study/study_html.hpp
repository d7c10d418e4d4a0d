#pragma once
// study.html: a study's page, self-contained and offline, beside its
// tables: the counts, the subjects to look at (failed, with the reason, and
// flagged by their checks, with the reasons), one plot per key quantity
// (each model's RMS, the selected model's radii, the superellipsoid's
// exponents) where every dot links to its subject's report.html, the
// selected models, links to the study tables, and the provenance.
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

namespace articula::study {

/// The page from study.json's document and the results.json documents of
/// the finished subjects (by subject id, in manifest order); links are
/// relative to `study_dir` and only to files that exist there.
std::string studyReportHtml(const nlohmann::json& study,
                            const std::vector<std::pair<std::string, nlohmann::json>>& results,
                            const std::filesystem::path& study_dir);

}  // namespace articula::study
