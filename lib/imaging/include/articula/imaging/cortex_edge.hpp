#pragma once
// Where a bone's outer surface is when its cortex is thin: a model of the
// blurred cortex fitted to the CT's voxels about a line across the edge.
//
// The steepest fall of a blurred profile (edges.hpp) lies on the surface of
// a thick cortex only; a cortex thinner than about three point-spread widths
// moves it outwards (0.2 mm for 0.8 mm of cortex under 0.5 mm of blur),
// because the cortex's inner rise adds slope. The model here is the profile
// itself: soft tissue, cortex and cancellous bone (and, across a joint gap,
// the socket) as steps, each blurred by the scanner's point-spread and the
// voxel's own extent along the line, fitted to the voxel values about the
// line (not to an interpolated profile, whose linear interpolation would be
// a second, phase-dependent kernel). A thin cortex trades its thickness
// against the blur within one profile, so the scanner's point-spread (a
// Gaussian, wider across the slices than within them) is estimated once
// over many profiles of the same CT (estimatePointSpread) and then held
// fixed for every line, at its width along that line.
//
// How the blur met the voxels matters as much as its width when the cortex
// is about a voxel thin: a scanner blurs the object before its voxels are
// taken (a Gaussian of the line's width, with each voxel's extent), but an
// image filter (a smoothed or resampled CT, a synthetic one) blurs the
// voxels themselves, with weights sampled at whole voxels along each grid
// axis. At 0.8 mm voxels under 0.5 mm of blur the two place an 0.8 mm
// cortex's surface 0.13 mm apart, so both are tried and the CT's own
// profiles choose (PointSpread::Kind).
#include <cmath>
#include <vector>

#include <Eigen/Core>

#include "articula/imaging/image.hpp"

namespace articula::imaging {

/// The voxels whose centres lie within `radius_mm` of the line x + s u,
/// s in [from_mm, to_mm] (u a unit vector pointing out of the bone): their
/// offsets along the line from a surface through x of mean curvature
/// `curvature_per_mm` (positive where convex; a voxel at a distance l from
/// the line lies l^2 curvature / 2 further out than its s, with l^2 taking
/// the variance of the voxel's extent across the line too), and their values.
struct LineVoxels {
  std::vector<double> offset_mm, value_hu;
  double box_variance_mm2 = 0;  // the voxel's extent along u, as a variance (partial volume)
  double slice_share = 0;       // (u . slice axis)^2: how far the line runs across the slices
  double curvature_per_mm = 0;  // the surface's mean curvature the offsets allow for
  Eigen::Vector3d spacing_mm = Eigen::Vector3d::Zero();      // the grid's, per axis
  Eigen::Vector3d extent_mm = Eigen::Vector3d::Zero();       // what a voxel averages over along each axis
  Eigen::Vector3d axis_step_mm = Eigen::Vector3d::Zero();    // how far along u one voxel's step along each grid axis goes
  Eigen::Vector3d axis_extent_mm = Eigen::Vector3d::Zero();  // ... and its extent along that axis
  Eigen::Vector3d point_mm = Eigen::Vector3d::Zero();        // x: where the line's neighbours are sought
};
/// `extent_mm`: what one voxel averages over along each grid axis (zero:
/// the volume's, ImageGeometry::voxelExtent; slices thicker than their
/// spacing reach further than one step).
LineVoxels voxelsAboutLine(const Volume& volume, const Eigen::Vector3d& x, const Eigen::Vector3d& u, double from_mm,
                           double to_mm, double radius_mm, double curvature_per_mm = 0,
                           const Eigen::Vector3d& extent_mm = Eigen::Vector3d::Zero());

/// The window the model is fitted over: from kCortexInwardMm inside an edge
/// (the cortex and some cancellous bone) to kCortexOutwardMm outside it (the
/// joint gap and the near side of a socket).
constexpr double kCortexInwardMm = 3.5, kCortexOutwardMm = 2.5;
/// How far either side of its guess a line's surface is sought: a
/// millimetre, or three quarters of the voxel's extent along the line
/// where that is more (`axis_extent_mm` as in LineVoxels): across 3 mm slices
/// a thin cortex's steepest fall lies up to 1.5 mm outside it. A line's
/// window reaches that much further in than kCortexInwardMm.
double cortexSearchMm(const Eigen::Vector3d& axis_extent_mm);
/// The radius about the line that holds about 50 voxels of the window (at
/// least 0.8 mm): enough for the model's seven unknowns at any voxel size.
/// On a CT noisier than kQuietCtNoiseHu voxel to voxel (`noise_hu`,
/// imaging/noise.hpp), as many more voxels as its noise's variance is
/// larger (the radius up to kMaxNoiseWidening times wider), so that each
/// fit sees the noise of a quiet CT. A fit's thickness is not linear in the
/// voxels: a noisy line's comes out thicker, and the outer surface outwards
/// with it (an osteoporotic phantom head's 0.8 mm cortex under 0.5 mm of
/// blur at 0.7 mm voxels read 1.0 mm thick at 60 HU and 1.2 at 100 HU, the
/// point-spread 0.46-0.47 and 0.43 mm, the surface 0.08-0.10 and 0.16 mm
/// outside; with the wider lines the point-spread 0.49-0.51 mm, the surface
/// within 0.03 mm).
double lineRadiusFor(const ImageGeometry& geometry, double noise_hu = 0);
/// The radius for a line along `u`: lineRadiusFor(geometry, noise_hu), and
/// where the slices are long (tissueHeldAcrossSlices), wide enough (up to
/// kMaxLineRadiusMm) that the voxels of the slices the line crosses lie at
/// every depth along it: a line near the slice axis meets each slice at one
/// depth only, and its surface is then told by no voxel.
double lineRadiusFor(const ImageGeometry& geometry, const Eigen::Vector3d& u, double noise_hu = 0);
constexpr double kMaxLineRadiusMm = 5.0;
/// The phantoms' 20 HU and real CTs' 9-21 HU lie below it; a sharp kernel
/// over 20 HU reads about 40.
constexpr double kQuietCtNoiseHu = 30.0, kMaxNoiseWidening = 3.0;
/// ... and no wider than this for the noise: over a wider disk the
/// surface's curvature departs from the line's quadratic allowance.
constexpr double kMaxNoisyLineRadiusMm = 3.0;

struct PointSpread;

/// The share of a blurred step's bright side that a voxel sees, as a
/// function of the voxel centre's depth behind the step (mm; negative in
/// front of it): Phi(depth / width) for a Gaussian of the line's width with
/// the voxel's extent; for a blur on the voxel grid, the grid's weights laid
/// along the line, spread by the voxel's extent and summed into a table.
class StepResponse {
 public:
  /// A Gaussian of this width along the line (the voxel's extent included).
  explicit StepResponse(double width_mm) : width_mm_(width_mm) {}
  /// `spread`'s blur along `line`, the voxel's extent added.
  StepResponse(const LineVoxels& line, const PointSpread& spread);
  double brightShare(double depth_mm) const;
  bool valid() const { return width_mm_ > 0 || !table_.empty(); }

