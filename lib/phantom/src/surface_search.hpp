#pragma once
// Searches on a head's surface from its centre: the boundary along a ray,
// the support point along a direction, and the area of a region.
#include <functional>

#include <Eigen/Core>

#include "articula/geometry/surface.hpp"

namespace articula::phantom::detail {

using Inside = std::function<bool(const Eigen::Vector3d&)>;

/// Distance from c to the boundary of a star-shaped solid along unit d, by
/// bisection on `inside` (c inside, c + reach * d outside).
double along(const Inside& inside, const Eigen::Vector3d& c, const Eigen::Vector3d& d, double reach,
             double tolerance = 1e-9);

/// A unit vector perpendicular to u.
Eigen::Vector3d perpendicular(const Eigen::Vector3d& u);

/// The point of the solid's surface farthest along unit u (its support
/// point), by a pattern search over directions from c (the heads are convex).
Eigen::Vector3d support(const Inside& inside, const Eigen::Vector3d& c, const Eigen::Vector3d& u, double reach);

/// Area (mm^2) of the model surface where `in_region` holds, over the
/// directions from c within the cone cos >= cos_limit about unit `axis`.
double modelArea(const geometry::PosedSurface& head, const Eigen::Vector3d& c, double reach, const Eigen::Vector3d& axis,
                 double cos_limit, const Inside& in_region);

}  // namespace articula::phantom::detail
