#pragma once
// Maps of the signed distances over the articular surface (thesis fig. 3.4,
// flattened: one small map per model, on one colour scale).
#include <string>
#include <vector>

#include <Eigen/Core>

#include "articula/report/azimuthal_map.hpp"

namespace articula::report {

struct ErrorMapPanel {
  std::string label;   // the model's name
  Eigen::VectorXd d;   // #P signed distances (mm), negative inside, in the map's point order
};

/// The colour scale's limit an error map takes by default: the 98th
/// percentile of |d| over all panels, rounded up to 1, 1.5, 2, 2.5, 3, 4, 5,
/// 6 or 8 x 10^k (the report's 3-D view and Slicer scene use it too, so that
/// one colour means one distance on every figure of a subject).
double sharedColourLimit(const std::vector<ErrorMapPanel>& panels);

struct ErrorMapOptions {
  double limit_mm = 0.0;   // colour scale -limit .. +limit; 0: the 98th percentile of |d| over
                           // all panels, rounded up to 1, 1.5, 2, 2.5, 3, 4, 5, 6 or 8 x 10^k
  int max_points = 2000;   // points drawn per panel: every k-th, k = ceil(#P / max_points)
  std::string highlight;   // the label of the panel to mark as "least RMS" (may be empty)
  /// Throws InvalidParameter for a negative limit or max_points < 1.
  void validate() const;
};

/// An SVG document: one map panel per entry of `panels`, each point of `map`
/// drawn as a dot coloured by its signed distance on divergingColour(d / limit),
/// quantised to 21 steps of limit / 10 (values beyond the limit take the end
/// colours); dots with larger |d| are drawn on top. Each panel has axes in mm,
/// a cross on the axis and a dashed circle 90 degrees from it; a colour bar in
/// mm ("colour-bar" group, data-limit-mm) and a caption giving the axis, the
/// centre and the map's right/up directions in LPS. Dots are zero-length
/// round-capped path segments ("M x y h0"), grouped by colour in <path
/// class="pts">, to keep thousands of points small.
/// Throws InputError if `panels` is empty or a panel's d does not have one
/// value per point.
std::string errorMapSvg(const AzimuthalMap& map, const std::vector<ErrorMapPanel>& panels,
                        const ErrorMapOptions& options, const std::string& title);

}  // namespace articula::report
