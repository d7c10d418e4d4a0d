#include "articula/geometry/surfaces.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "articula/core/error.hpp"
#include "articula/geometry/frames.hpp"
#include "articula/geometry/power.hpp"
#include "uv_sphere.hpp"

namespace articula::geometry {

using Eigen::Matrix3d;
using Eigen::Vector3d;

// ---------------------------------------------------------------- posed shapes

Evaluation PosedSurface::evaluate(const Vector3d& x, int order) const {
  Evaluation local = evaluateCanonical(pose_.toLocal(x), order);
  Evaluation global;
  global.value = local.value;
  if (order >= 1) global.gradient = map_ * local.gradient;
  if (order >= 2) global.hessian = map_ * local.hessian * map_.transpose();
  return global;
}

SurfaceMesh PosedSurface::sample(int azimuth_steps, int polar_steps, double /*extent*/) const {
  return uvSphereMesh(azimuth_steps, polar_steps, [this](double azimuth, double latitude) {
    return std::optional<Vector3d>(pose_.toGlobal(canonicalPoint(azimuth, latitude)));
  });
}

namespace {
Pose makePose(const ShapeParameters& p) {
  Pose pose;
  pose.rotation = rotationFromAngles(p.angles);
  pose.translation = p.center;
  pose.scale = p.model == ShapeModel::Sphere ? Vector3d::Constant(p.radii[0]) : p.radii;
  return pose;
}

Vector3d unitSpherePoint(double azimuth, double latitude) {
  return {std::cos(latitude) * std::cos(azimuth), std::cos(latitude) * std::sin(azimuth), std::sin(latitude)};
}

// F = |u|^2 - 1: the canonical form of the sphere and of the ellipsoid (the pose scales it).
Evaluation unitSphereEvaluation(const Vector3d& u, int order) {
  Evaluation e;
  e.value = u.squaredNorm() - 1.0;
  if (order >= 1) e.gradient = 2.0 * u;
  if (order >= 2) e.hessian = 2.0 * Matrix3d::Identity();
  return e;
}
}  // namespace

std::unique_ptr<PosedSurface> makeSurface(const ShapeParameters& p) {
  validate(p);
  switch (p.model) {
    case ShapeModel::Sphere: return std::make_unique<Sphere>(p.radii[0], p.center);
    case ShapeModel::Ellipsoid: return std::make_unique<Ellipsoid>(makePose(p));
    case ShapeModel::Superellipsoid: return std::make_unique<Superellipsoid>(makePose(p), p.exponents);
    case ShapeModel::Ovoid:
      return std::make_unique<Superovoid>(makePose(p), Vector3d::Constant(2.0), p.cx, p.cy, true);
    case ShapeModel::Superovoid: return std::make_unique<Superovoid>(makePose(p), p.exponents, p.cx, p.cy);
  }
  throw UsageError("unknown shape model");
}

// ---------------------------------------------------------------- sphere

namespace {
Pose spherePose(double radius, const Vector3d& center) {
  Pose pose;
  pose.translation = center;
  pose.scale.setConstant(radius);
  return pose;
}
}  // namespace

Sphere::Sphere(double radius, const Vector3d& center)
    : PosedSurface(spherePose(radius, center)), radius_(radius), center_(center) {
  if (!std::isfinite(radius) || !(radius > 0.0)) throw InvalidParameter("a", "a radius > 0 mm", radius);
}

Evaluation Sphere::evaluate(const Vector3d& x, int order) const {
  const double inv_r2 = 1.0 / (radius_ * radius_);
  const Vector3d d = x - center_;
  Evaluation e;
  e.value = d.squaredNorm() * inv_r2 - 1.0;
  if (order >= 1) e.gradient = 2.0 * inv_r2 * d;
  if (order >= 2) e.hessian = Matrix3d::Identity() * (2.0 * inv_r2);
  return e;
}

Evaluation Sphere::evaluateCanonical(const Vector3d& u, int order) const { return unitSphereEvaluation(u, order); }

Vector3d Sphere::canonicalPoint(double azimuth, double latitude) const {
  return unitSpherePoint(azimuth, latitude);
}

// ---------------------------------------------------------------- ellipsoid

Evaluation Ellipsoid::evaluateCanonical(const Vector3d& u, int order) const { return unitSphereEvaluation(u, order); }

Vector3d Ellipsoid::canonicalPoint(double azimuth, double latitude) const {
  return unitSpherePoint(azimuth, latitude);
}

// ---------------------------------------------------------------- superellipsoid

Superellipsoid::Superellipsoid(const Pose& pose, const Vector3d& exponents)
    : PosedSurface(pose), exponents_(exponents) {
  ShapeParameters p;
  p.model = ShapeModel::Superellipsoid;
  p.radii = pose.scale;
  p.exponents = exponents;
  validate(p);
}

Evaluation Superellipsoid::evaluateCanonical(const Vector3d& u, int order) const {
  Evaluation e;
  e.value = -1.0;
  for (int i = 0; i < 3; ++i) {
    const AbsPower t = absPower(u[i], exponents_[i]);
    e.value += t.value;
    e.gradient[i] = t.first;
    e.hessian(i, i) = t.second;
  }
  (void)order;  // the three powers give all orders at once
  return e;
}

Vector3d Superellipsoid::canonicalPoint(double azimuth, double latitude) const {
  const double cl = std::cos(latitude);
  return {signedPower(cl * std::cos(azimuth), 2.0 / exponents_[0]),
          signedPower(cl * std::sin(azimuth), 2.0 / exponents_[1]),
          signedPower(std::sin(latitude), 2.0 / exponents_[2])};
}

// ---------------------------------------------------------------- Barr's superellipsoid

BarrSuperellipsoid::BarrSuperellipsoid(const Pose& pose, double epsilon1, double epsilon2)
    : PosedSurface(pose), e1_(epsilon1), e2_(epsilon2) {
  ShapeParameters p;
  p.model = ShapeModel::Ellipsoid;
  p.radii = pose.scale;
  validate(p);
  for (auto [name, e] : {std::pair{"epsilon1", epsilon1}, std::pair{"epsilon2", epsilon2}})
    if (!std::isfinite(e) || !(e > 0.0) || e > 1.0)
      throw InvalidParameter(name, "a value in (0, 1] (exponents 2/epsilon >= 2: smooth and convex)", e);
}

Evaluation BarrSuperellipsoid::evaluateCanonical(const Vector3d& u, int /*order*/) const {
  const double n = 2.0 / e1_;  // exponent of |x| and |y| inside
  const double m = e1_ / e2_;  // outer exponent
  const AbsPower px = absPower(u[0], n), py = absPower(u[1], n), pz = absPower(u[2], 2.0 / e2_);
  const double s = px.value + py.value;
  Evaluation e;
  e.value = pz.value - 1.0;
  e.gradient[2] = pz.first;
  e.hessian(2, 2) = pz.second;
  if (s > 0.0) {
    const double sm = std::pow(s, m);
    e.value += sm;
    const double d1 = m * sm / s;                   // m s^(m-1)
    const double d2 = m * (m - 1.0) * sm / (s * s);  // m (m-1) s^(m-2)
    e.gradient[0] = d1 * px.first;
    e.gradient[1] = d1 * py.first;
    e.hessian(0, 0) = d2 * px.first * px.first + d1 * px.second;
    e.hessian(1, 1) = d2 * py.first * py.first + d1 * py.second;
    e.hessian(0, 1) = e.hessian(1, 0) = d2 * px.first * py.first;
  }
  return e;
}

Vector3d BarrSuperellipsoid::canonicalPoint(double azimuth, double latitude) const {
  const double c2 = signedPower(std::cos(latitude), e2_);
  return {signedPower(std::cos(azimuth), e1_) * c2, signedPower(std::sin(azimuth), e1_) * c2,
          signedPower(std::sin(latitude), e2_)};
}

// ---------------------------------------------------------------- superovoid

Superovoid::Superovoid(const Pose& pose, const Vector3d& exponents, const Eigen::Vector4d& cx,
                       const Eigen::Vector4d& cy, bool is_ovoid)
    : PosedSurface(pose), exponents_(exponents), cx_(cx), cy_(cy), is_ovoid_(is_ovoid) {
  ShapeParameters p;
  p.model = is_ovoid ? ShapeModel::Ovoid : ShapeModel::Superovoid;
  p.radii = pose.scale;
  p.exponents = exponents;
  p.cx = cx;
  p.cy = cy;
  validate(p);
  if (is_ovoid && exponents != Vector3d::Constant(2.0))
    throw InvalidParameter("gamma1", "2 for an ovoid", exponents[0]);
}

namespace {
// p(z), p'(z), p''(z) with z clamped to the closed component's slab [-1, 1].
struct Denominator {
  double p, dp, ddp;
};
Denominator denominator(const Eigen::Vector4d& c, double z) {
  if (z <= -1.0 || z >= 1.0) {
    const double zc = z < 0.0 ? -1.0 : 1.0;
    return {c[0] + zc * (c[1] + zc * (c[2] + zc * c[3])), 0.0, 0.0};
  }
  return {c[0] + z * (c[1] + z * (c[2] + z * c[3])), c[1] + z * (2.0 * c[2] + 3.0 * z * c[3]),
          2.0 * c[2] + 6.0 * z * c[3]};
}

// Adds |w / p(z)|^g, for the coordinate w at index i, to F and its derivatives.
void addRatioTerm(Evaluation& e, int i, double w, double g, const Denominator& d) {
  const double inv_p = 1.0 / d.p;
  const double q = w * inv_p;
  const AbsPower t = absPower(q, g);
  const double q_w = inv_p;
  const double q_z = -q * d.dp * inv_p;
  const double q_wz = -d.dp * inv_p * inv_p;
  const double q_zz = q * (2.0 * d.dp * d.dp * inv_p * inv_p - d.ddp * inv_p);
  e.value += t.value;
  e.gradient[i] += t.first * q_w;
  e.gradient[2] += t.first * q_z;
  e.hessian(i, i) += t.second * q_w * q_w;
  const double cross = t.second * q_w * q_z + t.first * q_wz;
  e.hessian(i, 2) += cross;
  e.hessian(2, i) += cross;
  e.hessian(2, 2) += t.second * q_z * q_z + t.first * q_zz;
}
}  // namespace

Evaluation Superovoid::evaluateCanonical(const Vector3d& u, int /*order*/) const {
  Evaluation e;
  const AbsPower tz = absPower(u[2], exponents_[2]);
  e.value = tz.value - 1.0;
  e.gradient[2] = tz.first;
  e.hessian(2, 2) = tz.second;
  addRatioTerm(e, 0, u[0], exponents_[0], denominator(cx_, u[2]));
  addRatioTerm(e, 1, u[1], exponents_[1], denominator(cy_, u[2]));
  return e;
}

Vector3d Superovoid::canonicalPoint(double azimuth, double latitude) const {
  const double cl = std::cos(latitude);
  const double z = signedPower(std::sin(latitude), 2.0 / exponents_[2]);
  return {denominator(cx_, z).p * signedPower(cl * std::cos(azimuth), 2.0 / exponents_[0]),
          denominator(cy_, z).p * signedPower(cl * std::sin(azimuth), 2.0 / exponents_[1]), z};
}

// ---------------------------------------------------------------- plane

Plane::Plane(const Vector3d& normal, const Vector3d& point) {
  const double n = normal.norm();
  if (!std::isfinite(n) || !(n > 0.0)) throw InvalidParameter("normal", "a non-zero finite vector", n);
  for (int i = 0; i < 3; ++i)
    if (!std::isfinite(point[i])) throw InvalidParameter("point", "finite coordinates", point[i]);
  normal_ = normal / n;
  offset_ = normal_.dot(point);
}

Evaluation Plane::evaluate(const Vector3d& x, int /*order*/) const {
  Evaluation e;
  e.value = normal_.dot(x) - offset_;
  e.gradient = normal_;
  return e;
}

SurfaceMesh Plane::sample(int azimuth_steps, int polar_steps, double extent) const {
  const TangentFrame f = householderFrame(normal_);
  const Vector3d origin = normal_ * offset_;
  return gridMesh(azimuth_steps, polar_steps, [&](double s, double t) {
    return std::optional<Vector3d>(origin + extent * (s * f.t + t * f.b));
  });
}

// ---------------------------------------------------------------- quadric

Quadric::Quadric(const Vector3d& a_ii, const Vector3d& a_i, const Matrix3d& rotation, const Vector3d& translation)
    : quadratic_(a_ii), linear_(a_i), rotation_(rotation), translation_(translation) {
  const char* qn[3] = {"a11", "a22", "a33"};
  const char* ln[3] = {"a1", "a2", "a3"};
  for (int i = 0; i < 3; ++i) {
    if (!std::isfinite(a_ii[i])) throw InvalidParameter(qn[i], "a finite coefficient", a_ii[i]);
    if (a_i[i] != 0.0 && a_i[i] != 1.0 && a_i[i] != -1.0)
      throw InvalidParameter(ln[i], "-1, 0 or 1 (eq. 2.9)", a_i[i]);
    if (a_ii[i] * a_i[i] != 0.0)
      throw InvalidParameter(ln[i], std::string("0 when ") + qn[i] + " != 0 (eq. 2.9)", a_i[i]);
  }
  if (quadratic_.isZero() && linear_.isZero()) throw InvalidParameter("a11", "a non-degenerate quadric", 0.0);
}

Evaluation Quadric::evaluate(const Vector3d& x, int order) const {
  const Vector3d l = rotation_.transpose() * (x - translation_);
  Evaluation e;
  e.value = quadratic_.dot(l.cwiseProduct(l)) + linear_.dot(l) - 1.0;
  if (order >= 1) e.gradient = rotation_ * (2.0 * quadratic_.cwiseProduct(l) + linear_);
  if (order >= 2) e.hessian = rotation_ * (2.0 * quadratic_).asDiagonal() * rotation_.transpose();
  return e;
}

SurfaceMesh Quadric::sample(int azimuth_steps, int polar_steps, double extent) const {
  return uvSphereMesh(azimuth_steps, polar_steps, [&](double azimuth, double latitude) -> std::optional<Vector3d> {
    const Vector3d d = unitSpherePoint(azimuth, latitude);
    // Eq. A.2 in its cancellation-free form: r = 2 / (r1 + sqrt(r1^2 + 4 r2)).
    const double r2 = quadratic_.dot(d.cwiseProduct(d));
    const double r1 = linear_.dot(d);
    const double disc = r1 * r1 + 4.0 * r2;
    if (disc < 0.0) return std::nullopt;
    const double denom = r1 + std::sqrt(disc);
    if (!(denom > 0.0)) return std::nullopt;
    const double r = 2.0 / denom;
    if (r > extent) return std::nullopt;
    return rotation_ * (r * d) + translation_;
  });
}

Quadric::Type Quadric::type() const {
  int pos = 0, neg = 0, zero_with_linear = 0;
  for (int i = 0; i < 3; ++i) {
    if (quadratic_[i] > 0) ++pos;
    else if (quadratic_[i] < 0) ++neg;
    else if (linear_[i] != 0) ++zero_with_linear;
  }
  if (pos == 3) return Type::Ellipsoid;
  if (pos == 2 && neg == 1) return Type::Hyperboloid1;
  if (pos == 1 && neg == 2) return Type::Hyperboloid2;
  if (pos == 2 && zero_with_linear == 1) return Type::EllipticParaboloid;
  if (pos == 1 && neg == 1 && zero_with_linear == 1) return Type::HyperbolicParaboloid;
  return Type::Other;
}

Vector3d Quadric::dimensions() const {
  Vector3d d;
  for (int i = 0; i < 3; ++i)
    d[i] = quadratic_[i] == 0.0 ? std::numeric_limits<double>::infinity() : 1.0 / std::sqrt(std::fabs(quadratic_[i]));
  return d;
}

}  // namespace articula::geometry
