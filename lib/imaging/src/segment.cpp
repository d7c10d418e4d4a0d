// Head segmentation with ITK filters on plain buffers (see segment.hpp).
#include "articula/imaging/segment.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <sstream>

#include <itkBinaryFillholeImageFilter.h>
#include <itkBinaryMorphologicalClosingImageFilter.h>
#include <itkBlackTopHatImageFilter.h>
#include <itkFlatStructuringElement.h>
#include <itkGeodesicActiveContourLevelSetImageFilter.h>
#include <itkGradientMagnitudeRecursiveGaussianImageFilter.h>
#include <itkMorphologicalWatershedFromMarkersImageFilter.h>
#include <itkSigmoidImageFilter.h>
#include <itkSignedMaurerDistanceMapImageFilter.h>

#include "articula/core/error.hpp"
#include "articula/core/log.hpp"
#include "articula/imaging/noise.hpp"
#include "head_search.hpp"
#include "itk_bridge.hpp"

namespace articula::imaging {
namespace {

using namespace detail;

using Mask = Image<std::uint8_t>;


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

/// Morphological closing with a ball of `radius_mm`: bridges the speckled
/// cancellous bone and thin cortex of real CT, so that hole filling can fill
/// the head's interior.
Mask close(const Mask& mask, double radius_mm) {
  if (radius_mm <= 0) return mask;
  using Ball = itk::FlatStructuringElement<3>;
  Ball::RadiusType radius;
  for (unsigned a = 0; a < 3; ++a)
    radius[a] = static_cast<itk::SizeValueType>(std::max(1.0, std::round(radius_mm / mask.geometry.spacing[static_cast<int>(a)])));
  auto filter = itk::BinaryMorphologicalClosingImageFilter<itk::Image<std::uint8_t, 3>, itk::Image<std::uint8_t, 3>, Ball>::New();
  filter->SetInput(toItk(mask));
  filter->SetKernel(Ball::Ball(radius));
  filter->SetForegroundValue(1);
  filter->SetSafeBorder(true);  // the volume's edge is not bone
  filter->Update();
  return fromItk<std::uint8_t>(filter->GetOutput());
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
  // A head is a solid: closing with a ball of a third of its radius bridges
  // the gaps of a thin or porous cortex (osteoporotic or lossy-compressed
  // bone falls below the window), so that its interior fills. Its convex
  // articular surface is left as it is.
  return fillHoles(close(head, r / 3));
}

/// Median of the values of `image` where `where` holds.
double medianWhere(const Image<float>& image, const std::vector<char>& where) {
  std::vector<float> v;
  for (size_t n = 0; n < where.size(); ++n)
    if (where[n]) v.push_back(image.voxels[n]);
  if (v.empty()) return 0;
  std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

/// Geodesic active contour (Caselles et al. 1997; the "snake" of ITK-SNAP
/// the thesis used), started from the head label: it pulls the surface onto
/// the strongest HU edge nearby and smooths it. The edge map is a sigmoid of
/// the gradient magnitude scaled by the label's own statistics (the median
/// gradient on its boundary is an edge, the median inside is not). The result
/// stays within two voxels of the label, so it cannot leak across the gap.
Mask refineByLevelSet(const Volume& hu, const Mask& head, int iterations) {
  using FloatImage = itk::Image<float, 3>;
  const ImageGeometry& g = hu.geometry;
  auto gradient = itk::GradientMagnitudeRecursiveGaussianImageFilter<FloatImage, FloatImage>::New();
  gradient->SetInput(toItk(hu));
  gradient->SetSigma(g.spacing.minCoeff());
  gradient->Update();
  const Image<float> magnitude = fromItk<float>(gradient->GetOutput());
  const Image<float> initial = signedDistance(head);  // mm, negative inside
  const double voxel = g.spacing.maxCoeff();
  std::vector<char> boundary(head.voxels.size()), interior(head.voxels.size());
  for (size_t n = 0; n < head.voxels.size(); ++n) {
    boundary[n] = std::abs(initial.voxels[n]) <= voxel;
    interior[n] = initial.voxels[n] < -3 * voxel;
  }
  const double edge = medianWhere(magnitude, boundary), flat = medianWhere(magnitude, interior);
  if (!(edge > flat)) return head;  // no edge to snap to
  auto sigmoid = itk::SigmoidImageFilter<FloatImage, FloatImage>::New();
  sigmoid->SetInput(gradient->GetOutput());
  sigmoid->SetOutputMinimum(0.0f);
  sigmoid->SetOutputMaximum(1.0f);
  sigmoid->SetAlpha(-(edge - flat) / 6.0);  // the ITK guide's choice: ~0 on edges, ~1 inside
  sigmoid->SetBeta((edge + flat) / 2.0);
  auto contour = itk::GeodesicActiveContourLevelSetImageFilter<FloatImage, FloatImage>::New();
  contour->SetInput(toItk(initial));
  contour->SetFeatureImage(sigmoid->GetOutput());
  contour->SetPropagationScaling(0.0);
  contour->SetCurvatureScaling(0.5);
  contour->SetAdvectionScaling(1.0);
  contour->SetMaximumRMSError(0.002);
  contour->SetNumberOfIterations(static_cast<itk::IdentifierType>(iterations));
  contour->Update();
  const Image<float> phi = fromItk<float>(contour->GetOutput());
  Mask out = head;
  for (size_t n = 0; n < out.voxels.size(); ++n) {
    const float d = initial.voxels[n];
    out.voxels[n] = d < -2 * voxel || (d <= 2 * voxel && phi.voxels[n] < 0) ? 1 : 0;
  }
  log::debug("level set: " + std::to_string(contour->GetElapsedIterations()) + " iterations, RMS change " +
             std::to_string(contour->GetRMSChange()) + ", edge " + std::to_string(edge) + " HU/mm, flat " +
             std::to_string(flat) + " HU/mm");
  return fillHoles(out);
}

}  // namespace

void SegmentOptions::validate() const {
  // Ranges that keep the work bounded: joint heads are 15-35 mm in radius
  // (60 mm leaves room for any animal or implant study), the closing and the
  // gap filter act on millimetres, the search grid on a few voxels.
  const auto range = [](double v, double lo, double hi, const std::string& what) {
    if (!(v >= lo && v <= hi)) {
      std::ostringstream m;
      m << what << ": expected " << lo << " to " << hi << ", found " << v;
      throw UsageError(m.str());
    }
  };
  range(hu_min, -2000, 10000, "--hu-min (HU)");
  range(hu_max, -2000, 40000, "--hu-max (HU)");
  if (!(hu_min < hu_max)) throw UsageError("--hu-min must be below --hu-max");
  range(surface_hu, -2000, 40000, "--surface-hu (HU)");
  if (roi_min.has_value() != roi_max.has_value()) throw UsageError("--roi needs both corners");
  if (roi_min && (roi_max->array() <= roi_min->array()).any())
    throw UsageError("--roi: expected xmin,ymin,zmin,xmax,ymax,zmax with min < max");
  range(min_head_radius_mm, 1, 60, "--min-radius (mm)");
  range(max_head_radius_mm, 1, 60, "--max-radius (mm)");
  if (!(min_head_radius_mm < max_head_radius_mm)) throw UsageError("head radius range must satisfy min < max");
  range(search_spacing_mm, 0.5, 10, "search spacing (mm)");
  range(close_radius_mm, 0, 20, "--close-radius (mm)");
  range(gap_width_mm, 0.5, 20, "joint gap width (mm)");
  if (level_set_iterations < 0 || level_set_iterations > 10000) throw UsageError("--level-set: expected 0 to 10000 iterations");
  if (!(midline_margin_mm == -1)) range(midline_margin_mm, 0, 500, "--midline-margin (mm; -1: automatic)");
  range(min_coverage, 0, 1, "--min-coverage");
}

namespace {
Label segmentHeadIn(const Volume& volume, const SegmentOptions& options, SegmentSummary& summary);
}  // namespace

Label segmentHead(const Volume& ct, const SegmentOptions& options, SegmentSummary* summary_out) {
  options.validate();
  SegmentSummary summary;
  // With an outside label the CT outside its bone is air: no soft tissue
  // to measure (and its marrow's texture is no noise), so none is measured.
  if (!options.one_bone) summary.noise_hu = noiseHu(ct);
  log::debug("the CT's noise voxel to voxel: " + std::to_string(summary.noise_hu) + " HU");
  // A noisy CT (low dose, a sharp kernel) is segmented on a copy smoothed by
  // an in-plane voxel: the label only has to hold the head, whose surface the
  // mesh stage places on the CT's own voxels.
  std::optional<Volume> calm;
  if (summary.noise_hu > kSmoothSegmentationAboveNoiseHu) {
    summary.smoothed_sigma_mm = std::max(ct.geometry.spacing[0], ct.geometry.spacing[1]);
    calm = smoothed(ct, summary.smoothed_sigma_mm);
    std::ostringstream m;
    m << "the CT's noise is about " << std::lround(summary.noise_hu) << " HU voxel to voxel (a low dose or a sharp "
      << "kernel; over " << kSmoothSegmentationAboveNoiseHu << " HU): the head was searched and labelled on a copy "
      << "smoothed by a Gaussian of " << summary.smoothed_sigma_mm << " mm, its surface placed on the CT's own voxels";
    log::warn(m.str());  // the report's check ct_noise_hu says it too
  }
  Label label = segmentHeadIn(calm ? *calm : ct, options, summary);
  if (summary_out) *summary_out = summary;
  return label;
}

namespace {

Label segmentHeadIn(const Volume& volume, const SegmentOptions& options, SegmentSummary& summary) {
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

  // 2. The head: measured from the seed point, or searched on the requested side.
  double depth = 0;
  Eigen::Vector3d center;
  HeadCandidate head_found;
  bool measured = false;  // a sphere through the head's edges (its rays cut the socket off)
  if (options.seed_point) {
    center = *options.seed_point;
    summary.seed_source = "seed-point";
    if (!insideVolume(g, center))
      throw InputError("--seed-point " + vec(center) + " lies outside the volume");
    depth = options.max_head_radius_mm;  // crop generously around a given seed
    head_found = measureHeadByRays(volume, center, options);
    measured = head_found.radius >= options.min_head_radius_mm && head_found.radius <= options.max_head_radius_mm &&
               head_found.coverage >= options.min_coverage && head_found.wellMeasured(g.spacing.maxCoeff()) &&
               (head_found.center - center).norm() <= head_found.radius;
    if (measured) center = head_found.center, depth = head_found.radius;
  } else {
    const std::string joint = options.joint == Joint::Hip ? "hip" : "shoulder";
    const std::string side = options.side == Side::Right ? "right" : "left";
    summary.seed_source = "automatic (" + joint + ", " + side + ")";
    SideCheck side_check;
    std::optional<HeadCandidate> outside_range;
    const bool found = findHead(volume, options, head_found, side_check, &outside_range);
    std::string passed_over;  // a sphere outside the radius range the search passed over, named
    if (outside_range && (!found || outside_range->area() > head_found.area())) {
      std::ostringstream m;
      m << "a spherical bone edge of radius " << std::lround(outside_range->radius * 10) / 10.0 << " mm at "
        << vec(outside_range->center) << " mm, edges on " << std::lround(100 * outside_range->coverage)
        << " % of its rays" << (found ? " (more bone surface than the head taken)" : "")
        << ", lies outside the plausible head radii " << options.min_head_radius_mm << "-" << options.max_head_radius_mm
        << " mm: if it is the head, widen --min-radius/--max-radius";
      passed_over = m.str();
    }
    if (side_check.other_side)
      throw ProcessingError("no " + std::string(options.joint == Joint::Hip ? "femoral" : "humeral") + " head on the " + side +
                            " side: " + side_check.how + " (the field of view holds one side only; run with --side " +
                            (side == "right" ? "left" : "right") + " if that is the joint meant)");
    if (!found) {
      std::ostringstream m;
      m << "no " << (options.joint == Joint::Hip ? "femoral" : "humeral") << " head found on the " << side
        << " side: no sphere of radius " << options.min_head_radius_mm << "-" << options.max_head_radius_mm
        << " mm has bone edges over " << options.min_coverage << " of its surface within "
        << kMaxRelativeRms * 100 << " % of its radius RMS (-v lists the candidates);"
        << " give --seed-point X,Y,Z (LPS mm) or adjust --hu-min";
      if (!passed_over.empty()) m << "; " << passed_over;
      throw ProcessingError(m.str());
    }
    if (!passed_over.empty()) summary.warnings.push_back(passed_over);
    summary.side_check = side_check.how.empty() ? "not verified" : side_check.how;
    summary.body_middle_x_mm = side_check.middle_x_mm;
    if (side_check.middle_x_mm) summary.body_middle_from = side_check.middle_from_outline ? "outline" : "field of view";
    if (side_check.how.empty())
      summary.warnings.push_back("the " + side + " side could not be verified: the field of view shows neither the body's "
                                 "outline on both sides nor a socket clearly medial to the head; the joint in view was taken");
    measured = !head_found.edge_mm.empty();
    center = head_found.center;
    depth = head_found.radius;
    log::info("head found at " + vec(center) + " mm, radius " + std::to_string(depth) + " mm" +
              (measured ? ", edges on " + std::to_string(static_cast<int>(std::lround(100 * head_found.coverage))) +
                              " % of the rays, RMS " + std::to_string(head_found.rms_mm) + " mm"
                        : " (by its facing surface voxels: the rays found no spherical edge)"));
  }
  if (measured) {
    summary.edge_coverage = head_found.coverage;
    summary.edge_rms_mm = head_found.rms_mm;
  }
  summary.head_found_by = measured ? "edges" : options.seed_point ? "seed point" : "surface voxels";
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
  // partial volume lifts it into the HU window, or the closing bridges it,
  // the black top-hat (closing minus image) finds it, and those voxels leave
  // the bone mask.
  Mask box_raw = close(crop(mask, lo, hi), options.close_radius_mm);
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
  // Cut again after the holes are filled: where noise has closed the soft
  // tissue around the head into bone, the shell the first cut opened was a
  // hole, and filling it gave it back.
  const bool thick_slices = g.spacing[2] > kThickSliceRatio * std::max(g.spacing[0], g.spacing[1]);
  const std::vector<double> cap_edges =
      measured ? capEdges(head_found, g.direction.col(2), neckSide(options.side), thick_slices) : std::vector<double>();
  if (measured) cutBeyondEdges(box_raw, head_found, cap_edges);
  Mask box_mask = fillHoles(box_raw);
  if (measured) cutBeyondEdges(box_mask, head_found, cap_edges);
  const ImageGeometry& bg = box_mask.geometry;
  const Image<float> box_distance = signedDistance(box_mask);
  // A seed point is only somewhere inside the head: re-centre on the deepest
  // full-resolution bone near it, and once more on the label's deepest point
  // (the seed can sit off-centre where bone is joined). The automatic
  // search's sphere is already centred.
  const bool recentre = options.seed_point.has_value() && !measured;
  if (recentre) {
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

  // 4-6. Watershed from markers.
  Mask head;
  double best = 0;
  for (int pass = 0; pass < (recentre ? 2 : 1); ++pass) {
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
  if (!recentre) summary.head_center_mm = center, summary.search_radius_mm = depth;
  summary.head_depth_mm = best;
  if (best < 0.5 * options.min_head_radius_mm)
    summary.warnings.push_back("the labelled head is thin (depth " + std::to_string(best) +
                               " mm): the seed may not be in a joint head");

  // The surface: on the HU edge by an active contour, or at the surface
  // level (nearer half maximum than the window's lower end, which sits a
  // third of a voxel outside in partial volume).
  if (options.level_set_iterations > 0) {
    head = refineByLevelSet(box_hu, head, options.level_set_iterations);
  } else if (!measured && options.surface_hu > options.hu_min) {
    // No cut along the head's edges (coarse voxels): peel the label's outer
    // layer twice where it is darker than surface_hu, which opens the thin
    // partial-volume bridges to the socket (the cortex keeps the darker
    // cancellous interior inside). With the cut, the label ends where the HU
    // window does and the mesh stage places the surface on the CT's edge.
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

  // Where the head's edges cut the socket off (measured), a label voxel
  // that borders bone the label does not hold lies on the segmentation's
  // own cut: the watershed's line across the neck, not the bone's surface.
  // It is labelled kLabelCutThroughBone, so that the mesh stage can tell
  // (docs/methods.md). Without that cut the label also borders the socket
  // across every gap the CT does not resolve, and nothing is marked.
  const auto bordersBone = [&](int i, int j, int k) {
    const int step[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    for (const auto& d : step) {
      const int a = i + d[0], b = j + d[1], c = k + d[2];
      if (a < 0 || b < 0 || c < 0 || a >= bg.size[0] || b >= bg.size[1] || c >= bg.size[2]) continue;
      if (box_mask.at(a, b, c) && !head.at(a, b, c)) return true;
    }
    return false;
  };
  Label label;
  label.geometry = g;
  label.voxels.assign(volume.voxels.size(), 0);
  for (int k = 0; k < bg.size[2]; ++k)
    for (int j = 0; j < bg.size[1]; ++j)
      for (int i = 0; i < bg.size[0]; ++i)
        if (head.at(i, j, k)) {
          const bool cut = measured && bordersBone(i, j, k);
          label.at(lo[0] + i, lo[1] + j, lo[2] + k) = cut ? kLabelCutThroughBone : kLabelBone;
          ++summary.label_voxels;
          summary.cut_through_bone_voxels += cut;
        }
  if (summary.label_voxels == 0) throw ProcessingError("the head label is empty after separation");
  return label;
}

}  // namespace
}  // namespace articula::imaging
