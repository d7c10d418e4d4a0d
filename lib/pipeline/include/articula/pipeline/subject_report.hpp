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

// Default of --selection-alpha: the level of the nested tests of the model
// selection (pipeline::selectNested).
constexpr double kDefaultSelectionAlpha = 0.05;
// Default of --selection-length: the length over which the nested tests count
// a CT surface's errors as shared (mm). A fit's own residuals cannot tell it:
// over a cap they hold the shape a model misses and the slices' direction-
// dependent error, which a variogram takes for lengths of 5-50 mm, while the
// surface's making (blur, the mesh's and the edge model's smoothing over
// about 3 mm) ties neighbours over a few millimetres. Measured on phantom
// CTs of known shape (docs/benchmarks.md, model selection): 3.5-4.5 mm
// select best, from 0.6 to 3 mm voxels alike.
constexpr double kDefaultSelectionLengthMm = 4.0;

struct SubjectReportOptions {
  std::filesystem::path folder;  // holds fits.json, errors/summary.json, points.ply (and label.nii.gz.json)
  std::filesystem::path ct;      // the subject's CT (recorded; hashed when it is a file; sliced for report.html)
  std::string series_uid;        // the CT's series, in a DICOM folder of several
  std::string joint = "hip", side = "right";
  double selection_alpha = kDefaultSelectionAlpha;
  double selection_length_mm = kDefaultSelectionLengthMm;  // 0: each fit's own residual correlation
  long long seed = -1;           // recorded in the provenance
};

/// Writes results.json, results.csv, head.mrk.json and report.html into options.folder and
/// returns the head's QC report (the caller decides what a failure means).
/// Throws InputError when a stage output is missing or unreadable.
QcReport writeSubjectReport(const SubjectReportOptions& options);

}  // namespace articula::pipeline
