#pragma once
// Reading CT volumes and labels (DICOM series, NIfTI, NRRD, MHA) with the
// checks ITK does not make, and writing them back. Everything in LPS mm.
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "articula/core/run_memory.hpp"
#include "articula/imaging/image.hpp"

namespace articula::imaging {

/// One DICOM series found in a folder.
/// How a series whose Series Instance UID is empty is named in listings and
/// chosen with --series-uid (a real UID holds digits and dots only).
inline constexpr const char* kEmptySeriesUid = "empty";

struct SeriesInfo {
  std::string uid;          // Series Instance UID; kEmptySeriesUid for files whose UID is empty
  std::string modality;     // (0008,0060)
  std::string description;  // (0008,103E)
  int files = 0;
};

struct ReadOptions {
  std::string series_uid;                  // empty: the largest CT series (logged)
  double spacing_tolerance = 0.01;         // relative deviation of slice gaps tolerated
  double tilt_tolerance_deg = 0.1;         // gantry tilt above which we refuse
};

/// What reading found: series, slice spacing, warnings; goes to the sidecar JSON.
struct ReadReport {
  std::string source;       // "dicom" or "file"
  std::string series_uid;
  std::string modality;
  std::vector<SeriesInfo> series;  // every series of the folder
  std::vector<std::string> unreadable_files;  // files of the folder that are no readable DICOM
  double slice_spacing_mm = 0;     // measured from Image Position Patient
  double slice_spacing_spread_mm = 0;
  double gantry_tilt_deg = 0;
  double slice_thickness_mm = 0;   // Slice Thickness (0018,0050) as the slices state it (0: not stated)
  std::vector<std::string> warnings;
};

/// Lists the DICOM series in `folder`; throws InputError if there is none.
std::vector<SeriesInfo> listDicomSeries(const std::filesystem::path& folder);

/// Reads a CT volume in HU from a DICOM folder or an image file (.nii, .nii.gz,
/// .nrrd, .nhdr, .mha, .mhd). Throws InputError (exit 3) for an empty or
/// non-DICOM folder, several series without options.series_uid, non-uniform
/// slice spacing or missing slices, gantry tilt, a non-CT modality, or a
/// non-orthonormal direction matrix.
Volume readVolume(const std::filesystem::path& input, const ReadOptions& options, ReadReport* report = nullptr);

/// The same without a copy. With a run's memory (RunMemory), the volume read
/// for this input and these options is kept, and read again only when its
/// files have changed (names, sizes, modification times): `articula run`
/// reads the CT once for all its stages instead of once per stage.
std::shared_ptr<const Volume> readSharedVolume(const std::filesystem::path& input, const ReadOptions& options,
                                               ReadReport* report = nullptr, RunMemory* memory = nullptr);

/// ITK's filters use at most `threads` threads (ITK's own pool otherwise
/// takes every core, whatever --threads says).
void limitImagingThreads(int threads);

/// The voxel grid of an image file (.nii.gz/.nii/.nrrd/.mha) from its header
/// alone (no voxels read). Throws InputError for another file, a header ITK
/// cannot read, or an image that is not 3-D with an orthonormal direction.
ImageGeometry readImageGeometry(const std::filesystem::path& input);

/// Reads a label image (any integer type, non-zero = kLabelBone). With
/// `keep_cut` (a label articula's segmentation wrote), its voxels of
/// kLabelCutThroughBone keep that value. With a run's `memory`, a file
/// unchanged since keepWrittenLabel kept it (or since an earlier read in the
/// run) is taken from memory: the same voxels, the grid from its header.
Label readLabel(const std::filesystem::path& input, bool keep_cut = false, RunMemory* memory = nullptr);

/// In a run (`memory` given, else nothing): keeps `label`, just written to
/// `path` by writeLabel, for the run's later readLabel of that file (a
/// CT-sized label took a sixth of a second to inflate for each stage).
void keepWrittenLabel(const std::filesystem::path& path, const Label& label, RunMemory* memory);

/// Writes a volume (as int16 HU) or a label (uint8) to .nii.gz/.nii/.nrrd/.mha,
/// atomically (temporary name, then rename).
void writeVolume(const std::filesystem::path& path, const Volume& volume, bool overwrite = true);
void writeLabel(const std::filesystem::path& path, const Label& label, bool overwrite = true);

/// Writes a CT DICOM series (int16, rescale slope 1, intercept 0) as
/// folder/slice_0000.dcm ..., one file per k, with Image Position/Orientation
/// Patient from the geometry and modality CT.
void writeDicomSeries(const std::filesystem::path& folder, const Volume& volume, const std::string& series_description);

/// Throws InputError unless `direction` is orthonormal within 1e-3.
void checkDirection(const Eigen::Matrix3d& direction, const std::string& where);

/// The ITK version this build reads and segments with (methods text, provenance).
std::string itkVersion();

}  // namespace articula::imaging
