#pragma once
// What the scanner and its reconstruction do to the phantom's tissues, on
// the voxel grid: blur, the reconstruction kernel, and the field of view's
// crop. Hand-written so that this module stays free of ITK.
#include <Eigen/Core>

#include "articula/imaging/image.hpp"

namespace articula::phantom::detail {

/// Separable Gaussian blur of an i-fastest buffer, sigma in mm per index
/// axis (an axis whose sigma is under 0.1 voxel is left as it is).
void blur(imaging::Volume& v, const Eigen::Vector3d& sigma_mm);

/// The sub-grid of `image` keeping the indices [lo, hi] along index axis `axis`.
template <typename T>
imaging::Image<T> cropAxis(const imaging::Image<T>& image, int axis, int lo, int hi) {
  imaging::Image<T> out;
  out.geometry = image.geometry;
  Eigen::Vector3d first = Eigen::Vector3d::Zero();
  first[axis] = lo;
  out.geometry.origin = image.geometry.toPhysical(first);
  out.geometry.size[axis] = hi - lo + 1;
  out.voxels.resize(static_cast<size_t>(out.geometry.voxelCount()));
  const Eigen::Vector3i& n = out.geometry.size;
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i) {
        Eigen::Vector3i from(i, j, k);
        from[axis] += lo;
        out.at(i, j, k) = image.at(from[0], from[1], from[2]);
      }
  return out;
}

}  // namespace articula::phantom::detail
