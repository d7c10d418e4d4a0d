#pragma once
// Differential operators D_n, D_t, D_b (appendix B) and curvature (eq. 4.21-4.23)
// of any implicit surface of the core.
#include <Eigen/Core>

#include "articula/geometry/frames.hpp"
#include "articula/geometry/surface.hpp"

namespace articula::geometry {

/// Orthonormal, right-handed frame at x: normal = D_n = grad F / |grad F|
/// (outward), tangent = D_t, binormal = D_b (Householder columns of grad F).
/// Appendix B's D_n is the first Householder column, -+grad F/|grad F|
/// depending on the sign of F_x; we return the outward normal always.
/// Throws ProcessingError where grad F = 0.
struct SurfaceFrame {
  Eigen::Vector3d normal, tangent, binormal;
};
SurfaceFrame surfaceFrame(const ImplicitSurface& surface, const Eigen::Vector3d& x,
                          FrameMethod method = FrameMethod::Householder);

/// Normal curvature along the unit tangent w at a surface point x:
/// k_w = w^T H w / |grad F| (eq. 4.21 with the outward normal), so convex
/// surfaces have positive curvature and a sphere of radius r has k = 1/r.
double normalCurvature(const ImplicitSurface& surface, const Eigen::Vector3d& x, const Eigen::Vector3d& w);

/// Principal curvatures k1 >= k2 and their unit directions at a surface point,
/// from eq. 4.22-4.23: w(theta) = cos(theta) t + sin(theta) b with
/// tan(2 theta) = 2 t^T H b / (t^T H t - b^T H b).
struct PrincipalCurvatures {
  double k1 = 0.0, k2 = 0.0;
  Eigen::Vector3d d1 = Eigen::Vector3d::Zero(), d2 = Eigen::Vector3d::Zero();
};
PrincipalCurvatures principalCurvatures(const ImplicitSurface& surface, const Eigen::Vector3d& x);

}  // namespace articula::geometry
