#pragma once
// The concrete surfaces. See surface.hpp for the sign convention.
#include <Eigen/Core>

#include "articula/geometry/surface.hpp"

namespace articula::geometry {

/// Plane (eq. 2.6): F = n.x - d with n normalised, so F is the signed distance
/// in mm; negative on the side opposite the normal.
class Plane : public ImplicitSurface {
 public:
  /// `normal` must be non-zero (InvalidParameter otherwise); `point` lies on the plane.
  Plane(const Eigen::Vector3d& normal, const Eigen::Vector3d& point);
  std::string name() const override { return "plane"; }
  Evaluation evaluate(const Eigen::Vector3d& x, int order = 2) const override;
  SurfaceMesh sample(int azimuth_steps, int polar_steps, double extent = 50.0) const override;
  const Eigen::Vector3d& normal() const { return normal_; }
  double offset() const { return offset_; }

 private:
  Eigen::Vector3d normal_;
  double offset_;
};

/// Quadric family (eq. 2.8-2.11, table 2.3), in local coordinates x_l = R^T (x - t):
/// F = a11 x^2 + a22 y^2 + a33 z^2 + a1 x + a2 y + a3 z - 1, with
/// a11 a1 = a22 a2 = a33 a3 = 0 (eq. 2.9) and a1, a2, a3 in {-1, 0, 1}.
/// F(t) = -1: "inside" is the side that holds the local origin.
class Quadric : public ImplicitSurface {
 public:
  enum class Type { Ellipsoid, Hyperboloid1, Hyperboloid2, EllipticParaboloid, HyperbolicParaboloid, Other };
  Quadric(const Eigen::Vector3d& a_ii, const Eigen::Vector3d& a_i, const Eigen::Matrix3d& rotation,
          const Eigen::Vector3d& translation);
  std::string name() const override { return "quadric"; }
  Evaluation evaluate(const Eigen::Vector3d& x, int order = 2) const override;
  /// Radial sample (eq. A.1-A.2); directions whose ray misses the surface are
  /// left out, and so are points beyond `extent` mm.
  SurfaceMesh sample(int azimuth_steps, int polar_steps, double extent = 50.0) const override;
  /// Classification of table 2.3.
  Type type() const;
  /// Dimension parameters a = |a11|^-1/2 etc. (eq. 2.10); infinity for a zero coefficient.
  Eigen::Vector3d dimensions() const;

 private:
  Eigen::Vector3d quadratic_, linear_;
  Eigen::Matrix3d rotation_;
  Eigen::Vector3d translation_;
};

/// Sphere: F = |x - t|^2 / a^2 - 1, evaluated directly (no rotation).
class Sphere : public PosedSurface {
 public:
  Sphere(double radius, const Eigen::Vector3d& center);
  std::string name() const override { return "sphere"; }
  Evaluation evaluate(const Eigen::Vector3d& x, int order = 2) const override;
  Evaluation evaluateCanonical(const Eigen::Vector3d& u, int order) const override;
  Eigen::Vector3d canonicalPoint(double azimuth, double latitude) const override;

 private:
  double radius_;
  Eigen::Vector3d center_;
};

/// Ellipsoid: |x_l|^2 - 1 in scaled local coordinates (radii a, b, c).
class Ellipsoid : public PosedSurface {
 public:
  using PosedSurface::PosedSurface;
  std::string name() const override { return "ellipsoid"; }
  Evaluation evaluateCanonical(const Eigen::Vector3d& u, int order) const override;
  Eigen::Vector3d canonicalPoint(double azimuth, double latitude) const override;
};

/// Superellipsoid, thesis form (eq. 2.12 / 5.37): |x|^g1 + |y|^g2 + |z|^g3 - 1, g >= 2.
class Superellipsoid : public PosedSurface {
 public:
  Superellipsoid(const Pose& pose, const Eigen::Vector3d& exponents);
  std::string name() const override { return "superellipsoid"; }
  Evaluation evaluateCanonical(const Eigen::Vector3d& u, int order) const override;
  /// Generalises eq. 2.16: x = sgn|cos(lat)cos(az)|^(2/g1), y = ..., z = sgn|sin(lat)|^(2/g3).
  Eigen::Vector3d canonicalPoint(double azimuth, double latitude) const override;
  const Eigen::Vector3d& exponents() const { return exponents_; }

 private:
  Eigen::Vector3d exponents_;
};

/// Superellipsoid in Barr's form (eq. 2.14):
/// (|x|^(2/e1) + |y|^(2/e1))^(e1/e2) + |z|^(2/e2) - 1, with 0 < e1, e2 <= 1 so
/// that every exponent is >= 2 (smooth and convex, as for the thesis form).
/// On the local z axis with e1 != e2 the Hessian's xy block is taken as its
/// limit along the axis, which is 0 for e2 < 1.
class BarrSuperellipsoid : public PosedSurface {
 public:
  /// Throws InvalidParameter ("epsilon1"/"epsilon2") outside (0, 1] or for bad radii.
  BarrSuperellipsoid(const Pose& pose, double epsilon1, double epsilon2);
  std::string name() const override { return "barr_superellipsoid"; }
  Evaluation evaluateCanonical(const Eigen::Vector3d& u, int order) const override;
  /// Eq. 2.16.
  Eigen::Vector3d canonicalPoint(double azimuth, double latitude) const override;
  double epsilon1() const { return e1_; }
  double epsilon2() const { return e2_; }

 private:
  double e1_, e2_;
};

/// Superovoid (Todd & Smart, eq. 2.18-2.19):
/// |x / px(z)|^g1 + |y / py(z)|^g2 + |z|^g3 - 1, p(z) = c0 + c1 z + c2 z^2 + c3 z^3.
///
/// The raw function has a second, spurious sheet (thesis section 3.4) where a
/// denominator p(z) reaches zero. The model is restricted to its closed
/// component: validate() requires p > 0 on local z in [-1, 1], the only z the
/// closed component spans (|z|^g3 <= 1 on it), and the denominators are
/// evaluated at z clamped to [-1, 1]. Outside that slab F >= |z|^g3 - 1 > 0, so
/// no second sheet exists; F is continuous everywhere and smooth off the
/// planes |z_l| = 1, which the surface touches only at its two vertices.
/// The ovoid is the superovoid with g1 = g2 = g3 = 2.
class Superovoid : public PosedSurface {
 public:
  Superovoid(const Pose& pose, const Eigen::Vector3d& exponents, const Eigen::Vector4d& cx,
             const Eigen::Vector4d& cy, bool is_ovoid = false);
  std::string name() const override { return is_ovoid_ ? "ovoid" : "superovoid"; }
  Evaluation evaluateCanonical(const Eigen::Vector3d& u, int order) const override;
  Eigen::Vector3d canonicalPoint(double azimuth, double latitude) const override;

 private:
  Eigen::Vector3d exponents_;
  Eigen::Vector4d cx_, cy_;
  bool is_ovoid_;
};

}  // namespace articula::geometry
