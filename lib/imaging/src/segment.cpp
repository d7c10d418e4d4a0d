// Head segmentation with ITK filters on plain buffers (see segment.hpp).
#include "articula/imaging/segment.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <itkBinaryFillholeImageFilter.h>
#include <itkBlackTopHatImageFilter.h>
#include <itkFlatStructuringElement.h>
#include <itkMorphologicalWatershedFromMarkersImageFilter.h>
#include <itkSignedMaurerDistanceMapImageFilter.h>

#include "articula/core/error.hpp"
#include "articula/core/log.hpp"
#include "itk_bridge.hpp"

namespace articula::imaging {
namespace {

using Mask = Image<std::uint8_t>;

std::string vec(const Eigen::Vector3d& v) {
  std::ostringstream s;
  s.precision(4);
  s << "(" << v[0] << ", " << v[1] << ", " << v[2] << ")";
  return s.str();
}

Mask fillHoles(const Mask& mask) {
  auto filter = itk::BinaryFillholeImageFilter<itk::Image<std::uint8_t, 3>>::New();
  filter->SetInput(toItk(mask));
  filter->SetForegroundValue(1);
  filter->FullyConnectedOff();
  filter->Update();
  return fromItk<std::uint8_t>(filter->GetOutput());
}

/// Signed Euclidean distance to the mask boundary in mm (negative inside).
Image<float> signedDistance(const Mask& mask) {
  auto filter = itk::SignedMaurerDistanceMapImageFilter<itk::Image<std::uint8_t, 3>, itk::Image<float, 3>>::New();
  filter->SetInput(toItk(mask));
  filter->SetUseImageSpacing(true);
  filter->SetSquaredDistance(false);
  filter->SetInsideIsPositive(false);
  filter->SetBackgroundValue(0);
  filter->Update();
  return fromItk<float>(filter->GetOutput());
}

/// The sub-grid [lo, hi] (inclusive voxel indices) of an image.
template <typename T>
Image<T> crop(const Image<T>& image, const Eigen::Vector3i& lo, const Eigen::Vector3i& hi) {
  Image<T> out;
  out.geometry = image.geometry;
  out.geometry.size = hi - lo + Eigen::Vector3i::Ones();
  out.geometry.origin = image.geometry.toPhysical(lo.cast<double>());
  out.voxels.resize(static_cast<size_t>(out.geometry.voxelCount()));
  for (int k = 0; k < out.geometry.size[2]; ++k)
    for (int j = 0; j < out.geometry.size[1]; ++j)
      for (int i = 0; i < out.geometry.size[0]; ++i) out.at(i, j, k) = image.at(lo[0] + i, lo[1] + j, lo[2] + k);
  return out;
}

/// Automatic head search: the deepest point of the filled bone mask, on a grid
/// of about options.search_spacing_mm, on the requested side of the
/// volume's centre, with a depth that a joint head can have.
bool findHead(const Mask& mask, const SegmentOptions& options, Eigen::Vector3d& center, double& depth) {
  const ImageGeometry& g = mask.geometry;
  Eigen::Vector3i factor;
  for (int a = 0; a < 3; ++a)
    factor[a] = std::max(1, static_cast<int>(std::lround(options.search_spacing_mm / g.spacing[a])));
  Mask coarse;
  coarse.geometry = g;
  for (int a = 0; a < 3; ++a) coarse.geometry.size[a] = (g.size[a] + factor[a] - 1) / factor[a];
  coarse.geometry.spacing = g.spacing.cwiseProduct(factor.cast<double>());
  // Block (0,0,0) covers voxels 0..f-1: its centre is at index (f-1)/2.
  coarse.geometry.origin = g.toPhysical((factor.cast<double>() - Eigen::Vector3d::Ones()) / 2.0);
  // Majority pooling: "any bone" would bridge the joint gap.
  std::vector<int> count(static_cast<size_t>(coarse.geometry.voxelCount()), 0);
  for (int k = 0; k < g.size[2]; ++k)
    for (int j = 0; j < g.size[1]; ++j)
      for (int i = 0; i < g.size[0]; ++i)
        if (mask.at(i, j, k)) ++count[static_cast<size_t>(coarse.geometry.linear(i / factor[0], j / factor[1], k / factor[2]))];
  const int block = factor.prod();
  coarse.voxels.resize(count.size());
  for (size_t n = 0; n < count.size(); ++n) coarse.voxels[n] = 2 * count[n] >= block ? 1 : 0;
  const Image<float> distance = signedDistance(fillHoles(coarse));
  const double mid_x = g.toPhysical((g.size.cast<double>() - Eigen::Vector3d::Ones()) / 2.0)[0];
  const double lo = 0.6 * options.min_head_radius_mm, hi = options.max_head_radius_mm;
  depth = 0;
  const ImageGeometry& cg = coarse.geometry;
  for (int k = 0; k < cg.size[2]; ++k)
    for (int j = 0; j < cg.size[1]; ++j)
      for (int i = 0; i < cg.size[0]; ++i) {
        const double d = -distance.at(i, j, k);
        if (d < lo || d > hi || d <= depth) continue;
        const Eigen::Vector3d x = cg.toPhysical(Eigen::Vector3d(i, j, k));
        // LPS: +x points to the patient's left.
        if ((options.side == Side::Right) != (x[0] < mid_x)) continue;
        depth = d;
        center = x;
      }
  return depth > 0;
}

/// Marker watershed on the signed distance to the bone surface: the head's
/// centre is a deep basin, and the bone bridges across the joint gap and the
/// head-neck junction are saddles where the head region stops. Markers: the
/// head core (ball of 0.85 r), far bone (beyond 1.35 r: socket, pelvis, shaft)
/// and everything outside the bone mask.
Mask watershedHead(const Image<float>& distance, const Mask& bone, const Eigen::Vector3d& center, double r) {
  const ImageGeometry& bg = bone.geometry;
  Image<unsigned> markers;
  markers.geometry = bg;
  markers.voxels.assign(bone.voxels.size(), 0);
  long long head_marker = 0;
  for (int k = 0; k < bg.size[2]; ++k)
    for (int j = 0; j < bg.size[1]; ++j)
      for (int i = 0; i < bg.size[0]; ++i) {
        const double d = (bg.toPhysical(Eigen::Vector3d(i, j, k)) - center).norm();
        unsigned& m = markers.at(i, j, k);
        if (!bone.at(i, j, k)) m = 3;
        else if (d < 0.85 * r) m = 1, ++head_marker;
        else if (d > 1.35 * r) m = 2;
      }
  if (head_marker == 0)
    throw ProcessingError("the seed " + vec(center) + " mm is not inside bone in the HU window");
  using FloatImage = itk::Image<float, 3>;
  using LabelImage = itk::Image<unsigned, 3>;
  auto watershed = itk::MorphologicalWatershedFromMarkersImageFilter<FloatImage, LabelImage>::New();
  watershed->SetInput(toItk(distance));
  watershed->SetMarkerImage(toItk(markers));
  watershed->SetMarkWatershedLine(false);
  watershed->SetFullyConnected(false);
  watershed->Update();
  const Image<unsigned> regions = fromItk<unsigned>(watershed->GetOutput());
  Mask head;
  head.geometry = bg;
  head.voxels.resize(regions.voxels.size());
  for (size_t n = 0; n < regions.voxels.size(); ++n) head.voxels[n] = regions.voxels[n] == 1 && bone.voxels[n];
  return fillHoles(head);
}

}  // namespace

void SegmentOptions::validate() const {
  if (!(hu_min < hu_max)) throw UsageError("--hu-min must be below --hu-max");
  if (roi_min.has_value() != roi_max.has_value()) throw UsageError("--roi needs both corners");
  if (roi_min && (roi_max->array() <= roi_min->array()).any())
    throw UsageError("--roi: expected xmin,ymin,zmin,xmax,ymax,zmax with min < max");
  if (!(min_head_radius_mm > 0 && min_head_radius_mm < max_head_radius_mm))
    throw UsageError("head radius range must satisfy 0 < min < max");
  if (!(search_spacing_mm > 0)) throw UsageError("search spacing must be > 0");
}

Label segmentHead(const Volume& volume, const SegmentOptions& options, SegmentSummary* summary_out) {
  options.validate();
  SegmentSummary summary;
  const ImageGeometry& g = volume.geometry;

  // 1. HU window within the ROI.
  Mask mask;
  mask.geometry = g;
  mask.voxels.assign(volume.voxels.size(), 0);
  for (int k = 0; k < g.size[2]; ++k)
    for (int j = 0; j < g.size[1]; ++j)
      for (int i = 0; i < g.size[0]; ++i) {
        const float hu = volume.at(i, j, k);
        if (hu < options.hu_min || hu > options.hu_max) continue;
        if (options.roi_min) {
          const Eigen::Vector3d x = g.toPhysical(Eigen::Vector3d(i, j, k));
          if ((x.array() < options.roi_min->array()).any() || (x.array() > options.roi_max->array()).any()) continue;
        }
        mask.at(i, j, k) = 1;
        ++summary.threshold_voxels;
      }
  if (summary.threshold_voxels == 0) {
    std::ostringstream m;
    m << "no voxel in the HU window [" << options.hu_min << ", " << options.hu_max << "]"
      << (options.roi_min ? " inside the ROI" : "") << "; is this a CT in Hounsfield units?";
    throw InputError(m.str());
  }

  // 2. The head: given, or the deepest bone on the requested side.
  double depth = 0;
  Eigen::Vector3d center;
  if (options.seed_point) {
    center = *options.seed_point;
    summary.seed_source = "seed-point";
    const Eigen::Vector3d idx = g.toIndex(center);
    if ((idx.array() < -0.5).any() || (idx.array() > g.size.cast<double>().array() - 0.5).any())
      throw InputError("--seed-point " + vec(center) + " lies outside the volume");
    depth = options.max_head_radius_mm;  // crop generously around a given seed
  } else {
    const std::string joint = options.joint == Joint::Hip ? "hip" : "shoulder";
    const std::string side = options.side == Side::Right ? "right" : "left";
    summary.seed_source = "automatic (" + joint + ", " + side + ")";
    if (!findHead(mask, options, center, depth)) {
      std::ostringstream m;
      m << "no " << (options.joint == Joint::Hip ? "femoral" : "humeral") << " head found on the " << side
        << " side: no bone deeper than " << 0.6 * options.min_head_radius_mm
        << " mm in the HU window; give --seed-point X,Y,Z (LPS mm) or adjust --hu-min";
      throw ProcessingError(m.str());
    }
    log::info("head found at " + vec(center) + " mm, depth " + std::to_string(depth) + " mm");
  }
  summary.seed_mm = center;

  // 3. Work on a box around the head that also holds the socket.
  const double half = std::max(2.2 * depth, depth + 25.0);
  Eigen::Vector3i lo = Eigen::Vector3i::Constant(1 << 30), hi = Eigen::Vector3i::Constant(-(1 << 30));
  for (int corner = 0; corner < 8; ++corner) {
    Eigen::Vector3d x = center;
    for (int a = 0; a < 3; ++a) x[a] += (corner >> a & 1) ? half : -half;
    const Eigen::Vector3d idx = g.toIndex(x);
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], static_cast<int>(std::floor(idx[a])));
      hi[a] = std::max(hi[a], static_cast<int>(std::ceil(idx[a])));
    }
  }
  lo = lo.cwiseMax(0);
  hi = hi.cwiseMin(g.size - Eigen::Vector3i::Ones());
  // The joint gap is a narrow dark valley between two bright cortices; where
  // partial volume lifts it into the HU window, the black top-hat (closing
  // minus image) finds it, and those voxels leave the bone mask.
  Mask box_raw = crop(mask, lo, hi);
  const Volume box_hu = crop(volume, lo, hi);
  if (options.gap_contrast_hu > 0) {
    using FloatImage = itk::Image<float, 3>;
    using Ball = itk::FlatStructuringElement<3>;
    Ball::RadiusType radius;
    for (unsigned a = 0; a < 3; ++a)
      radius[a] = static_cast<itk::SizeValueType>(std::max(1.0, std::ceil(options.gap_width_mm / 2 / box_hu.geometry.spacing[static_cast<int>(a)])));
    auto tophat = itk::BlackTopHatImageFilter<FloatImage, FloatImage, Ball>::New();
    tophat->SetInput(toItk(box_hu));
    tophat->SetKernel(Ball::Ball(radius));
    tophat->Update();
    const Image<float> valley = fromItk<float>(tophat->GetOutput());
    long long removed = 0;
    for (size_t n = 0; n < box_raw.voxels.size(); ++n)
      if (box_raw.voxels[n] && valley.voxels[n] > options.gap_contrast_hu && box_hu.voxels[n] < options.surface_hu)
        box_raw.voxels[n] = 0, ++removed;
    log::debug("joint-gap valley: " + std::to_string(removed) + " voxels removed from the bone mask");
  }
  const Mask box_mask = fillHoles(box_raw);
  const ImageGeometry& bg = box_mask.geometry;
  const Image<float> box_distance = signedDistance(box_mask);
  {
    // Re-centre on the deepest full-resolution bone near the search's centre:
    // the coarse grid can bridge a narrow joint gap and shift it.
    const Eigen::Vector3d start = center;
    double deepest = 0;
    for (int k = 0; k < bg.size[2]; ++k)
      for (int j = 0; j < bg.size[1]; ++j)
        for (int i = 0; i < bg.size[0]; ++i) {
          const Eigen::Vector3d x = bg.toPhysical(Eigen::Vector3d(i, j, k));
          if ((x - start).norm() < 0.5 * depth && -box_distance.at(i, j, k) > deepest) {
            deepest = -box_distance.at(i, j, k);
            center = x;
          }
        }
    if (deepest > 0) depth = deepest;
  }

  // 4-6. Watershed from markers, then re-centred once on the label's deepest
  //      point (the search's centre can sit off-centre where bone is joined).
  Mask head;
  double best = 0;
  for (int pass = 0; pass < 2; ++pass) {
    const double r = pass == 0 ? depth : best;
    if (pass == 1) center = summary.head_center_mm;
    head = watershedHead(box_distance, box_mask, center, r);
    const Image<float> head_distance = signedDistance(head);
    best = 0;
    for (int k = 0; k < bg.size[2]; ++k)
      for (int j = 0; j < bg.size[1]; ++j)
        for (int i = 0; i < bg.size[0]; ++i)
          if (-head_distance.at(i, j, k) > best) {
            best = -head_distance.at(i, j, k);
            summary.head_center_mm = bg.toPhysical(Eigen::Vector3d(i, j, k));
          }
    if (best < 0.5 * options.min_head_radius_mm) break;  // no head to re-centre on
  }
  summary.head_depth_mm = best;
  if (best < 0.5 * options.min_head_radius_mm)
    summary.warnings.push_back("the labelled head is thin (depth " + std::to_string(best) +
                               " mm): the seed may not be in a joint head");

  // The surface at the surface level (nearer half maximum than the window's
  // lower end, which sits a third of a voxel outside in partial volume).
  if (options.surface_hu > options.hu_min) {
    // Peel twice: only voxels on the label's outer layer, so the cortex keeps
    // the darker cancellous interior inside.
    for (int peel = 0; peel < 2; ++peel) {
      Mask next = head;
      for (int k = 0; k < bg.size[2]; ++k)
        for (int j = 0; j < bg.size[1]; ++j)
          for (int i = 0; i < bg.size[0]; ++i) {
            if (!head.at(i, j, k) || box_hu.at(i, j, k) >= options.surface_hu) continue;
            const bool outer = i == 0 || j == 0 || k == 0 || i + 1 == bg.size[0] || j + 1 == bg.size[1] ||
                               k + 1 == bg.size[2] || !head.at(i - 1, j, k) || !head.at(i + 1, j, k) ||
                               !head.at(i, j - 1, k) || !head.at(i, j + 1, k) || !head.at(i, j, k - 1) ||
                               !head.at(i, j, k + 1);
            if (outer) next.at(i, j, k) = 0;
          }
      head = next;
    }
  }

  Label label;
  label.geometry = g;
  label.voxels.assign(volume.voxels.size(), 0);
  for (int k = 0; k < bg.size[2]; ++k)
    for (int j = 0; j < bg.size[1]; ++j)
      for (int i = 0; i < bg.size[0]; ++i)
        if (head.at(i, j, k)) {
          label.at(lo[0] + i, lo[1] + j, lo[2] + k) = 1;
          ++summary.label_voxels;
        }
  if (summary.label_voxels == 0) throw ProcessingError("the head label is empty after separation");
  if (summary_out) *summary_out = summary;
  return label;
}

}  // namespace articula::imaging
