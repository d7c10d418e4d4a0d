#pragma once
// Triangulations of parametric samples, shared by the surfaces' samplers.
#include <functional>
#include <optional>

#include <Eigen/Core>

#include "articula/geometry/surface.hpp"

namespace articula::geometry {

/// point(azimuth, latitude) -> surface point, or nullopt where the surface has none.
using SphericalParametrisation = std::function<std::optional<Eigen::Vector3d>(double, double)>;
/// point(s, t) for s, t in [-1, 1].
using PlanarParametrisation = std::function<std::optional<Eigen::Vector3d>(double, double)>;

/// A closed UV-sphere: one vertex per pole, `polar_steps - 1` rings of
/// `azimuth_steps` vertices; triangles wound counter-clockwise seen from
/// outside (outward normals). Triangles touching a missing point are dropped.
SurfaceMesh uvSphereMesh(int azimuth_steps, int polar_steps, const SphericalParametrisation& point);

/// A (s_steps + 1) x (t_steps + 1) grid over [-1, 1]^2, two triangles per cell.
SurfaceMesh gridMesh(int s_steps, int t_steps, const PlanarParametrisation& point);

}  // namespace articula::geometry
