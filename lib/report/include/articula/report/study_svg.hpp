#pragma once
// The study figure: how the fit error falls along the model hierarchy, subject
// by subject.
#include <string>
#include <vector>

#include <Eigen/Core>

namespace articula::report {

struct StudyRms {
  std::vector<std::string> subjects;  // #S
  std::vector<std::string> models;    // #M, in hierarchy order (the x axis)
  Eigen::MatrixXd rms_mm;             // #S x #M; NaN where a subject lacks a model
};

/// An SVG document: for each subject a grey line through its RMS per model
/// (paired across models; broken where a value is missing), its least-RMS
/// model drawn as a filled dot; the per-model mean over the subjects that
/// have it as a black bar joined by a thick line, labelled with its value;
/// axes "model" and "RMS of the signed distances (mm)" from 0. Every dot and
/// mean has a <title> ("s01 sphere: 0.123 mm", "mean sphere: 0.2 mm (3
/// subjects)") that a browser shows on hover; each subject's marks are one
/// <g class="subject">. Throws InputError when there is no subject or model or
/// rms_mm is not #S x #M.
std::string studyRmsSvg(const StudyRms& study, const std::string& title);

}  // namespace articula::report
