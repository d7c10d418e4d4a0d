#pragma once
// report.html: a subject's results as one self-contained page that opens
// offline (no external resource; a content security policy forbids any
// request): the verdict first (the head's checks and their reasons, the
// selected model, the head centre and radii with 95 % intervals), an
// interactive 3-D view (head_view.hpp), CT slices through the head with the segmentation's
// edge and the model's outline (head_slices.hpp), the checks, the five
// models, the error figures of the errors stage inline, and an About section (version, commit, command,
// date, parameters, input hashes and a methods paragraph generated from the
// run, to paste into a paper). Written by the report stage beside
// results.json, from it and the stage outputs of the subject's folder.
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

namespace articula::subject {

/// The page for `results` (results.json's document) of the subject in
/// `folder` (its errors/*.svg inlined; points.ply.json, label.nii.gz.json
/// and bone.vtp.json read for the methods, when present), with the CT
/// slices' figures and the 3-D view's section (or notes why there are none)
/// as given.
std::string subjectReportHtml(const nlohmann::json& results, const std::filesystem::path& folder,
                              const std::string& slices_html, const std::string& view_html);

}  // namespace articula::subject
