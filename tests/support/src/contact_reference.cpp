#include "articula/testsupport/contact_reference.hpp"

#include <Eigen/Geometry>
#include <Eigen/QR>

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "articula/core/error.hpp"

namespace articula::contact {

namespace {
using Vec3L = Eigen::Matrix<long double, 3, 1>;
using Mat3L = Eigen::Matrix<long double, 3, 3>;

// A shape in long double with its support point x(v) (global, maximiser of v . x).
struct ShapeL {
  Mat3L rotation, m;  // m = R D^2 R^T (quadrics)
  Vec3L radii, exponents, center;
  bool quadric;

  explicit ShapeL(const ConvexShape& s)
      : rotation(s.rotation.cast<long double>()),
        radii(s.radii.cast<long double>()),
        exponents(s.exponents.cast<long double>()),
        center(s.center.cast<long double>()),
        quadric(s.quadric) {
    m = rotation * radii.cwiseAbs2().asDiagonal() * rotation.transpose();
  }

  Vec3L support(const Vec3L& v) const {
    if (quadric) return center + m * v / std::sqrt(v.dot(m * v));
    // Lagrange: |u_i| = (mu |w_i| / g_i)^(1 / (g_i - 1)), w = D R^T v; with
    // t = log mu, f(t) = log sum_i exp(p_i (t + log a_i)) (p_i = g_i / (g_i - 1),
    // a_i = |w_i| / g_i) is increasing and convex, so plain Newton from a
    // point right of the root (one term equal to 1) descends monotonically to it.
    const Vec3L w = radii.cwiseProduct(rotation.transpose() * v);
    long double log_a[3], p[3], t = INFINITY;
    for (int i = 0; i < 3; ++i) {
      p[i] = exponents[i] / (exponents[i] - 1.0L);
      log_a[i] = w[i] != 0.0L ? std::log(std::fabs(w[i]) / exponents[i]) : -INFINITY;
      if (w[i] != 0.0L) t = std::min(t, -log_a[i]);
    }
    for (int it = 0; it < 200; ++it) {
      long double S = 0.0L, dS = 0.0L;
      for (int i = 0; i < 3; ++i) {
        const long double term = std::exp(p[i] * (t + log_a[i]));
        S += term;
        dS += p[i] * term;
      }
      const long double step = std::log(S) * S / dS;
      if (!(step > 0.0L)) break;  // at the root to rounding
      t -= step;
      if (step <= 1e-18L * (1.0L + std::fabs(t))) break;
    }
    Vec3L u;
    for (int i = 0; i < 3; ++i)
      u[i] = w[i] != 0.0L ? std::copysign(std::exp((t + log_a[i]) / (exponents[i] - 1.0L)), w[i]) : 0.0L;
    return center + rotation * radii.cwiseProduct(u);
  }
};

// s(v) and its gradient x_B(-v) - x_A(v).
long double dual(const ShapeL& a, const ShapeL& b, const Vec3L& v, Vec3L* gradient) {
  const Vec3L g = b.support(-v) - a.support(v);
  if (gradient) *gradient = g;
  return v.dot(g);
}

// Unit outward normal of the shape at canonical u (F = sum |u_i|^g_i - 1).
Vec3L normalAt(const ShapeL& s, const Vec3L& u) {
  Vec3L grad;
  for (int i = 0; i < 3; ++i) grad[i] = s.exponents[i] * u[i] * std::pow(std::fabs(u[i]), s.exponents[i] - 2.0L);
  return (s.rotation * grad.cwiseQuotient(s.radii)).normalized();
}
Vec3L canonicalOf(const ShapeL& s, const Vec3L& x) {
  return (s.rotation.transpose() * (x - s.center)).cwiseQuotient(s.radii);
}

// Polishes the climb's maximiser v by Gauss-Newton on the common-normal
// conditions in the canonical coordinates of both points (8 equations, 6
// unknowns, central-difference Jacobian): F_A = F_B = 0, n_A x n_B = 0,
// (x_B - x_A) x n_A = 0. The climb alone crawls (and Newton in v diverges) where
// the answer lies in a flat region of a superellipsoid: there the support
// point moves like a cube root of v. The pair found is kept when it is a
// contact pair (opposite normals): its signed distance is s(n_A), a value of
// the dual like any other, so it can only tighten the maximum from below.
void polish(const ShapeL& a, const ShapeL& b, const Vec3L& v, long double& s) {
  using Vec6L = Eigen::Matrix<long double, 6, 1>;
  using Vec8L = Eigen::Matrix<long double, 8, 1>;
  auto residual = [&](const Vec6L& q) {
    const Vec3L ua = q.head<3>(), ub = q.tail<3>();
    const Vec3L na = normalAt(a, ua), nb = normalAt(b, ub);
    const Vec3L d = (b.center + b.rotation * b.radii.cwiseProduct(ub)) - (a.center + a.rotation * a.radii.cwiseProduct(ua));
    Vec8L r;
    r[0] = ua.array().abs().pow(a.exponents.array()).sum() - 1.0L;
    r[1] = ub.array().abs().pow(b.exponents.array()).sum() - 1.0L;
    r.segment<3>(2) = na.cross(nb);
    r.segment<3>(5) = d.cross(na);
    return r;
  };
  Vec6L q;
  q << canonicalOf(a, a.support(v)), canonicalOf(b, b.support(-v));
  Vec8L r = residual(q);
  for (int it = 0; it < 20; ++it) {
    Eigen::Matrix<long double, 8, 6> J;
    for (int k = 0; k < 6; ++k) {
      const long double h = 1e-9L * (1.0L + std::fabs(q[k]));
      Vec6L qp = q, qm = q;
      qp[k] += h, qm[k] -= h;
      J.col(k) = (residual(qp) - residual(qm)) / (2.0L * h);
    }
    const Vec6L step = J.colPivHouseholderQr().solve(-r);
    const Vec8L rn = residual(q + step);
    if (!(rn.norm() < r.norm())) break;
    q += step, r = rn;
  }
  const Vec3L ua = q.head<3>(), ub = q.tail<3>(), na = normalAt(a, ua);
  const Vec3L d = (b.center + b.rotation * b.radii.cwiseProduct(ub)) - (a.center + a.rotation * a.radii.cwiseProduct(ua));
  const long double distance = std::copysign(d.norm(), na.dot(d));
  if (r.norm() < 1e-15L && na.dot(normalAt(b, ub)) < 0.0L && distance > s) s = distance;
}
}  // namespace

double referenceConvexDistance(const ConvexShape& a, const ConvexShape& b, int samples, int starts) {
  const ShapeL la(a), lb(b);
  std::vector<std::pair<long double, Vec3L>> best;
  best.reserve(static_cast<size_t>(samples));
  for (int i = 0; i < samples; ++i) {
    const long double z = 1.0L - (2.0L * i + 1.0L) / samples, r = std::sqrt(1.0L - z * z);
    const long double t = 2.39996322972865332L * i;  // golden angle
    const Vec3L v(r * std::cos(t), r * std::sin(t), z);
    best.push_back({dual(la, lb, v, nullptr), v});
  }
  const auto count = std::min<size_t>(static_cast<size_t>(starts), best.size());
  std::partial_sort(best.begin(), best.begin() + static_cast<long>(count), best.end(),
                    [](const auto& l, const auto& r) { return l.first > r.first; });
  long double answer = best.front().first;
  for (size_t k = 0; k < count; ++k) {
    Vec3L v = best[k].second, g;
    long double s = dual(la, lb, v, &g), step = 0.05L;
    for (int it = 0; it < 20000 && step > 1e-12L; ++it) {
      const Vec3L gt = g - g.dot(v) * v;
      if (gt.norm() < 1e-19L) break;
      const Vec3L trial = (v + step * gt / gt.norm()).normalized();
      Vec3L tg;
      const long double ts = dual(la, lb, trial, &tg);
      if (ts > s) {
        s = ts, v = trial, g = tg, step *= 1.5L;
      } else {
        step *= 0.5L;
      }
    }
    polish(la, lb, v, s);
    answer = std::max(answer, s);
  }
  return static_cast<double>(answer);
}

double referenceEllipsoidDistance(const ConvexShape& a, const ConvexShape& b, int samples, int starts) {
  if (!a.quadric || !b.quadric) throw UsageError("referenceEllipsoidDistance: both shapes must be ellipsoids");
  return referenceConvexDistance(a, b, samples, starts);
}

}  // namespace articula::contact
