#pragma once
// Segmentation of one joint head (femoral or humeral) from a CT volume:
// HU threshold, optional ROI, hole filling, automatic head finding (the
// deepest bone point on the chosen side, on a ~2 mm grid), then a marker
// watershed on the distance to the bone surface, which cuts the head from
// the socket and the neck at the narrow bone bridges between them.
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "articula/imaging/image.hpp"

namespace articula::imaging {

enum class Joint { Hip, Shoulder };
enum class Side { Left, Right };

struct SegmentOptions {
  double hu_min = 200.0;  // bone window (HU)
  double hu_max = 3000.0;
  std::optional<Eigen::Vector3d> roi_min, roi_max;  // LPS mm box; both or neither
  std::optional<Eigen::Vector3d> seed_point;        // LPS mm, inside the head; else automatic
  Joint joint = Joint::Hip;
  Side side = Side::Right;                          // patient side (LPS: right is -x)
  double min_head_radius_mm = 15.0;                 // plausible joint heads
  double max_head_radius_mm = 35.0;
  double search_spacing_mm = 2.0;                   // grid of the automatic head search
  double gap_width_mm = 4.0;     // widest joint gap the valley filter closes
  double gap_contrast_hu = 300;  // black top-hat above which a voxel is gap, not bone (0: off)
  double surface_hu = 400;       // level of the head's final surface (<= hu_min: the window's end)
  /// Throws UsageError naming the first invalid option.
  void validate() const;
};

struct SegmentSummary {
  std::string seed_source;                  // "seed-point" or "automatic (joint, side)"
  Eigen::Vector3d seed_mm = Eigen::Vector3d::Zero();
  Eigen::Vector3d head_center_mm = Eigen::Vector3d::Zero();  // deepest point of the label
  double head_depth_mm = 0;                 // its distance to the label surface (~ head radius)
  long long threshold_voxels = 0;           // voxels in the HU window (within the ROI)
  long long label_voxels = 0;
  std::vector<std::string> warnings;
};

/// Labels the joint head (with whatever of its neck the watershed keeps) as 1
/// in the volume's own grid. Throws ProcessingError (exit 1) if no head is
/// found and InputError if the window holds no voxel.
Label segmentHead(const Volume& volume, const SegmentOptions& options, SegmentSummary* summary = nullptr);

}  // namespace articula::imaging
