#pragma once
// A reviewer's ratings of a study's subjects: ratings.csv in the study folder
// (subject,decision,note; decision include or exclude), saved from the study
// page or written by hand. The study tables leave the excluded subjects out
// and say who was excluded and why (`articula batch --gather-only`, the
// Snakefile's study rule).
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "articula/pipeline/manifest.hpp"

namespace articula::study {

struct Rating {
  std::string decision;  // "include" or "exclude"
  std::string note;
};

/// The file name in a study folder.
inline constexpr const char* kRatingsFile = "ratings.csv";

/// The study's ratings by subject (none when ratings.csv is absent). Throws
/// InputError naming the file and line for a missing column, a decision other
/// than include or exclude, or a subject rated twice; a subject not in
/// `subjects` is skipped with a warning (a rating left from an older manifest).
std::map<std::string, Rating> readRatings(const std::filesystem::path& study_dir, const std::vector<pipeline::Subject>& subjects);

}  // namespace articula::study
