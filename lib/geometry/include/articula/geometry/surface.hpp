#pragma once
// Smooth convex implicit surfaces of the thesis (ch. 2) with value, gradient
// and Hessian in closed form.
//
// Sign convention, for every surface: F(x) < 0 inside, F(x) = 0 on the
// surface, F(x) > 0 outside; the gradient points outwards. The posed shapes
// use the thesis's unit canonical form minus one, F = F_canonical(x_l) - 1,
// evaluated at x_l = D^-1 R^T (x - t) (eq. 2.20), so F is dimensionless.
// Points x are global LPS millimetres.
#include <memory>
#include <string>

#include <Eigen/Core>

#include "articula/geometry/pose.hpp"
#include "articula/geometry/shape.hpp"

namespace articula::geometry {

struct Evaluation {
  double value = 0.0;                                  // F
  Eigen::Vector3d gradient = Eigen::Vector3d::Zero();  // dF/dx (1/mm)
  Eigen::Matrix3d hessian = Eigen::Matrix3d::Zero();   // d2F/dx2 (1/mm^2)
};

/// A triangulated sample of a surface: #V x 3 vertices (mm), #F x 3 triangles.
struct SurfaceMesh {
  Eigen::MatrixX3d vertices;
  Eigen::MatrixX3i triangles;
};

class ImplicitSurface {
 public:
  virtual ~ImplicitSurface() = default;
  virtual std::string name() const = 0;
  /// F(x) with its first (order >= 1) and second (order >= 2) derivatives.
  virtual Evaluation evaluate(const Eigen::Vector3d& x, int order = 2) const = 0;
  double value(const Eigen::Vector3d& x) const { return evaluate(x, 0).value; }
  Eigen::Vector3d gradient(const Eigen::Vector3d& x) const { return evaluate(x, 1).gradient; }
  Eigen::Matrix3d hessian(const Eigen::Vector3d& x) const { return evaluate(x, 2).hessian; }
  /// Exact parametric sample (appendix A): every vertex satisfies F = 0 to
  /// rounding. `azimuth_steps` around the local z axis, `polar_steps` from
  /// pole to pole. Unbounded surfaces (plane, open quadrics) are sampled over
  /// a patch of `extent` mm around their local origin.
  virtual SurfaceMesh sample(int azimuth_steps, int polar_steps, double extent = 50.0) const = 0;
};

/// A shape of the fitting hierarchy (or Barr's superellipsoid) placed by a
/// pose: evaluated in unit canonical coordinates and mapped by the chain rule,
/// gradient = A g_l, Hessian = A H_l A^T with A = R D^-1.
class PosedSurface : public ImplicitSurface {
 public:
  explicit PosedSurface(const Pose& pose) : pose_(pose), map_(pose.gradientMap()) {}
  const Pose& pose() const { return pose_; }
  Evaluation evaluate(const Eigen::Vector3d& x, int order = 2) const override;
  SurfaceMesh sample(int azimuth_steps, int polar_steps, double extent = 50.0) const override;
  /// F and its derivatives in unit canonical coordinates u = x_l.
  virtual Evaluation evaluateCanonical(const Eigen::Vector3d& u, int order) const = 0;
  /// The canonical surface point at azimuth in [-pi, pi) and latitude in [-pi/2, pi/2].
  virtual Eigen::Vector3d canonicalPoint(double azimuth, double latitude) const = 0;

 private:
  Pose pose_;
  Eigen::Matrix3d map_;  // A = R D^-1
};

/// Builds the surface of any hierarchy model after validate(p).
std::unique_ptr<PosedSurface> makeSurface(const ShapeParameters& p);

}  // namespace articula::geometry
