#include "articula/sampling/downsample.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Fuzzy_sphere.h>
#include <CGAL/Kd_tree.h>
#include <CGAL/Orthogonal_k_neighbor_search.h>
#include <CGAL/Search_traits_3.h>
#include <CGAL/Search_traits_adapter.h>
#include <CGAL/property_map.h>
#include <boost/iterator/counting_iterator.hpp>

#include "articula/core/error.hpp"

namespace articula::sampling {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
// A kd-tree over point indices, looking the coordinates up in a vector.
using PointMap = CGAL::Pointer_property_map<Point>::type;
using Traits = CGAL::Search_traits_adapter<std::size_t, PointMap, CGAL::Search_traits_3<Kernel>>;
using Tree = CGAL::Kd_tree<Traits>;
using Ball = CGAL::Fuzzy_sphere<Traits>;
using KnnSearch = CGAL::Orthogonal_k_neighbor_search<Traits>;

/// Indices of the points in the closed ball (callers make it open).
std::vector<std::size_t> withinBall(const Tree& tree, std::size_t center, double radius) {
  std::vector<std::size_t> out;
  tree.search(std::back_inserter(out), Ball(center, radius, 0.0, tree.traits()));
  return out;
}

}  // namespace

void DownsampleOptions::validate() const {
  if (!(ball_radius_mm >= 0)) throw UsageError("--ball-radius: expected a radius >= 0 mm");
  if (!(ratio > 0 && ratio <= 1)) throw UsageError("--ratio: expected a fraction in (0, 1]");
  if (!(duplicate_tolerance_mm >= 0)) throw UsageError("duplicate tolerance must be >= 0");
  if (outlier_neighbors < 1) throw UsageError("outlier neighbours must be >= 1");
  if (!(outlier_mads > 0)) throw UsageError("outlier threshold must be > 0");
}

std::vector<int> gaussianDownsample(const Eigen::MatrixX3d& P, const DownsampleOptions& o, DownsampleSummary* summary_out) {
  o.validate();
  DownsampleSummary summary;
  const std::size_t n = static_cast<std::size_t>(P.rows());
  summary.original = static_cast<long long>(n);
  std::vector<Point> points(n);
  for (std::size_t i = 0; i < n; ++i) points[i] = Point(P(static_cast<Eigen::Index>(i), 0), P(static_cast<Eigen::Index>(i), 1), P(static_cast<Eigen::Index>(i), 2));
  const PointMap map(points.data());
  Tree tree(boost::counting_iterator<std::size_t>(0), boost::counting_iterator<std::size_t>(n), Tree::Splitter(),
            Traits(map));
  tree.build();
  std::vector<char> removed(n, 0);

  // Duplicates: keep the first of every cluster within the tolerance.
  for (std::size_t i = 0; i < n; ++i) {
    if (removed[i]) continue;
    for (std::size_t j : withinBall(tree, i, o.duplicate_tolerance_mm))
      if (j > i && !removed[j] && CGAL::squared_distance(points[i], points[j]) <= o.duplicate_tolerance_mm * o.duplicate_tolerance_mm)
        removed[j] = 1, ++summary.duplicates;
  }
  // Outliers: mean distance to the k nearest neighbours far above the median
  // (robust scale: 1.4826 x median absolute deviation).
  if (o.remove_outliers && n > static_cast<std::size_t>(o.outlier_neighbors) + 1) {
    std::vector<double> mean_knn(n, 0.0);
    for (std::size_t i = 0; i < n; ++i) {
      KnnSearch search(tree, points[i], static_cast<unsigned>(o.outlier_neighbors + 1), 0, true, KnnSearch::Distance(map));
      double sum = 0;
      int count = 0;
      for (const auto& hit : search)
        if (hit.first != i) sum += std::sqrt(hit.second), ++count;
      mean_knn[i] = count ? sum / count : 0.0;
    }
    std::vector<double> sorted = mean_knn;
    std::nth_element(sorted.begin(), sorted.begin() + static_cast<long>(n / 2), sorted.end());
    const double median = sorted[n / 2];
    for (double& d : sorted) d = std::fabs(d - median);
    std::nth_element(sorted.begin(), sorted.begin() + static_cast<long>(n / 2), sorted.end());
    const double scale = std::max(1.4826 * sorted[n / 2], 1e-9 + 0.05 * median);
    for (std::size_t i = 0; i < n; ++i)
      if (!removed[i] && mean_knn[i] > median + o.outlier_mads * scale) removed[i] = 1, ++summary.outliers;
  }

  // The open-ball sampling: a random order of the points is the same as
  // drawing uniformly among those still left at every step.
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::mt19937_64 rng(o.seed);
  std::shuffle(order.begin(), order.end(), rng);
  const long long target = static_cast<long long>(std::ceil(o.ratio * static_cast<double>(n)));
  std::vector<int> kept;
  summary.termination = "no point left";
  for (std::size_t i : order) {
    if (removed[i]) continue;
    if (o.ratio < 1.0 && static_cast<long long>(kept.size()) >= target) {
      summary.termination = "ratio reached";
      break;
    }
    kept.push_back(static_cast<int>(i));
    removed[i] = 1;
    if (o.ball_radius_mm > 0)
      for (std::size_t j : withinBall(tree, i, o.ball_radius_mm))
        if (CGAL::squared_distance(points[i], points[j]) < o.ball_radius_mm * o.ball_radius_mm) removed[j] = 1;  // open ball
  }
  summary.reduced = static_cast<long long>(kept.size());
  if (summary_out) *summary_out = summary;
  return kept;
}

}  // namespace articula::sampling
