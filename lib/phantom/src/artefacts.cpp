#include "artefacts.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace articula::phantom::detail {

void blur(imaging::Volume& v, const Eigen::Vector3d& sigma_mm) {
  const imaging::ImageGeometry& g = v.geometry;
  for (int axis = 0; axis < 3; ++axis) {
    const double s = sigma_mm[axis] / g.spacing[axis];
    if (s < 0.1) continue;
    const int r = static_cast<int>(std::ceil(3 * s));
    std::vector<double> w(static_cast<size_t>(2 * r + 1));
    double sum = 0;
    for (int t = -r; t <= r; ++t) sum += w[static_cast<size_t>(t + r)] = std::exp(-0.5 * t * t / (s * s));
    for (double& x : w) x /= sum;
    const long long stride = axis == 0 ? 1 : axis == 1 ? g.size[0] : static_cast<long long>(g.size[0]) * g.size[1];
    const int n = g.size[axis];
    std::vector<float> line(static_cast<size_t>(n));
    for (long long start = 0; start < g.voxelCount(); ++start) {
      // Visit each line once, from its first voxel.
      if ((start / stride) % n != 0) continue;
      for (int t = 0; t < n; ++t) line[static_cast<size_t>(t)] = v.voxels[static_cast<size_t>(start + t * stride)];
      for (int t = 0; t < n; ++t) {
        double acc = 0;
        for (int q = -r; q <= r; ++q) acc += w[static_cast<size_t>(q + r)] * line[static_cast<size_t>(std::clamp(t + q, 0, n - 1))];
        v.voxels[static_cast<size_t>(start + t * stride)] = static_cast<float>(acc);
      }
    }
  }
}

}  // namespace articula::phantom::detail
