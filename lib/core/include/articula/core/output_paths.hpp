#pragma once
// Checks a command makes on the files it will write, before any work: none
// may be one of its inputs (the same path, or the same file through links),
// so that a run can never destroy the data it reads.
#include <filesystem>
#include <vector>

namespace articula {

/// Throws UsageError (exit 2) naming both paths if any of `outputs` is one of
/// `inputs`, or lies inside an input folder (a DICOM series).
void refuseOutputsOverInputs(const std::vector<std::filesystem::path>& outputs,
                             const std::vector<std::filesystem::path>& inputs);

}  // namespace articula
