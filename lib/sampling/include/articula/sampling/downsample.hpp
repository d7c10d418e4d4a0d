#pragma once
// Gaussian (open-ball) down-sampling of thesis section 3.2.3 with duplicate
// and outlier removal first: pick a point at random (seeded), keep it, drop
// every point within the open ball of radius r around it, repeat until the
// kept fraction reaches the ratio or no point is left (table 3.1).
#include <string>
#include <vector>

#include <Eigen/Core>

namespace articula::sampling {

struct DownsampleOptions {
  double ball_radius_mm = 1.0;       // open ball radius r
  double ratio = 1.0;                // stop when kept / original >= ratio (1: until no point is left)
  unsigned long long seed = 42;
  double duplicate_tolerance_mm = 1e-6;
  bool remove_outliers = true;
  int outlier_neighbors = 8;         // k of the mean k-nearest-neighbour distance
  double outlier_mads = 6.0;         // outlier: mean kNN distance > median + this many scaled MADs
  /// Throws UsageError naming the first invalid option.
  void validate() const;
};

struct DownsampleSummary {
  long long original = 0, duplicates = 0, outliers = 0, reduced = 0;
  std::string termination;           // "ratio reached" or "no point left"
};

/// Row indices into P (#P x 3, mm) of the kept points, in the order picked.
std::vector<int> gaussianDownsample(const Eigen::MatrixX3d& P, const DownsampleOptions& options,
                                    DownsampleSummary* summary = nullptr);

}  // namespace articula::sampling
