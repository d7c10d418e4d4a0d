#pragma once
// Line charts of time series (simulation outputs: trajectories, contact
// forces, integrator step sizes), hand-written SVG as the other figures.
#include <string>
#include <vector>

namespace articula::report {

struct LineSeries {
  std::string label;
  std::vector<double> x, y;  // same length; NaN breaks the line
};

struct LineChart {
  std::string title, x_label, y_label;  // labels with their units
  bool log_y = false;                   // logarithmic y axis (positive values only)
};

/// An SVG document: every series as a polyline over shared axes with ticks
/// and a legend. Throws InvalidParameter if a series' x and y differ in length.
std::string lineChartSvg(const std::vector<LineSeries>& series, const LineChart& chart);

}  // namespace articula::report
