#pragma once
// Exact signed Euclidean distance (thesis eq. 3.4, without the box of eq. 3.6)
// from points to a shape model of the hierarchy, with the closest surface
// point. Negative inside, as F. Global LPS millimetres throughout.
//
// Sphere: closed form. Ellipsoid: Eberly's robust root bracketing.
// Superellipsoid, ovoid, superovoid: Newton on the closest-point conditions
// q - x + mu grad F(q) = 0, F(q) = 0, started from the nearest point of a
// precomputed surface sample; inside, the sample's triangles whose planes
// are nearer than the best distance so far (the surface in their cone lies
// beyond them) are tried too (deep interior points, points near the medial
// axis), and a projected descent on the surface takes over where Newton fails.
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "articula/geometry/shape.hpp"
#include "articula/geometry/surface.hpp"

namespace articula::distance {

struct ClosestPoint {
  double distance = 0.0;                            // signed, mm
  Eigen::Vector3d point = Eigen::Vector3d::Zero();  // closest surface point, mm
};

class SignedDistance {
 public:
  /// Validates `shape` (InvalidParameter otherwise). evaluate() splits its
  /// points over `threads` threads (0: every hardware thread).
  explicit SignedDistance(const geometry::ShapeParameters& shape, int threads = 1);
  ~SignedDistance();
  SignedDistance(SignedDistance&&) noexcept;
  SignedDistance& operator=(SignedDistance&&) noexcept;

  const geometry::ShapeParameters& shape() const { return shape_; }

  /// The global minimum of the distance: exact for any point.
  ClosestPoint closest(const Eigen::Vector3d& x) const;

  /// Local refinement from `guess` (e.g. the closest point on a nearby shape,
  /// as during fitting); falls back to closest() if it does not converge.
  /// Exact whenever `guess` lies in the basin of the global minimum.
  ClosestPoint closestFrom(const Eigen::Vector3d& x, const Eigen::Vector3d& guess) const;

  /// The global minimum like closest(), started from `guess`: a point
  /// outside whose local minimum is found from there needs no global search
  /// (the projection onto a convex body is its only stationary point with the
  /// point on the outer side); every other point gets closest().
  ClosestPoint closestExactFrom(const Eigen::Vector3d& x, const Eigen::Vector3d& guess) const;

  /// How evaluate() uses `feet` on entry.
  enum class Start {
    Cold,        // ignored: closest() for every point (exact)
    Warm,        // guesses, refined locally (closestFrom: fitting)
    WarmExact,   // guesses that spare global searches (closestExactFrom: exact)
  };

  /// Signed distances of `points` (#P x 3) into `d` (#P) and closest points
  /// into `feet` (#P x 3); `feet` on entry are used as `start` says when
  /// they have #P rows.
  void evaluate(const Eigen::MatrixX3d& points, Eigen::VectorXd& d, Eigen::MatrixX3d& feet, Start start) const;
  /// evaluate() with Start::Warm when `warm`, else Start::Cold.
  void evaluate(const Eigen::MatrixX3d& points, Eigen::VectorXd& d, Eigen::MatrixX3d& feet, bool warm = false) const {
    evaluate(points, d, feet, warm ? Start::Warm : Start::Cold);
  }

 private:
  bool newton(const Eigen::Vector3d& x, const Eigen::Vector3d& start, ClosestPoint& result) const;
  /// Newton from `guess`, else (or, with outside_only, for a point not outside) closest().
  ClosestPoint refineFrom(const Eigen::Vector3d& x, const Eigen::Vector3d& guess, bool outside_only) const;
  ClosestPoint descent(const Eigen::Vector3d& x, const Eigen::Vector3d& start) const;
  Eigen::Vector3d radialProjection(const Eigen::Vector3d& x) const;

  geometry::ShapeParameters shape_;
  int threads_ = 1;
  std::unique_ptr<geometry::PosedSurface> surface_;
  geometry::Pose pose_;
  Eigen::Matrix3d rotation_;
  void buildSeeds() const;
  // Built on first use, so that warm-started evaluation (fitting) skips it.
  mutable Eigen::MatrixX3d seeds_;  // surface sample in the rotated frame (mm)
  mutable double seed_spacing_ = 0.0;
  mutable Eigen::MatrixX3i triangles_;   // the sample's triangles (seed indices)
  mutable Eigen::MatrixX4d planes_;     // their planes: outward unit normal, offset (-inf: no bound)
  // Runs of consecutive triangles: mean normal, largest normal deviation,
  // smallest offset; a lower bound for all their planes at once.
  mutable Eigen::Matrix<double, Eigen::Dynamic, 5> groups_;
};

/// Signed distances of `points` (#P x 3) to `shape`: convenience over SignedDistance.
Eigen::VectorXd signedDistances(const geometry::ShapeParameters& shape, const Eigen::MatrixX3d& points, int threads = 1);

}  // namespace articula::distance
