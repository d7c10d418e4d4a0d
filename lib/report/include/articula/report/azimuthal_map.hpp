#pragma once
// A flat, area-true map of the points of a joint head, for error maps.
#include <Eigen/Core>

namespace articula::report {

struct AzimuthalMap {
  Eigen::MatrixX2d xy;          // #P x 2 map coordinates (mm)
  Eigen::Vector3d centre;       // LPS mm
  Eigen::Vector3d axis;         // unit, LPS: the map's centre direction
  Eigen::Vector3d right, up;    // unit, LPS: the map's +x and +y directions
  double radius_mm = 0.0;       // R: mean distance of the points from the centre
};

/// Lambert azimuthal equal-area projection of `points` (#P x 3, LPS mm) seen
/// from `centre`, about the mean direction from the centre to the points (the
/// head's main axis; +S when the points surround the centre). A point at
/// angle theta from the axis maps to radius 2 R sin(theta / 2), so areas on the
/// sphere of radius R keep their size (theta = 90 degrees maps to R sqrt(2)).
/// The map is the view from outside the head: `up` is S projected onto the
/// map plane (P, or L, when the axis is within 26 degrees of it), `right` is
/// up x axis. A point at the centre maps to the origin, one opposite the axis
/// to (2R, 0).
AzimuthalMap azimuthalEqualArea(const Eigen::MatrixX3d& points, const Eigen::Vector3d& centre);

}  // namespace articula::report
