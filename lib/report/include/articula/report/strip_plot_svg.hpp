#pragma once
// One quantity across the subjects of a study: a dot per subject on one
// axis, a lane per group (a joint and side), each dot a link to the
// subject's page, for study.html.
#include <string>
#include <vector>

namespace articula::report {

struct StripPoint {
  std::string label;  // the subject, shown on hover with its value
  double value = 0;   // NaN: left out
  std::string link;   // relative address of the subject's page ("" : no link)
  std::string group;  // its lane ("hip, right"); one lane when every group is ""
  std::string flag;   // "" or the checks' verdict ("warn", "fail"): a ringed, coloured dot
};

/// An SVG document 700 px wide: the points on a horizontal axis with "nice"
/// ticks labelled in `unit` (one axis for every lane, so lanes compare), a
/// lane per group in order of first appearance, labelled at its left; in a
/// lane the dots are spread vertically by their order so that equal values
/// stay apart. Each dot is an <a href> around a <circle> with a <title>
/// ("s01: 22.7 mm", and "(checks: warn)" when flagged). A note instead of
/// the axis when no value is finite.
std::string stripPlotSvg(const std::string& title, const std::string& unit, const std::vector<StripPoint>& points);

}  // namespace articula::report
