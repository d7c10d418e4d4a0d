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

/// Throws ProcessingError (exit 1) naming the target and the system's reason
/// when `output` cannot be written: it is a folder, or its folder does not
/// exist and cannot be made, or is not writable. Checked before the work, so
/// that an unwritable target does not cost a whole run. Creates the folder.
void checkOutputTarget(const std::filesystem::path& output);

}  // namespace articula
