#pragma once
// A subject's results from its stage outputs: results.json (every model's
// parameters with units, standard errors, errors, AIC/BIC, the selected
// model, the head's QC checks, provenance), results.csv (a row per model)
// head.mrk.json (the head centre and axes for 3D Slicer) and report.html
// (subject_html.hpp: the page a reader checks), all in the subject's folder.
// The report stage of the pipeline.
#include <filesystem>
#include <string>

#include "articula/pipeline/qc.hpp"

namespace articula::pipeline {

// Default of --selection-tolerance: models whose RMS is within 10 % of the
// least are not told apart; on phantoms of known shape
// (tests/apps/batch_killed.sh) the voxelised surface leaves the true model
// 4-9 % above the most flexible one.
constexpr double kDefaultSelectionTolerance = 0.10;
// Default of --selection-floor (see pipeline::selectParsimonious).
constexpr double kDefaultSelectionFloorMm = 0.03;

struct SubjectReportOptions {
  std::filesystem::path folder;  // holds fits.json, errors/summary.json, points.ply (and label.nii.gz.json)
  std::filesystem::path ct;      // the subject's CT (recorded; hashed when it is a file; sliced for report.html)
  std::string series_uid;        // the CT's series, in a DICOM folder of several
  std::string joint = "hip", side = "right";
  double selection_tolerance = kDefaultSelectionTolerance;
  double selection_floor_mm = kDefaultSelectionFloorMm;
  long long seed = -1;           // recorded in the provenance
};

/// Writes results.json, results.csv, head.mrk.json and report.html into options.folder and
/// returns the head's QC report (the caller decides what a failure means).
/// Throws InputError when a stage output is missing or unreadable.
QcReport writeSubjectReport(const SubjectReportOptions& options);

}  // namespace articula::pipeline
