#pragma once
// Private to lib/imaging: finding a joint head in a CT (a Hough transform
// for spheres proposes centres, rays cast from each measure the sphere
// through the first bone edges seen from inside) and cutting the bone
// beyond the head's edges. Used by segment.cpp.
#include <optional>
#include <string>
#include <vector>

#include "articula/imaging/image.hpp"
#include "articula/imaging/segment.hpp"

namespace articula::imaging::detail {

// A joint head's cap is nearly spherical: the RMS of its edges about their
// sphere stays below this share of the radius (real femoral and humeral
// heads 1-2.5 %, superellipsoids of exponents up to 2.6 about 3 %) plus a
// quarter voxel of quantisation; an ellipsoidal trochanter or a tuberosity
// does not.
constexpr double kMaxRelativeRms = 0.04;
constexpr double kRmsVoxelShare = 0.25;
// A field of view this wide (left-right) holds both sides of the body: a
// joint head then lies at least kAutomaticMidlineMargin from its middle
// (hips 70-110 mm, shoulders 120-200 mm; vertebral bodies, near-spherical
// too, lie on it).
constexpr double kBothSidesWidthMm = 250, kAutomaticMidlineMargin = 40;
// The body's outline: above this HU (fat is about -100, air -1000). It is
// whole left and right when at most this share of the field's edge columns
// hold body.
constexpr double kBodyHu = -400, kBodyAtEdgeShare = 0.02;
// The socket seen from a head's centre: a fall of kSocketContrastHu at the
// head's edge and a rise of as much within half a radius, on at least this
// share of the rays, whose mean direction leans this far to one side (x).
constexpr double kMinSocketRayShare = 0.10, kMinSocketMedialShift = 0.2, kSocketContrastHu = 150;
constexpr int kRayCount = 512;
// Rays are cast again from each new centre, at most this often; a candidate
// whose centre still moves is not measured.
constexpr int kMaxRayRounds = 8;
// A sphere started from another quantile of the rays' edge distances than
// the median replaces the median's when this many times as many edges agree.
constexpr double kConsensusGain = 1.5;
// A ray's valley (its first fall into a valley, imaging::firstValleyAlongRay:
// a narrow joint gap's, too shallow for an edge) counts where it is a gap's
// before the ray's edge (imaging::isGapValleyBefore) and at most a joint gap
// and a thin cortex (kValleyGapReachMm) short of it; the valleys may take
// the edges' place when at least kMinValleyRays rays have one.
constexpr double kValleyGapReachMm = 3.5;
constexpr int kMinValleyRays = 10;
// The valleys' sphere replaces the edges' where a fifth more rays agree on
// it as closely (within kValleyRmsTie of the RMS: the rays facing the
// socket join the head's), or at least kValleyCountShare of them far more
// closely (kValleyRmsGain: the edges' sphere ran between the head and the
// socket's far side, looser than either).
constexpr double kValleyCountGain = 1.2, kValleyRmsTie = 1.05, kValleyCountShare = 0.8, kValleyRmsGain = 0.75;

/// A head measured from a point inside it: the sphere through the first bone
/// edges seen on rays from that point, and the edges themselves.
struct HeadCandidate {
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  double radius = 0, coverage = 0, rms_mm = 0;  // coverage: share of the rays whose edge lies on the sphere
  std::vector<double> edge_mm;                  // per ray of the lattice, from `center`; NaN: no edge on the sphere
  std::vector<char> short_of_sphere;            // per ray: its edge was found but short of the sphere's band
  double area() const { return coverage * 4 * M_PI * radius * radius; }
  /// Edges on a third of the rays and nearly spherical: a head's cap seen
  /// through a visible gap.
  bool wellMeasured(double voxel_mm) const {
    return !edge_mm.empty() && coverage >= 0.3 && rms_mm <= kMaxRelativeRms * radius + kRmsVoxelShare * voxel_mm;
  }
};

/// "(x, y, z)" with 4 significant digits, for messages.
std::string vec(const Eigen::Vector3d& v);
/// Whether x (LPS mm) lies within the grid (half a voxel beyond its centres).
bool insideVolume(const ImageGeometry& g, const Eigen::Vector3d& x);

/// Measures the head seen from `start` (a point inside it).
HeadCandidate measureHeadByRays(const Volume& volume, const Eigen::Vector3d& start, const SegmentOptions& options);
/// The automatic search on options.side; false when no candidate is a
/// plausible head, or when the one found is of the other side. The side
/// comes from the body's middle (its outline, when whole in the field), else
/// the field's middle (a field wide enough for both sides), else the socket
/// (sideBySocket, one joint in a narrow field). `side` says how, or why the
/// head was refused. `outside_range`, when given, receives the well-measured
/// sphere on the side with the most bone surface (HeadCandidate::area) whose
/// radius lies outside the plausible range (SegmentOptions' min/max head
/// radius) but within a factor 1.5 of it: where it has more than the head
/// taken, a head bigger or smaller than the range expects was passed over.
struct SideCheck {
  std::string how;           // empty: the side could not be verified
  bool other_side = false;   // the joint found is of the other side: refused
  std::optional<double> middle_x_mm;  // the body's middle (LPS x) the side was judged by, when one was
  bool middle_from_outline = false;   // from the body's outline (else the middle of a wide field of view)
};
bool findHead(const Volume& volume, const SegmentOptions& options, HeadCandidate& head, SideCheck& side,
              std::optional<HeadCandidate>* outside_range = nullptr);
/// The side a joint is on from its socket, medial to it across the joint
/// space (acetabulum, glenoid); none when too little socket is seen or it
/// leans to neither side.
std::optional<Side> sideBySocket(const Volume& volume, const HeadCandidate& head, const SegmentOptions& options);
/// The head's edge distance per ray of the lattice, the holes of its cap
/// filled from their neighbours (the neck's directions stay NaN);
/// `slice_axis`: the grid's slice normal (unit, LPS); `neck_side`: where the
/// neck leaves the head, roughly (unit, LPS; neckSide); `thick_slices`:
/// slices more than kThickSliceRatio times the in-plane spacing apart.
std::vector<double> capEdges(const HeadCandidate& head, const Eigen::Vector3d& slice_axis, const Eigen::Vector3d& neck_side,
                             bool thick_slices);
/// Slices more than this many times the in-plane spacing apart blur the dome's
/// edge along them (capEdges).
constexpr double kThickSliceRatio = 1.5;
/// Where a femoral or humeral neck leaves its head, roughly: lateral and
/// inferior (LPS: -x on the right side, +x on the left; -z).
Eigen::Vector3d neckSide(Side side);
/// Clears the mask's voxels beyond the head's edges (capEdges) in the directions of its cap.
void cutBeyondEdges(Image<std::uint8_t>& mask, const HeadCandidate& head, const std::vector<double>& edge);

}  // namespace articula::imaging::detail
