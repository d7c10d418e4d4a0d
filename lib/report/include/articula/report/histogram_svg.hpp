#pragma once
// Histograms of signed distances with their fitted Gaussians (thesis fig. 3.5).
#include <string>
#include <vector>

#include <Eigen/Core>

namespace articula::report {

struct Histogram {
  double lower = 0.0, bin_width = 1.0;  // mm
  std::vector<long> counts;
};

/// Counts of `d` in `bins` equal bins over [lower, upper] (values outside are
/// clamped into the end bins).
Histogram histogram(const Eigen::VectorXd& d, double lower, double upper, int bins);

struct Series {
  std::string label;
  Eigen::VectorXd values;  // signed distances (mm)
  double mu = 0.0, sigma = 0.0;
};

/// An SVG document: one step histogram per series on shared bins (sqrt(N) of
/// them over the common range), each with its Gaussian N(mu, sigma) scaled
/// to counts; axes with ticks, units and a legend.
std::string histogramSvg(const std::vector<Series>& series, const std::string& title);

}  // namespace articula::report
