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
  // The range in which the solver's double arithmetic holds (a length of
  // 1e6 squared and summed stays far from overflow; 1e-6 mm is below any
  // body's size): beyond it, results would be noise, so the shape is refused.
  constexpr double kMinRadius = 1e-6, kMaxLength = 1e6;
  for (int i = 0; i < 3; ++i) {
    if (!std::isfinite(radii[i]) || !(radii[i] >= kMinRadius && radii[i] <= kMaxLength))
      throw InvalidParameter(radius_names[i], "a radius from 1e-6 to 1e6 mm", radii[i]);
    if (!std::isfinite(exponents[i]) || !(exponents[i] >= 2.0))
      throw InvalidParameter(exponent_names[i], "a finite exponent >= 2 (smooth and convex)", exponents[i]);
    if (!std::isfinite(center[i]) || !(std::abs(center[i]) <= kMaxLength))
      throw InvalidParameter("center", "a coordinate within +-1e6 mm", center[i]);
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

namespace {

// e^x for a small multiplicative update (a Halley step's factor below, a
// power's change between nearby points): the library call when |x| is large;
// a Taylor polynomial once |x| is small (error below |x|^5 / 5! < 3e-20 for
// |x| <= 3e-4, |x|^9 / 9! < 6e-20 for |x| <= 0.03), which takes the call off
// the iteration's critical path. `bound` >= |x| picks the branch for all
// factors of one step at once.
double expOfStep(double x, double bound) {
  if (bound <= 3e-4) return 1.0 + x * (1.0 + x * (1.0 / 2 + x * (1.0 / 6 + x / 24)));
  if (bound > 0.03) return std::exp(x);
  return 1.0 + x * (1.0 + x * (1.0 / 2 + x * (1.0 / 6 + x * (1.0 / 24 + x * (1.0 / 120 + x * (1.0 / 720 + x * (1.0 / 5040 + x / 40320)))))));
}

// log(1 + x) for |x| <= 1e-3 by its series (error below |x|^7 / 7 < 2e-22).
double log1pSeries(double x) {
  return x * (1.0 - x * (1.0 / 2 - x * (1.0 / 3 - x * (1.0 / 4 - x * (1.0 / 5 - x / 6)))));
}

// log S near the root, where S - 1 is small, by the series; else std::log,
// whose error there only perturbs a step that the next one corrects.
double logNearOne(double S) { return std::fabs(S - 1.0) > 1e-3 ? std::log(S) : log1pSeries(S - 1.0); }

// |u|^(g-2) as exp((g/2 - 1) log u^2): cheaper than pow here (the
// common-normal solver's main cost), and exact for g = 2.
double powerMinusTwo(double g, double u) {
  const double u2 = u * u;
  return g == 2.0 ? 1.0 : u2 > 0.0 ? std::exp((0.5 * g - 1.0) * std::log(u2)) : 0.0;
}

// As geometry::absPower, from the powers |u_i|^(g_i - 2).
CanonicalEvaluation fromPowers(const ConvexShape& s, const Vector3d& u, const Vector3d& powers) {
  CanonicalEvaluation e{-1.0, Vector3d::Zero(), Vector3d::Zero(), powers};
  for (int i = 0; i < 3; ++i) {
    const double g = s.exponents[i], p = powers[i];
    e.value += u[i] * u[i] * p;
    e.gradient[i] = g * u[i] * p;
    e.hessian_diagonal[i] = g * (g - 1.0) * p;
  }
  return e;
}

}  // namespace

CanonicalEvaluation evaluateCanonical(const ConvexShape& s, const Vector3d& u) {
  if (s.quadric) return {u.squaredNorm() - 1.0, 2.0 * u, Vector3d::Constant(2.0), Vector3d::Ones()};
  Vector3d powers;
  for (int i = 0; i < 3; ++i) powers[i] = powerMinusTwo(s.exponents[i], u[i]);
  return fromPowers(s, u, powers);
}

CanonicalEvaluation evaluateCanonical(const ConvexShape& s, const Vector3d& u, const Vector3d& u_near,
                                      const CanonicalEvaluation& near) {
  if (s.quadric) return evaluateCanonical(s, u);
  Vector3d powers;
  for (int i = 0; i < 3; ++i) {
    const double ratio = (u[i] - u_near[i]) / u_near[i];  // u / u_near - 1: not finite when u_near = 0
    const double y = (s.exponents[i] - 2.0) * log1pSeries(ratio);
    powers[i] = std::fabs(ratio) <= 1e-3 ? near.powers[i] * expOfStep(y, std::fabs(y))
                                         : powerMinusTwo(s.exponents[i], u[i]);
  }
  return fromPowers(s, u, powers);
}

Vector3d supportCanonical(const ConvexShape& s, const Vector3d& v) {
  // max w . u subject to F(u) = 0, with w = D R^T v (v . x = w . u + v . c).
  const Vector3d w = s.radii.cwiseProduct(s.rotation.transpose() * v);
  if (s.quadric) return w / w.norm();
  // Lagrange: w_i = lambda g_i |u_i|^(g_i-1) sgn(u_i), so with mu = 1/lambda,
  // a_i = |w_i| / g_i and p_i = g_i / (g_i - 1) in (1, 2]: |u_i| = (mu a_i)^(p_i - 1),
  // and F = 0 reads S = sum_i (mu a_i)^p_i = 1. Put mu = e^tau / a_max: the
  // terms are T_i = r_i^p_i e^(p_i tau) with r_i = a_i / a_max <= 1, S(0) is
  // in [1, 3], and the root tau* in [-log 3, 0].
  // Reciprocals are taken of values known before the iteration, so that the
  // divisions stay off the chain of dependent operations that sets the latency.
  double a[3], p[3], inverse_r[3], log_r[3], term[3];
  int largest = 0;
  for (int i = 0; i < 3; ++i) {
    a[i] = std::fabs(w[i]) * (1.0 / s.exponents[i]);
    p[i] = s.exponents[i] / (s.exponents[i] - 1.0);
    if (a[i] > a[largest]) largest = i;
  }
  const double inverse_largest = 1.0 / a[largest];
  for (int i = 0; i < 3; ++i) {
    // r below 1e-300 is taken as 1e-300 in 1 / r (which would overflow): the
    // u_i it scales is then at most (1e-300)^(p_i - 1), zero to u's precision.
    inverse_r[i] = a[largest] / std::max(a[i], 1e-300 * a[largest]);
    log_r[i] = i == largest ? 0.0 : std::log(a[i] * inverse_largest);  // r = 0 gives -inf: a zero term
  }
  // Halley's method on f(tau) = log S: f' is the mean of the p_i weighted by
  // the terms, f'' their variance (<= 1/4), |f'''| < 0.1, so a step of size h
  // leaves an error of about K h^3 with K = |f'''/(6 f') - (f''/(2 f'))^2| < 0.032:
  // after a step under 1e-5 the error is below 4e-17, and the iteration stops.
  // With f' = S'/S and f'' = S''/S - f'^2, Halley's step 2 f f' / (2 f'^2 - f f'')
  // is 2 f S S' / ((2 + f) S'^2 - f S S''): one division per step; plain
  // Newton if that denominator is not positive.
  auto halleyStep = [&p](const double* t, double f) {
    const double S = t[0] + t[1] + t[2];
    const double dS = p[0] * t[0] + p[1] * t[1] + p[2] * t[2];
    const double d2S = p[0] * p[0] * t[0] + p[1] * p[1] * t[1] + p[2] * p[2] * t[2];
    const double denominator = (2.0 + f) * dS * dS - f * S * d2S;
    return denominator > 0.0 ? 2.0 * f * S * dS / denominator : f * S / dS;
  };
  // The first step, from tau = 0, is taken in single precision (expf and
  // logf, about 1e-7 relative, cost a fraction of the double calls): it only
  // places the start, where the terms are then computed in double, and the
  // steps below take out its error with the rest.
  double first_terms[3];
  for (int i = 0; i < 3; ++i) first_terms[i] = i == largest ? 1.0 : std::exp(static_cast<float>(p[i] * log_r[i]));
  const double first_step =
      halleyStep(first_terms, std::log(static_cast<float>(first_terms[0] + first_terms[1] + first_terms[2])));
  for (int i = 0; i < 3; ++i) term[i] = std::exp(p[i] * (log_r[i] - first_step));  // r^p e^(p tau)
  // tau itself is never formed: each step multiplies the terms by e^(-p_i h)
  // and `inverse_scale` (e^-tau) by e^h, polynomials once h is small (expOfStep).
  double inverse_scale = std::exp(first_step);
  for (int iteration = 0; iteration < 60; ++iteration) {
    const double step = halleyStep(term, logNearOne(term[0] + term[1] + term[2]));
    const double bound = 2.0 * std::fabs(step);  // >= |p_i step|
    for (int i = 0; i < 3; ++i) term[i] *= expOfStep(-p[i] * step, bound);
    inverse_scale *= expOfStep(step, bound);
    if (!(std::fabs(step) > 1e-5)) break;  // also ends on NaN (v = 0 or not finite)
  }
  // |u_i| = (mu a_i)^(p_i - 1) = T_i / (mu a_i), mu a_i = e^tau r_i.
  Vector3d u;
  for (int i = 0; i < 3; ++i) u[i] = term[i] > 0.0 ? std::copysign(term[i] * inverse_scale * inverse_r[i], w[i]) : 0.0;
  return u;
}

// With t_i = |u_i|^g_i on the surface (sum t_i = 1), the Hessian of F in
// global coordinates has eigenvalues H_j / r_j^2 = g_j (g_j - 1) t_j^(1 - 2/g_j) / r_j^2
// and the gradient's length is |D^-1 grad F| = sqrt(sum_i (g_i / r_i)^2 t_i^(2 - 2/g_i)),
// so every principal curvature is at most max_j (H_j / r_j^2) / |D^-1 grad F|.
// For each j the radius |D^-1 grad F| r_j^2 / H_j is bounded below by the
// larger of its own-component term r_j t_j^(1/g_j) / (g_j - 1) (increasing in
// t_j) and G r_j^2 / H_j (decreasing), G the least gradient length; the
// smaller of the two curves' crossing and the value at t_j = 1 bounds it.
double leastRadiusOfCurvature(const ConvexShape& s) {
  // G^2 >= min over the simplex of sum c_i t_i^P, c_i = (g_i / r_i)^2, P the
  // largest 2 - 2/g_i (t_i <= 1); by Lagrange that minimum is
  // c_min (sum (c_i / c_min)^(-1/(P-1)))^-(P-1), c_min for P = 1 (ellipsoids).
  double c[3], power = 1.0;
  for (int i = 0; i < 3; ++i) {
    c[i] = (s.exponents[i] / s.radii[i]) * (s.exponents[i] / s.radii[i]);
    power = std::max(power, 2.0 - 2.0 / s.exponents[i]);
  }
  const double c_min = std::min({c[0], c[1], c[2]});
  double g2 = c_min;
  if (power > 1.0) {
    double sum = 0.0;
    for (double ci : c) sum += std::pow(ci / c_min, -1.0 / (power - 1.0));
    g2 = c_min * std::pow(sum, -(power - 1.0));
  }
  const double gradient = std::sqrt(g2);
  double radius = INFINITY;
  for (int j = 0; j < 3; ++j) {
    const double g = s.exponents[j], r = s.radii[j], crossing = gradient * r / g;  // t* = crossing^(g / (g - 1))
    radius = std::min(radius, crossing <= 1.0 ? r * std::pow(crossing, 1.0 / (g - 1.0)) / (g - 1.0)
                                              : gradient * r * r / (g * (g - 1.0)));
  }
  return radius;
}

double boundingRadius(const ConvexShape& s) { return s.quadric ? s.radii.maxCoeff() : s.radii.norm(); }

}  // namespace articula::contact