 private:
  double width_mm_ = 0;
  double table_first_mm_ = 0;  // depth of table_[0]
  std::vector<double> table_;  // the share every kTableStepMm
};

/// The bone about a line: its cortex's thickness and the levels of the
/// soft tissue outside, the cortex and the cancellous bone within.
struct CortexTissue {
  double thickness_mm = 0;
  double outside_hu = 0, cortex_hu = 0, inside_hu = 0;
};

struct CortexFit : CortexTissue {
  bool found = false;
  double offset_mm = 0;        // the outer (periosteal) surface along u
  double gap_mm = 0;           // to the socket's step beyond it (where the model puts one)
  double sum_squares = 0;      // of the residuals (and of the held levels' departures, weighted), HU^2
};

/// The blurred-cortex model fitted to `line` with the steps blurred as
/// `response` says, the surface searched within cortexSearchMm of `guess_mm`. Where
/// the voxels rise again beyond the edge (a socket across a joint gap), the
/// window ends within that rise.
/// With `held`, the cortex has the held thickness and its levels are drawn
/// towards the held ones (each as if a few voxels had shown it): for a line
/// whose blur is too wide to tell a thin cortex's thickness from its
/// brightness (across thick slices), the tissue comes from lines that can.
/// Not found when the fit puts no bright layer on the bone side (cortex or
/// bone at least `min_contrast_hu` above the outside) or the surface at the
/// search's end.
CortexFit fitCortex(const LineVoxels& line, double guess_mm, const StepResponse& response,
                    double min_contrast_hu = 150, const CortexTissue* held = nullptr);
/// The same with the scanner's Gaussian point-spread `sigma_mm` along the
/// line (the voxel's extent is added).
CortexFit fitCortex(const LineVoxels& line, double guess_mm, double sigma_mm, double min_contrast_hu = 150);

/// The CT's Gaussian point-spread (standard deviations): one width within
/// the slices and one across them (a CT's slice profile is often wider than
/// its in-plane blur), and how it was applied.
struct PointSpread {
  /// Where the blur was applied: before the voxels were taken (a scanner),
  /// or to the voxels along each grid axis, its Gaussian's weights sampled
  /// at whole voxels (an image filter: a smoothed, resampled or synthetic CT).
  enum class Kind { Scanner, VoxelGrid };
  bool found = false;
  Kind kind = Kind::Scanner;
  double sigma_mm = 0;        // within the slices
  double slice_sigma_mm = 0;  // across them (along the slice axis, the grid's third index)
  int profiles = 0;           // lines it was estimated on
  /// Whether the lines across the slices take the cortex of the lines
  /// within them (fitCortex's `held`): on long slices (tissueHeldAcrossSlices)
  /// or a blur across the slices a tenth wider than within them.
  bool held_across = false;
  /// The width along a line: the Gaussian's spread in its direction.
  double along(const LineVoxels& line) const {
    return std::sqrt(sigma_mm * sigma_mm * (1 - line.slice_share) + slice_sigma_mm * slice_sigma_mm * line.slice_share);
  }
};

/// How far inside a surface of the line's mean curvature the model, which
/// blurs a flat step, puts it under `spread` (mm; negative where concave):
/// the blur averages the bone over a patch of the surface around the line,
/// which on a convex surface lies deeper the further out, by the curvature
/// times half the blur's variance across the line (the voxel's own extent
/// is in the line's offsets already). On a sphere of radius R under an
/// isotropic Gaussian of width s: s^2 / R, 0.016 mm for 0.6 mm on 23 mm.
double curvatureShiftMm(const LineVoxels& line, const PointSpread& spread);

/// The point-spread that lets the blurred-cortex model fit `lines` (each
/// centred on its edge's first guess) best, by the profile likelihood of
/// its kind and widths: each line's residual after its own fit, on a log
/// scale (a line the model cannot explain, a socket's rim or a cut through
/// the bone, weighs no more than one it fits; summed residuals let such
/// lines pull the width). First, for each kind, one width for both
/// directions (a grid over 0.05-2 mm, then parabolas through the
/// likelihood about its best, which jumps by a few units from width to
/// width as each line's search ends a little differently); the kind that
/// fits better is kept. Then the slice width and the width within the
/// slices, each within a factor 2.5 of the common one, replace it only when
/// they fit better by more than the log of the voxels' count (the Bayesian
/// information criterion). Lines that face a socket are left out while 30
/// others remain. Not found with fewer than 30 lines or when the one
/// width's least lies at the end of its range. Lines that hardly cross the
/// slices (their shares summing to less than a tenth of the lines) give one
/// width for both.
/// Where the slices are more than a fifth longer than the in-plane voxel
/// (tissueHeldAcrossSlices), the width within them is the one width of the
/// lines within them (slice share below kWithinSlicesShare) instead, since
/// the lines across long slices see the slice's own profile, which a
/// generator or scanner may take unlike the model's box: of those lines,
/// the ones the model explains (their residual within 1.3 times the
/// median), and of the kind they fit better by more than the log of their
/// voxels' count (else the common one's).
/// There, or where the width across the slices comes out more than a tenth
/// wider than within them, the width across the slices is then estimated
/// again on the lines across them, each fitted with the tissue of its
/// nearest lines within the slices (nearbyTissue): across long or thick
/// slices a thin cortex's thickness trades against the blur, and the width
/// with it (held_across). `more_within_slices`: further lines within long
/// slices that join those of `lines` there for the width within them and
/// the tissue held across them, and take part in nothing else.
/// `noise_hu`: the CT's noise voxel to voxel (noiseHu); the width within the
/// slices leans under noise, and where it is given the lean is measured by
/// remaking the lines from their fits with that noise and taken off.
PointSpread estimatePointSpread(const std::vector<LineVoxels>& lines, int threads = 1,
                                const std::vector<LineVoxels>& more_within_slices = {}, double noise_hu = 0);

/// Lines whose slice share is below this lie within the slices: across
/// them a line sees the in-plane voxel's extent and blur only.
constexpr double kWithinSlicesShare = 0.05;
/// Whether the voxels (their extent, ImageGeometry::voxelExtent) are long
/// enough across the slices for the lines across them to take their tissue
/// from the lines within them.
bool tissueHeldAcrossSlices(const Eigen::Vector3d& extent_mm);
/// ... or whose point-spread is a tenth wider across the slices than within them.
bool tissueHeldAcrossSlices(const Eigen::Vector3d& extent_mm, double sigma_mm, double slice_sigma_mm);
/// For each of `points`, the median tissue of its nearest (15) `known`
/// tissues (at `known_points`).
std::vector<CortexTissue> nearbyTissue(const std::vector<Eigen::Vector3d>& points,
                                       const std::vector<Eigen::Vector3d>& known_points,
                                       const std::vector<CortexTissue>& known);

}  // namespace articula::imaging
