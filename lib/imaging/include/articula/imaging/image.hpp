#pragma once
// A 3-D image as a plain buffer with its physical geometry, the currency
// between modules (ITK stays inside lib/imaging, VTK inside lib/mesh).
// Voxel (i, j, k) sits at x = origin + direction * diag(spacing) * (i, j, k)^T
// in LPS millimetres, exactly as ITK's TransformIndexToPhysicalPoint.
#include <cstdint>
#include <vector>

// All of the system Eigen (3.4): ITK bundles Eigen 3.3.9 under the same
// include guards, so the modules must be defined before any ITK header.
#include <Eigen/Dense>

namespace articula::imaging {

struct ImageGeometry {
  Eigen::Vector3i size = Eigen::Vector3i::Zero();              // voxels along i, j, k
  Eigen::Vector3d spacing = Eigen::Vector3d::Ones();           // mm
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();            // LPS mm of voxel (0,0,0)
  Eigen::Matrix3d direction = Eigen::Matrix3d::Identity();     // columns: i, j, k axes in LPS
  /// The slices' own extent along k where it is not their spacing (a DICOM
  /// series' Slice Thickness, 0018,0050: slices reconstructed thicker than
  /// their spacing overlap); 0: the spacing.
  double slice_thickness_mm = 0;

  /// What one voxel averages over along each axis: its spacing, and
  /// across the slices their thickness where it is known.
  Eigen::Vector3d voxelExtent() const {
    Eigen::Vector3d extent = spacing;
    if (slice_thickness_mm > 0) extent[2] = slice_thickness_mm;
    return extent;
  }
  long long voxelCount() const { return static_cast<long long>(size[0]) * size[1] * size[2]; }
  /// Linear index with i fastest (ITK and VTK buffer order).
  long long linear(int i, int j, int k) const {
    return i + static_cast<long long>(size[0]) * (j + static_cast<long long>(size[1]) * k);
  }
  /// Physical LPS point of a (continuous) index.
  Eigen::Vector3d toPhysical(const Eigen::Vector3d& ijk) const {
    return origin + direction * spacing.asDiagonal() * ijk;
  }
  /// Continuous index of a physical LPS point.
  Eigen::Vector3d toIndex(const Eigen::Vector3d& x) const {
    return spacing.cwiseInverse().asDiagonal() * (direction.inverse() * (x - origin));
  }
};

template <typename T>
struct Image {
  ImageGeometry geometry;
  std::vector<T> voxels;  // #voxels, i fastest
  T& at(int i, int j, int k) { return voxels[static_cast<size_t>(geometry.linear(i, j, k))]; }
  const T& at(int i, int j, int k) const { return voxels[static_cast<size_t>(geometry.linear(i, j, k))]; }
};

using Volume = Image<float>;        // CT in Hounsfield units
using Label = Image<std::uint8_t>;  // 0 background, else bone of interest
/// A label's values: bone of interest, and such a voxel on the segmentation's
/// cut through bone (bordering bone the label does not hold, as where the
/// head was cut from its neck). Every value but 0 is the bone's.
constexpr std::uint8_t kLabelBone = 1, kLabelCutThroughBone = 2;

}  // namespace articula::imaging
