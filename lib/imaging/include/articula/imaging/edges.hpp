#pragma once
// Where a CT's bone surface is, to a fraction of a voxel: the steepest fall
// of the HU profile along a line leaving the bone (the gradient maximum of
// a blurred step, which a symmetric point-spread leaves in place), not where
// a fixed HU threshold cuts a blurred cortex. A cortex thinner than about
// three point-spread widths pulls it outwards a little (its inner rise adds
// slope; 0.1 mm for 1.5 mm of cortex under 0.7 mm of blur), far less than a
// threshold or the local half maximum, which a thin cortex's lowered peak
// moves outwards by twice that. Plain buffers, no ITK: the
// head search and the mesh stage both read profiles.
#include <Eigen/Core>

#include "articula/imaging/image.hpp"

namespace articula::imaging {

/// The coarsest voxel (its longest side, mm) at which a joint head's edge
/// stands apart from its socket's: beyond it (3 mm slices) the joint gap
/// blurs away, and an edge further out than the label, or the lack of one
/// at a point, tells nothing.
constexpr double kSeparateEdgesMaxVoxelMm = 2.0;

/// Above this, a voxel is metal (a screw, a stem): cortical bone stays
/// below it. A fall from metal is the metal's edge, never the bone's.
constexpr double kMetalHu = 2500;

/// HU at a physical LPS point by trilinear interpolation; NaN outside the grid.
double interpolate(const Volume& volume, const Eigen::Vector3d& x);

struct EdgeSearch {
  double inward_mm = 2.0;         // search from this far inside the start point ...
  double outward_mm = 2.0;        // ... to this far outside it
  double step_mm = 0.1;           // profile sampling step
  double smoothing_mm = 0.0;      // derivative-of-Gaussian scale (0: a quarter of the finest voxel, at least 0.15 mm)
  double min_contrast_hu = 150;   // least fall across the edge (within 1.5 mm either side)
  double min_inside_hu = 200;     // the bone side of the edge reaches at least this
};

struct Edge {
  bool found = false;
  double offset_mm = 0;       // along the direction from the start point (positive: outwards)
  double slope_hu_per_mm = 0; // the fall's steepest slope (positive)
  double inside_hu = 0, outside_hu = 0;  // the profile's maximum before and minimum after the edge
};

/// The bone's outer edge on the line x + t * outward (outward a unit vector
/// pointing out of the bone), t in [-inward_mm, outward_mm]: the steepest fall
/// of the smoothed profile, refined by a parabola through its three samples.
/// Not found when the line leaves the grid, or the fall is weaker than
/// min_contrast_hu or does not start from bone.
Edge locateEdge(const Volume& volume, const Eigen::Vector3d& x, const Eigen::Vector3d& outward,
                const EdgeSearch& search);

/// The first bone edge met going out from `origin` along `direction`
/// between from_mm and to_mm (for rays cast from inside a head): the first
/// fall of the smoothed profile that is at least min_contrast_hu deep and
/// starts from bone. Not found when there is none before to_mm.
Edge firstEdgeAlongRay(const Volume& volume, const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                       double from_mm, double to_mm, const EdgeSearch& search);

/// A fall into a valley: the bone's edge where a narrow joint gap's blurred
/// valley lies between the head's cortex and the socket's.
struct ValleySearch {
  double min_fall_hu = 60;       // from the bone side's maximum down to the valley's floor,
  double min_fall_share = 0.15;  // and this share of that maximum (a dip in a bright cortex is no gap)
  double min_rise_hu = 50;       // from the floor up again, within rise_reach_mm beyond it
  double rise_reach_mm = 3.0;
};

/// A valley is a joint gap's, between two cortices, where the bone before it
/// (its edge's inside_hu) reaches at least this share of the bone beyond it
/// (the far edge's): a valley of cancellous texture lies below the cortex
/// that follows it.
constexpr double kGapValleyPeakShare = 0.8;
/// Beyond this voxel (its longest side, mm) firstEdgeBeforeAGap takes no
/// valley: a gap of a millimetre blurs away there, and a faint cortex's
/// valleys are its cancellous texture's (osteoporotic heads at 1 x 1 x 2 mm).
constexpr double kGapValleyMaxVoxelMm = 1.25;

/// The first fall met going out from `origin` (as firstEdgeAlongRay, as
/// steep and from bone) that ends in a valley: at least min_fall_hu (and
/// min_fall_share of the bone's HU) down to its floor, and rising again by
/// min_rise_hu within rise_reach_mm beyond it. Across a joint gap of about a
/// millimetre between thin, faint cortices the valley need not fall
/// min_contrast_hu, and the first edge is then the socket's far side; this
/// fall is the head's. Its outside_hu is the valley's floor.
Edge firstValleyAlongRay(const Volume& volume, const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                         double from_mm, double to_mm, const EdgeSearch& search, const ValleySearch& valley = {});

/// A valley lies this far short of the edge at least to be a gap's before it.
constexpr double kGapValleyShortOfEdgeMm = 0.5;

/// Whether `valley` (firstValleyAlongRay) is a joint gap's before `edge`
/// (firstEdgeAlongRay on the same line): more than kGapValleyShortOfEdgeMm
/// short of it, its bone at least kGapValleyPeakShare of the edge's.
bool isGapValleyBefore(const Edge& valley, const Edge& edge);

/// The first bone edge met going out (firstEdgeAlongRay), or, where a joint
/// gap's valley lies before it (isGapValleyBefore) and the voxels are at
/// most kGapValleyMaxVoxelMm, the fall into that valley: the head's edge,
/// not the socket cortex's far side.
Edge firstEdgeBeforeAGap(const Volume& volume, const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                         double from_mm, double to_mm, const EdgeSearch& search);

}  // namespace articula::imaging
