#include "articula/contact/convex_shape.hpp"

#include <Eigen/LU>

#include <algorithm>
#include <cmath>

#include "articula/core/error.hpp"
#include "articula/geometry/pose.hpp"

namespace articula::contact {

using Eigen::Vector3d;

ConvexShape makeConvexShape(const Vector3d& center, const Eigen::Matrix3d& rotation, const Vector3d& radii,
                            const Vector3d& exponents) {
  static const char* radius_names[3] = {"a", "b", "c"};
  static const char* exponent_names[3] = {"gamma1", "gamma2", "gamma3"};
  for (int i = 0; i < 3; ++i) {
    if (!std::isfinite(radii[i]) || !(radii[i] > 0.0))
      throw InvalidParameter(radius_names[i], "a finite radius > 0 mm", radii[i]);
    if (!std::isfinite(exponents[i]) || !(exponents[i] >= 2.0))
      throw InvalidParameter(exponent_names[i], "a finite exponent >= 2 (smooth and convex)", exponents[i]);
    if (!std::isfinite(center[i])) throw InvalidParameter("center", "a finite coordinate (mm)", center[i]);
  }
  const double orthogonality = (rotation.transpose() * rotation - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (!std::isfinite(orthogonality) || orthogonality > 1e-9)
    throw InvalidParameter("rotation", "an orthonormal matrix (max |R^T R - I| <= 1e-9)", orthogonality);
  if (rotation.determinant() < 0.0)
    throw InvalidParameter("rotation", "a proper rotation (det +1)", rotation.determinant());
  ConvexShape s;
  s.center = center;
  s.rotation = rotation;
  s.radii = radii;
  s.exponents = exponents;
  s.quadric = (exponents.array() == 2.0).all();
  return s;
}

ConvexShape shapeFromParameters(const geometry::ShapeParameters& p) {
  using geometry::ShapeModel;
  const Eigen::Matrix3d R = geometry::rotationFromAngles(p.angles);
  switch (p.model) {
    case ShapeModel::Sphere: return makeConvexShape(p.center, R, Vector3d::Constant(p.radii[0]));
    case ShapeModel::Ellipsoid: return makeConvexShape(p.center, R, p.radii);
    case ShapeModel::Superellipsoid: return makeConvexShape(p.center, R, p.radii, p.exponents);
    default:
      throw UsageError("contact: model '" + geometry::modelName(p.model) +
                       "' is not supported (expected sphere, ellipsoid or superellipsoid: the "
                       "solver's start relies on central symmetry, which ovoids lack)");
  }
}

CanonicalEvaluation evaluateCanonical(const ConvexShape& s, const Vector3d& u) {
  if (s.quadric) return {u.squaredNorm() - 1.0, 2.0 * u, Vector3d::Constant(2.0)};
  // As geometry::absPower, with |u|^(g-2) as exp((g/2 - 1) log u^2): cheaper
  // than pow here (the solver's main cost), and exact for g = 2.
  CanonicalEvaluation e{-1.0, Vector3d::Zero(), Vector3d::Zero()};
  for (int i = 0; i < 3; ++i) {
    const double g = s.exponents[i], u2 = u[i] * u[i];
    const double p = g == 2.0 ? 1.0 : u2 > 0.0 ? std::exp((0.5 * g - 1.0) * std::log(u2)) : 0.0;  // |u|^(g-2)
    e.value += u2 * p;
    e.gradient[i] = g * u[i] * p;
    e.hessian_diagonal[i] = g * (g - 1.0) * p;
  }
  return e;
}

Vector3d supportCanonical(const ConvexShape& s, const Vector3d& v) {
  // max w . u subject to F(u) = 0, with w = D R^T v (v . x = w . u + v . c).
  const Vector3d w = s.radii.cwiseProduct(s.rotation.transpose() * v);
  if (s.quadric) return w / w.norm();
  // Lagrange: w_i = lambda g_i |u_i|^(g_i-1) sgn(u_i), so with mu = 1/lambda,
  // a_i = |w_i| / g_i and p_i = g_i / (g_i - 1): |u_i| = (mu a_i)^(p_i - 1),
  // and F = 0 reads S(t) = sum_i exp(p_i x_i) = 1 with x_i = t + log a_i, t = log mu.
  // Start: with x_i <= 0 near the root, exp(p_i x_i) >= exp(p_max x_i), so
  // the root of sum_i exp(p_max x_i) = 1 lies right of the root (S >= 1 there).
  double a[3], log_a[3], p[3];
  bool active[3];
  double p_max = 0.0, log_a_max = -INFINITY;
  for (int i = 0; i < 3; ++i) {
    active[i] = w[i] != 0.0;
    a[i] = std::fabs(w[i]) / s.exponents[i];
    log_a[i] = active[i] ? std::log(a[i]) : 0.0;
    p[i] = s.exponents[i] / (s.exponents[i] - 1.0);
    if (active[i]) p_max = std::max(p_max, p[i]), log_a_max = std::max(log_a_max, log_a[i]);
  }
  double sum = 0.0;
  for (int i = 0; i < 3; ++i)
    if (active[i]) sum += log_a[i] == log_a_max ? 1.0 : std::exp(p_max * (log_a[i] - log_a_max));
  double t = -log_a_max - std::log(sum) / p_max;
  // Halley's method on f = log S (f' = mean of p_i weighted by the terms, f''
  // their variance <= 1/4): cubic convergence, so a step under 1e-6 leaves the
  // error at rounding; plain Newton if Halley's denominator is not positive.
  double term[3] = {0.0, 0.0, 0.0}, step = 0.0;
  for (int iteration = 0; iteration < 60; ++iteration) {
    double S = 0.0, dS = 0.0, d2S = 0.0;
    for (int i = 0; i < 3; ++i) {
      if (!active[i]) continue;
      term[i] = std::exp(p[i] * (t + log_a[i]));
      S += term[i];
      dS += p[i] * term[i];
      d2S += p[i] * p[i] * term[i];
    }
    const double f = std::log(S), f1 = dS / S, f2 = d2S / S - f1 * f1;
    const double denominator = 2.0 * f1 * f1 - f * f2;
    step = denominator > 0.0 ? 2.0 * f * f1 / denominator : f / f1;
    t -= step;
    if (std::fabs(step) <= 1e-6 * (1.0 + std::fabs(t))) break;
  }
  // |u_i| = exp((p_i - 1) x_i) = exp(p_i x_i) / (a_i e^t) at the final t; the
  // terms exp(p_i x_i) of the last evaluation move by the factor exp(-p_i step),
  // for |p_i step| < 1e-4 (the usual end) a cubic Taylor polynomial is exact to rounding.
  const double mu = std::exp(t);
  Vector3d u = Vector3d::Zero();
  for (int i = 0; i < 3; ++i) {
    if (!active[i]) continue;
    const double x = p[i] * step;
    const double shift = std::fabs(x) < 1e-4 ? 1.0 - x * (1.0 - x * (0.5 - x / 6.0)) : std::exp(-x);
    u[i] = std::copysign(term[i] * shift / (a[i] * mu), w[i]);
  }
  return u;
}

double boundingRadius(const ConvexShape& s) { return s.quadric ? s.radii.maxCoeff() : s.radii.norm(); }

}  // namespace articula::contact
