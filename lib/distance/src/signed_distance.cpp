#include "articula/distance/signed_distance.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <Eigen/LU>

#include "articula/core/parallel.hpp"
#include "articula/distance/ellipsoid_distance.hpp"
#include "articula/geometry/pose.hpp"

namespace articula::distance {

using Eigen::Matrix3d;
using Eigen::Vector3d;
using geometry::ShapeModel;

namespace {
// F, gradient and Hessian in the shape's rotated but unscaled frame
// y = R^T (x - t), where Euclidean distances are the global ones.
struct LocalEvaluation {
  double value;
  Vector3d gradient;
  Matrix3d hessian;
};

constexpr Eigen::Index kGroup = 6;  // triangles per bounding run
bool isQuadric(ShapeModel m) { return m == ShapeModel::Sphere || m == ShapeModel::Ellipsoid; }
}  // namespace

SignedDistance::SignedDistance(const geometry::ShapeParameters& shape, int threads)
    : shape_(shape), threads_(resolveThreads(threads)), surface_(geometry::makeSurface(shape)), pose_(surface_->pose()), rotation_(pose_.rotation) {}

void SignedDistance::buildSeeds() const {
  // Seeds: an exact parametric sample of the surface, and the longest edge
  // between neighbours, which bounds how far any surface point is from a seed.
  const geometry::SurfaceMesh mesh = surface_->sample(32, 16);
  seeds_.resize(mesh.vertices.rows(), 3);
  for (Eigen::Index i = 0; i < mesh.vertices.rows(); ++i)
    seeds_.row(i) = (rotation_.transpose() * (mesh.vertices.row(i).transpose() - pose_.translation)).transpose();
  for (Eigen::Index f = 0; f < mesh.triangles.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const double edge =
          (seeds_.row(mesh.triangles(f, k)) - seeds_.row(mesh.triangles(f, (k + 1) % 3))).norm();
      seed_spacing_ = std::max(seed_spacing_, edge);
    }
  // Each triangle's plane, outward. The triangles are inscribed in the convex
  // body and close around the local origin, so the surface within the cone of
  // a triangle seen from the origin lies beyond its plane: the plane's
  // distance bounds the distance to that part of the surface from below.
  // A triangle whose plane does not keep the origin inside gets no bound.
  triangles_ = mesh.triangles;
  planes_.resize(mesh.triangles.rows(), 4);
  for (Eigen::Index f = 0; f < mesh.triangles.rows(); ++f) {
    const Vector3d a = seeds_.row(mesh.triangles(f, 0)).transpose();
    const Vector3d b = seeds_.row(mesh.triangles(f, 1)).transpose();
    const Vector3d c = seeds_.row(mesh.triangles(f, 2)).transpose();
    const Vector3d n = (b - a).cross(c - a);
    const double len = n.norm();
    const double offset = len > 0.0 ? n.dot(a) / len : 0.0;
    if (len > 1e-12 * seed_spacing_ * seed_spacing_ && offset > 1e-9 * seed_spacing_)
      planes_.row(f) << n.transpose() / len, offset;
    else
      planes_.row(f) << 0.0, 0.0, 0.0, -std::numeric_limits<double>::infinity();
  }
  // The sample's triangles come in strips, so consecutive ones are close:
  // o_f - n_f.y >= min o - n.y - max |n_f - n| |y| bounds a run's planes.
  const Eigen::Index groups = (planes_.rows() + kGroup - 1) / kGroup;
  groups_.resize(groups, 5);
  for (Eigen::Index g = 0; g < groups; ++g) {
    const Eigen::Index begin = g * kGroup, end = std::min(begin + kGroup, planes_.rows());
    Vector3d n = Vector3d::Zero();
    double offset = std::numeric_limits<double>::infinity();
    for (Eigen::Index f = begin; f < end; ++f) {
      n += planes_.block<1, 3>(f, 0).transpose();
      offset = std::min(offset, planes_(f, 3));
    }
    n = n.norm() > 0.0 ? Vector3d(n.normalized()) : Vector3d::UnitZ();
    double spread = 0.0;
    for (Eigen::Index f = begin; f < end; ++f)
      spread = std::max(spread, (planes_.block<1, 3>(f, 0).transpose() - n).norm());
    groups_.row(g) << n.transpose(), spread, offset;
  }
}

SignedDistance::~SignedDistance() = default;
SignedDistance::SignedDistance(SignedDistance&&) noexcept = default;
SignedDistance& SignedDistance::operator=(SignedDistance&&) noexcept = default;

namespace {
LocalEvaluation evaluateLocal(const geometry::PosedSurface& s, const Vector3d& inv_radii, const Vector3d& y) {
  const geometry::Evaluation e = s.evaluateCanonical(y.cwiseProduct(inv_radii), 2);
  return {e.value, e.gradient.cwiseProduct(inv_radii),
          inv_radii.asDiagonal() * e.hessian * inv_radii.asDiagonal()};
}
}  // namespace

Vector3d SignedDistance::radialProjection(const Vector3d& y) const {
  // Every ray from the local origin (inside: F = -1) leaves the convex body
  // exactly once: Newton along the ray from y's own place (near the surface
  // where it is used), kept within a bracket of the crossing, bisection
  // where a step would leave it.
  const Vector3d inv_r = pose_.scale.cwiseInverse();
  const Vector3d u = y.cwiseProduct(inv_r);
  const double len = u.norm();
  if (!(len > 0.0)) return Vector3d(0.0, 0.0, pose_.scale[2]);
  const Vector3d dir = u / len;
  double lo = 0.0, hi = std::numeric_limits<double>::infinity();
  double s = len;
  for (int i = 0; i < 200; ++i) {
    const geometry::Evaluation e = surface_->evaluateCanonical(s * dir, 1);
    if (e.value == 0.0) break;
    (e.value < 0.0 ? lo : hi) = s;
    const double slope = e.gradient.dot(dir);
    double next = slope > 0.0 ? s - e.value / slope : std::numeric_limits<double>::quiet_NaN();
    // Converged: a Newton step from |F| < 1e-9 lands within rounding.
    if (next > lo && next < hi && std::fabs(e.value) < 1e-9) {
      s = next;
      break;
    }
    if (!(next > lo && next < hi)) next = std::isfinite(hi) ? 0.5 * (lo + hi) : 2.0 * s;
    if (std::fabs(next - s) <= 1e-15 * s || hi - lo <= 1e-15 * hi) {
      s = next;
      break;
    }
    s = next;
  }
  return (s * dir).cwiseProduct(pose_.scale);
}

bool SignedDistance::newton(const Vector3d& y, const Vector3d& start, ClosestPoint& result) const {
  const Vector3d inv_r = pose_.scale.cwiseInverse();
  const double scale = pose_.scale.maxCoeff();
  Vector3d q = start;
  LocalEvaluation e = evaluateLocal(*surface_, inv_r, q);
  double mu = (y - q).dot(e.gradient) / e.gradient.squaredNorm();
  auto merit = [&](const Vector3d& qq, double m, const LocalEvaluation& ee) {
    return (qq - y + m * ee.gradient).squaredNorm() + ee.value * ee.value / ee.gradient.squaredNorm();
  };
  double current = merit(q, mu, e);
  const double tolerance = 1e-12 * scale;
  for (int iteration = 0;; ++iteration) {
    if (current <= tolerance * tolerance) break;
    if (iteration == 60) return false;
    Eigen::Matrix4d J;
    J.topLeftCorner<3, 3>() = Matrix3d::Identity() + mu * e.hessian;
    J.topRightCorner<3, 1>() = e.gradient;
    J.bottomLeftCorner<1, 3>() = e.gradient.transpose();
    J(3, 3) = 0.0;
    Eigen::Vector4d r;
    r.head<3>() = q - y + mu * e.gradient;
    r[3] = e.value;
    // Eigen's closed-form 4 x 4 inverse is several times cheaper than its
    // pivoted LU (a sixth of the fitting time, measured); LU where it fails.
    Eigen::Vector4d step = Eigen::Vector4d::Constant(std::numeric_limits<double>::quiet_NaN());
    if (J.determinant() != 0.0) step = J.inverse() * -r;
    if (!step.allFinite()) step = J.partialPivLu().solve(-r);
    if (!step.allFinite()) return false;
    // A step that must be cut below 1/16 heads for a singular point of the
    // conditions, where the merit stalls short of zero: the caller's descent
    // is cheaper than halving on.
    double alpha = 1.0;
    bool accepted = false;
    for (int k = 0; k < 5; ++k, alpha *= 0.5) {
      const Vector3d q_new = q + alpha * step.head<3>();
      const double mu_new = mu + alpha * step[3];
      const LocalEvaluation e_new = evaluateLocal(*surface_, inv_r, q_new);
      const double m_new = merit(q_new, mu_new, e_new);
      if (m_new < current) {
        q = q_new;
        mu = mu_new;
        e = e_new;
        current = m_new;
        accepted = true;
        break;
      }
    }
    // Stalled: accept only at (near) rounding level.
    if (!accepted) {
      if (current > 1e4 * tolerance * tolerance) return false;
      break;
    }
  }
  const double dist = (y - q).norm();
  // y = q + mu grad F(q): the sign of mu says which side of the tangent plane
  // y is, which for a convex body is inside or outside. Very near the surface
  // F(y) itself decides.
  const bool inside = dist > 1e-6 * scale ? mu < 0.0 : evaluateLocal(*surface_, inv_r, y).value < 0.0;
  result.distance = inside ? -dist : dist;
  result.point = q;
  return true;
}

ClosestPoint SignedDistance::descent(const Vector3d& y, const Vector3d& start) const {
  // Safeguard where Newton on the closest-point conditions fails (near points
  // where they are singular): Newton on the surface itself within a trust
  // region, steps in the tangent plane projected back radially, only shorter
  // distances accepted (it cannot diverge, and converges fast where Newton
  // did not).
  const Vector3d inv_r = pose_.scale.cwiseInverse();
  const double scale = pose_.scale.maxCoeff();
  Vector3d q = radialProjection(start);
  double best = (y - q).squaredNorm();
  double radius = seed_spacing_ > 0.0 ? seed_spacing_ : 0.1 * scale;
  double handover = 1e-4;
  for (int i = 0; i < 200; ++i) {
    const LocalEvaluation e = evaluateLocal(*surface_, inv_r, q);
    const Vector3d n = e.gradient.normalized();
    const Vector3d v = q - y;
    // Tangent basis and the reduced problem: gradient b, Hessian A of the
    // Lagrangian |q - y|^2 / 2 + mu F, mu from v + mu grad F = 0.
    const Vector3d t1 = n.unitOrthogonal(), t2 = n.cross(t1);
    Eigen::Matrix<double, 3, 2> T;
    T << t1, t2;
    const double mu = -v.dot(e.gradient) / e.gradient.squaredNorm();
    const Eigen::Vector2d b = T.transpose() * v;
    if (b.norm() <= 1e-13 * scale) break;
    // Close to a minimum Newton converges in a step or two, where the descent
    // would creep down to rounding level; if it lands elsewhere, go on.
    if (b.norm() <= handover * scale) {
      ClosestPoint polished;
      if (newton(y, q, polished) && std::fabs(polished.distance) <= std::sqrt(best)) return polished;
      handover *= 1e-3;
    }
    const Eigen::Matrix2d A = T.transpose() * (Matrix3d::Identity() + mu * e.hessian) * T;
    const Eigen::Vector2d eig = Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(A, Eigen::EigenvaluesOnly).eigenvalues();
    // Damped enough for a convex model; the step cut to the trust radius.
    const double lambda = std::max(0.0, -eig[0]) + 1e-3 * std::max(1e-3, std::fabs(eig[1]));
    Eigen::Vector2d w = -(A + lambda * Eigen::Matrix2d::Identity()).ldlt().solve(b);
    bool accepted = false;
    for (int k = 0; k < 60; ++k) {
      if (w.norm() > radius) w *= radius / w.norm();
      if (w.norm() <= 1e-15 * scale) break;
      const Vector3d candidate = radialProjection(q + T * w);
      const double dist2 = (y - candidate).squaredNorm();
      if (dist2 < best) {
        q = candidate;
        best = dist2;
        radius = std::max(radius, 2.0 * w.norm());
        accepted = true;
        break;
      }
      radius = 0.25 * w.norm();
    }
    if (!accepted) break;
  }
  ClosestPoint result;
  // Newton polishes the minimum found (to the tolerance of its conditions).
  if (newton(y, q, result) && std::fabs(result.distance) <= std::sqrt(best)) return result;
  result.point = q;
  result.distance = evaluateLocal(*surface_, inv_r, y).value < 0.0 ? -std::sqrt(best) : std::sqrt(best);
  return result;
}

ClosestPoint SignedDistance::closest(const Vector3d& x) const {
  ClosestPoint result;
  if (shape_.model == ShapeModel::Sphere) {
    const Vector3d v = x - shape_.center;
    const double len = v.norm();
    const Vector3d dir = len > 0.0 ? Vector3d(v / len) : Vector3d::UnitZ();
    result.distance = len - shape_.radii[0];
    result.point = shape_.center + shape_.radii[0] * dir;
    return result;
  }
  const Vector3d y = rotation_.transpose() * (x - pose_.translation);
  if (shape_.model == ShapeModel::Ellipsoid) {
    Vector3d q;
    result.distance = ellipsoidClosestPoint(pose_.scale, y, q);
    result.point = rotation_ * q + pose_.translation;
    return result;
  }
  if (seeds_.rows() == 0) buildSeeds();
  // Nearest seed first.
  Eigen::Index nearest = 0;
  const Eigen::VectorXd seed_d2 = (seeds_.rowwise() - y.transpose()).rowwise().squaredNorm();
  seed_d2.minCoeff(&nearest);
  auto solve = [&](const Vector3d& start) {
    ClosestPoint c;
    if (!newton(y, start, c)) c = descent(y, start);
    return c;
  };
  ClosestPoint best;
  const Vector3d first = seeds_.row(nearest).transpose();
  if (newton(y, first, best)) {
    // A stationary point with y on its outer side is y's projection onto the
    // convex body: the global minimum, no other seed can do better.
    if (best.distance > 0.0) {
      best.point = rotation_ * best.point + pose_.translation;
      return best;
    }
  } else {
    best = descent(y, first);
  }
  // Any nearer minimum lies in the cone of a triangle whose plane is nearer
  // than the best distance so far, within one seed spacing of a vertex closer
  // than |d| + spacing: those triangles are tried from their vertex nearest
  // to y unless it is within two spacings of a start tried or a minimum
  // found. Within half a spacing of the surface every such vertex is.
  const double h = seed_spacing_;
  if (std::fabs(best.distance) <= 0.5 * h) {
    best.point = rotation_ * best.point + pose_.translation;
    return best;
  }
  thread_local std::vector<Vector3d> found;  // reused: no allocation per point
  found.assign({first, best.point});
  thread_local Eigen::VectorXd group_bound;
  group_bound.noalias() = groups_.col(4) - groups_.leftCols<3>() * y;
  group_bound.array() -= y.norm() * groups_.col(3).array();
  // A vertex once considered is near a start or minimum from then on: each is
  // compared with those found once, not for each of its triangles.
  thread_local std::vector<std::uint32_t> seen;
  thread_local std::uint32_t stamp = 0;
  if (seen.size() < static_cast<size_t>(seeds_.rows()) || ++stamp == 0) {
    seen.assign(std::max(seen.size(), static_cast<size_t>(seeds_.rows())), 0);
    stamp = 1;
  }
  for (Eigen::Index g = 0; g < group_bound.size(); ++g) {
    if (group_bound[g] >= std::fabs(best.distance)) continue;
    for (Eigen::Index f = g * kGroup; f < std::min((g + 1) * kGroup, planes_.rows()); ++f) {
      const double reach = std::fabs(best.distance) + h;
      if (planes_(f, 3) - planes_.block<1, 3>(f, 0).dot(y.transpose()) >= std::fabs(best.distance)) continue;
      Eigen::Index v = triangles_(f, 0);
      for (int k = 1; k < 3; ++k)
        if (seed_d2[triangles_(f, k)] < seed_d2[v]) v = triangles_(f, k);
      if (seed_d2[v] >= reach * reach || seen[v] == stamp) continue;
      seen[v] = stamp;
      const Vector3d s = seeds_.row(v).transpose();
      bool near_known = false;
      for (const Vector3d& known : found)
        if ((s - known).squaredNorm() < 4.0 * h * h) near_known = true;
      if (near_known) continue;
      const ClosestPoint c = solve(s);
      found.push_back(s);
      found.push_back(c.point);
      if (std::fabs(c.distance) < std::fabs(best.distance)) best = c;
    }
  }
  best.point = rotation_ * best.point + pose_.translation;
  return best;
}

ClosestPoint SignedDistance::closestExactFrom(const Vector3d& x, const Vector3d& guess) const {
  return refineFrom(x, guess, true);
}

ClosestPoint SignedDistance::closestFrom(const Vector3d& x, const Vector3d& guess) const {
  return refineFrom(x, guess, false);
}

ClosestPoint SignedDistance::refineFrom(const Vector3d& x, const Vector3d& guess, bool outside_only) const {
  if (isQuadric(shape_.model)) return closest(x);
  const Vector3d y = rotation_.transpose() * (x - pose_.translation);
  ClosestPoint c;
  if (!newton(y, rotation_.transpose() * (guess - pose_.translation), c) || (outside_only && !(c.distance > 0.0)))
    return closest(x);
  c.point = rotation_ * c.point + pose_.translation;
  return c;
}

void SignedDistance::evaluate(const Eigen::MatrixX3d& points, Eigen::VectorXd& d, Eigen::MatrixX3d& feet,
                              Start start) const {
  const Eigen::Index n = points.rows();
  d.resize(n);
  if (feet.rows() != n) {
    start = Start::Cold;
    feet.resize(n, 3);
  }
  // The seeds are built lazily by closest(); once, before threads share them.
  constexpr Eigen::Index kChunk = 2048;
  if (n >= 2 * kChunk && threads_ > 1 && !isQuadric(shape_.model) && seeds_.rows() == 0) buildSeeds();
  parallelFor(n, kChunk, threads_, [&](std::ptrdiff_t begin, std::ptrdiff_t end) {
    for (Eigen::Index i = begin; i < end; ++i) {
      const Vector3d x = points.row(i).transpose();
      const ClosestPoint c = start == Start::Warm        ? closestFrom(x, feet.row(i).transpose())
                             : start == Start::WarmExact ? closestExactFrom(x, feet.row(i).transpose())
                                                         : closest(x);
      d[i] = c.distance;
      feet.row(i) = c.point.transpose();
    }
  });
}

Eigen::VectorXd signedDistances(const geometry::ShapeParameters& shape, const Eigen::MatrixX3d& points, int threads) {
  Eigen::VectorXd d;
  Eigen::MatrixX3d feet;
  SignedDistance(shape, threads).evaluate(points, d, feet);
  return d;
}

}  // namespace articula::distance
