#pragma once
// Segmentation of one joint head (femoral or humeral) from a CT volume:
// HU threshold, optional ROI, closing and hole filling, automatic head
// finding (a Hough transform for spheres on the chosen side, ~2 mm grid,
// whose candidates are measured by rays at full resolution: the sphere
// through the first bone edges seen from inside), the bone beyond those
// edges cut off (gap and socket, however narrow the gap), then a marker
// watershed on the distance to the bone surface, which cuts the head from
// the neck at its narrowest; the head's surface at a HU level or,
// optionally, by a geodesic active contour.
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
  bool one_bone = false;  // the CT holds one bone only (keepLabelledBone): its side is the label's, not judged by position
  Joint joint = Joint::Hip;
  Side side = Side::Right;                          // patient side (LPS: right is -x)
  double min_head_radius_mm = 15.0;                 // plausible joint heads
  double max_head_radius_mm = 35.0;
  double search_spacing_mm = 2.0;                   // grid of the automatic head search
  double close_radius_mm = 5.0;  // closing before hole filling: bridges speckled cancellous bone (0: off)
  double min_coverage = 0.15;       // least share of a found head's sphere that is bone surface
  // A found head lies this far from the volume's mid-sagittal plane; -1:
  // automatic, 40 mm when the field of view spans 250 mm or more left-right
  // (both sides of the body: never the spine), else 0.
  double midline_margin_mm = -1;
  double gap_width_mm = 4.0;     // widest joint gap the valley filter closes
  double gap_contrast_hu = 300;  // black top-hat above which a voxel is gap, not bone (0: off)
  double surface_hu = 400;       // level of the head's final surface (<= hu_min: the window's end)
  int level_set_iterations = 0;  // > 0: the surface by a geodesic active contour instead of surface_hu
  /// Throws UsageError naming the first invalid option.
  void validate() const;
};

struct SegmentSummary {
  std::string seed_source;                  // "seed-point" or "automatic (joint, side)"
  std::string side_check;                   // automatic: how the side was established, or "not verified"
  std::optional<double> body_middle_x_mm;   // automatic: the body's middle (LPS x) the side was judged by
  std::string body_middle_from;             // "outline" or "field of view" (a wide one), with body_middle_x_mm
  std::string head_found_by;                // "edges" (a sphere through bone edges along rays), "surface voxels"
                                            // (automatic, no such sphere: the voxels facing a centre), "seed point"
  Eigen::Vector3d seed_mm = Eigen::Vector3d::Zero();
  // Automatic search: the centre of the head's sphere; with a seed point:
  // the deepest point of the label.
  Eigen::Vector3d head_center_mm = Eigen::Vector3d::Zero();
  double search_radius_mm = 0;              // the automatic search's sphere radius (0 with a seed point)
  double head_depth_mm = 0;                 // deepest label point's distance to the label surface
  // The sphere through the head's CT edges seen from its centre (0 when a
  // seed point gave no plausible sphere): share of rays with an edge on it, RMS.
  double edge_coverage = 0, edge_rms_mm = 0;
  long long threshold_voxels = 0;           // voxels in the HU window (within the ROI)
  long long label_voxels = 0;
  long long cut_through_bone_voxels = 0;    // of label_voxels, those labelled kLabelCutThroughBone
  double noise_hu = 0;                      // the CT's noise voxel to voxel (imaging/noise.hpp; 0 with one_bone)
  double smoothed_sigma_mm = 0;             // the Gaussian the head was segmented after (0: none, the CT as read)
  std::vector<std::string> warnings;
};

/// Labels the joint head (with whatever of its neck the watershed keeps) in
/// the volume's own grid: kLabelBone, or kLabelCutThroughBone on its cut.
/// A CT noisier than kSmoothSegmentationAboveNoiseHu (imaging/noise.hpp) is
/// searched and labelled on a copy smoothed by an in-plane voxel.
/// Throws ProcessingError (exit 1) if no head is found and InputError if the
/// window holds no voxel.
Label segmentHead(const Volume& volume, const SegmentOptions& options, SegmentSummary* summary = nullptr);

}  // namespace articula::imaging
