#pragma once
// One quantity across the subjects of a study: a dot per subject on one
// axis, each dot a link to the subject's page, for study.html.
#include <string>
#include <vector>

namespace articula::report {

struct StripPoint {
  std::string label;  // the subject, shown on hover with its value
  double value = 0;   // NaN: left out
  std::string link;   // relative address of the subject's page ("" : no link)
};

/// An SVG document (700 x 90 px): the points on a horizontal axis with
/// "nice" ticks labelled in `unit`, spread vertically by their order so that
/// equal values stay apart; each dot is an <a href> around a <circle> with a
/// <title> ("s01: 22.7 mm"). A note instead of the axis when no value is finite.
std::string stripPlotSvg(const std::string& title, const std::string& unit, const std::vector<StripPoint>& points);

}  // namespace articula::report
