#pragma once
// Batch manifests: one subject per row, columns `subject,input,joint,side`,
// then optional per-subject options, any stage option under its name in
// `articula run` (stage_options.hpp): a column `seed_point` with value
// `1,2,3` becomes `--seed-point 1,2,3` for that subject, a flag's column
// takes true or false (empty cells add nothing). Relative inputs are
// resolved from the manifest's folder.
#include <filesystem>
#include <string>
#include <vector>

namespace articula::pipeline {

struct Subject {
  std::string id;                   // subject column; a safe folder name
  std::filesystem::path input;      // absolute
  std::string joint;                // hip | shoulder
  std::string side;                 // left | right
  std::vector<std::string> options; // extra command-line arguments
  int line = 0;                     // line in the manifest
};

/// Reads and checks a manifest; throws InputError naming the file and line for
/// a missing column, an empty or duplicated subject id, an id that is not a
/// safe folder name, a joint/side outside hip|shoulder / left|right, or a
/// stage option's value its declaration refuses (out of range, not a number,
/// no choice of its own).
std::vector<Subject> readManifest(const std::filesystem::path& manifest);

/// Problems with a subject's input that would make it fail (missing path,
/// unreadable, an empty folder, an unknown extension); empty if none.
/// With `scan_series`, a DICOM folder's series are scanned as the run will
/// (every file walked, no voxel read): for --validate, not for every batch,
/// whose runs scan them anyway.
std::vector<std::string> checkSubjectInput(const Subject& subject, bool scan_series = false);

}  // namespace articula::pipeline
