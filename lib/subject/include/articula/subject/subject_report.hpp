#pragma once
// A subject's results from its stage outputs: results.json (every model's
// parameters with units, standard errors, errors, AIC/BIC, the selected
// model, the head's QC checks, provenance), results.csv (a row per model)
// head.mrk.json (the head centre and axes for 3D Slicer) and report.html
// (subject_html.hpp: the page a reader checks), all in the subject's folder.
// The report stage of the pipeline.
#include <filesystem>
#include <string>

#include "articula/checks/qc.hpp"
#include "articula/core/run_memory.hpp"
#include "articula/statistics/model_selection.hpp"

namespace articula::subject {

struct SubjectReportOptions {
  std::filesystem::path folder;  // holds fits.json, errors/summary.json, points.ply (and label.nii.gz.json)
  std::filesystem::path ct;      // the subject's CT (recorded; hashed when it is a file; sliced for report.html)
  std::string series_uid;        // the CT's series, in a DICOM folder of several
  std::string joint = "hip", side = "right";
  double selection_alpha = statistics::kDefaultSelectionAlpha;
  double selection_length_mm = statistics::kDefaultSelectionLengthMm;  // 0: each fit's own residual correlation
  long long seed = -1;           // recorded in the provenance
  RunMemory* memory = nullptr;   // a run's memory: the CT its earlier stages read (cli::CommonOptions::memory)
};

/// Writes results.json, results.csv, head.mrk.json and report.html into options.folder and
/// returns the head's QC report (the caller decides what a failure means).
/// Throws InputError when a stage output is missing or unreadable.
checks::QcReport writeSubjectReport(const SubjectReportOptions& options);

}  // namespace articula::subject
