#pragma once
// What the scanner and its reconstruction do to the phantom's tissues, on
// the voxel grid: blur, the reconstruction kernel, and the field of view's
// crop. Hand-written so that this module stays free of ITK.
#include <functional>

#include <Eigen/Core>

#include "articula/imaging/image.hpp"

namespace articula::phantom::detail {

/// Separable Gaussian blur of an i-fastest buffer, sigma in mm per index
/// axis (an axis whose sigma is under 0.1 voxel is left as it is).
void blur(imaging::Volume& v, const Eigen::Vector3d& sigma_mm);

/// Unsharp masking within the slices (index axes 0 and 1):
/// v + gain (v - G_sigma v), an overshoot on either side of each edge.
void sharpenInPlane(imaging::Volume& v, double sigma_mm, double gain);

/// Metal artefacts, slice by slice across index axis 2 (axial slices):
/// beam-hardening and photon-starvation streaks as a simple model, not a
/// reconstruction. In each slice with metal (voxel centres where is_metal),
/// twelve lines at seeded angles through seeded metal voxels, each adding
/// +-150-500 HU (scaled by the slice's metal area up to 30 mm^2) over a
/// Gaussian profile 0.7 mm wide that fades over 60 mm; and dark bands of
/// 200-500 HU, as wide as the metal, along each metal part's long axis
/// (where it is 1.5 times longer than wide) and along the line joining two
/// parts, fading over 30 mm beyond them.
void addMetalStreaks(imaging::Volume& v, const std::function<bool(const Eigen::Vector3d&)>& is_metal,
                     unsigned long long seed);

/// Clips to a scanner's range: 12-bit CT stores -1024 to 3071 HU.
void clipToScannerRange(imaging::Volume& v);

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
