#include "articula/contact/ellipsoid_contact.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <vector>

#include "articula/core/error.hpp"
#include "articula/geometry/fibonacci.hpp"
#include "articula/geometry/frames.hpp"

namespace articula::contact {

using Eigen::Matrix3d;
using Eigen::Vector3d;

namespace {

constexpr int kMaxAscents = 64;   // Newton ascents from samples, at most
constexpr double kSame = 0.999;     // an ascent this close to a maximum reached goes there
constexpr double kMoved = 0.98;     // a warm ascent that turned the normal further may have changed basin
constexpr double kGradientTolerance = 1e-11;  // |tangential grad s| / length
constexpr int kRefinements = 2;  // a warm start splits a watched cap this many levels deep before searching again
// cos and sin of k pi / 3: the six caps around a split cap's centre.
constexpr double kHexagon[6][2] = {{1.0, 0.0}, {0.5, 0.8660254037844386}, {-0.5, 0.8660254037844386},
                                   {-1.0, 0.0}, {-0.5, -0.8660254037844386}, {0.5, -0.8660254037844386}};

// Antipodal directions (a Fibonacci lattice on the upper half, then its
// negation); the upper half's coordinates again as separate arrays, so that
// the scan vectorises; and the covering radius rho of the set: every unit
// vector lies within rho of a direction (the direction's cap). Cached per count.
struct DirectionSet {
  int count = 0;
  std::vector<Vector3d> directions;  // count; [i + count/2] = -[i]
  std::vector<double> x, y, z;       // count / 2: the upper half
  double rho = 0.0, cos_rho = 1.0, sin_rho = 0.0;
  // A sample this close to a maximum reached (cos(2 rho)) is taken to lie in
  // its basin and is not ascended from (the one assumption of the search).
  double cos_settled = 1.0;
};

const DirectionSet& directionSet(int count) {
  thread_local std::map<int, DirectionSet> sets;  // per count: callers may alternate option sets
  thread_local const DirectionSet* last = nullptr;
  if (last && last->count == count) return *last;
  DirectionSet& set = sets[count];
  last = &set;
  if (set.count == count) return set;
  set.count = count;
  const int half = count / 2;
  set.directions.assign(static_cast<size_t>(2 * half), Vector3d::Zero());
  set.x.resize(static_cast<size_t>(half));
  set.y.resize(static_cast<size_t>(half));
  set.z.resize(static_cast<size_t>(half));
  for (int i = 0; i < half; ++i) {
    const Vector3d v = geometry::fibonacciDirection(i, half, 0.0);  // the upper half
    set.directions[static_cast<size_t>(i)] = v;
    set.directions[static_cast<size_t>(i + half)] = -v;
    set.x[static_cast<size_t>(i)] = v.x();
    set.y[static_cast<size_t>(i)] = v.y();
    set.z[static_cast<size_t>(i)] = v.z();
  }
  // Covering radius: the largest angle from a dense probe set to its nearest direction.
  double cos_cover = 1.0;
  const int probes = 4000;
  for (int p = 0; p < probes; ++p) {
    const double z = 1.0 - (2.0 * p + 1.0) / probes, r = std::sqrt(std::max(0.0, 1.0 - z * z));
    const double azimuth = M_PI * (3.0 - std::sqrt(5.0)) * p * 1.0001;  // off the lattice's own angles
    const Vector3d w(r * std::cos(azimuth), r * std::sin(azimuth), z);
    double nearest = -1.0;
    for (const Vector3d& d : set.directions) nearest = std::max(nearest, d.dot(w));
    cos_cover = std::min(cos_cover, nearest);
  }
  // Margin for the probe set's own spacing (about 0.06 rad at 4,000 probes).
  set.rho = std::acos(cos_cover) + 0.06;
  set.cos_rho = std::cos(set.rho);
  set.sin_rho = std::sin(set.rho);
  set.cos_settled = std::cos(2.0 * set.rho);
  return set;
}

// A symmetric 3x3 matrix by its six entries: the hot loop's shape matrices
// at half the arithmetic of a full Matrix3d product.
struct Symmetric3 {
  double xx = 0.0, yy = 0.0, zz = 0.0, xy = 0.0, xz = 0.0, yz = 0.0;
  Vector3d operator*(const Vector3d& v) const {
    return {xx * v.x() + xy * v.y() + xz * v.z(), xy * v.x() + yy * v.y() + yz * v.z(),
            xz * v.x() + yz * v.y() + zz * v.z()};
  }
  // this + w x x^T
  void addOuter(double w, const Vector3d& x) {
    xx += w * x.x() * x.x(), yy += w * x.y() * x.y(), zz += w * x.z() * x.z();
    xy += w * x.x() * x.y(), xz += w * x.x() * x.z(), yz += w * x.y() * x.z();
  }
  double determinant() const {
    return xx * (yy * zz - yz * yz) - xy * (xy * zz - yz * xz) + xz * (xy * yz - yy * xz);
  }
  // Solves this * x = r by the adjugate (this must be non-singular).
  Vector3d solve(const Vector3d& r) const {
    const double cxx = yy * zz - yz * yz, cyy = xx * zz - xz * xz, czz = xx * yy - xy * xy;
    const double cxy = xz * yz - xy * zz, cxz = xy * yz - xz * yy, cyz = xy * xz - xx * yz;
    const double inverse_det = 1.0 / (xx * cxx + xy * cxy + xz * cxz);
    return inverse_det * Vector3d(cxx * r.x() + cxy * r.y() + cxz * r.z(), cxy * r.x() + cyy * r.y() + cyz * r.z(),
                                  cxz * r.x() + cyz * r.y() + czz * r.z());
  }
};

// L = D R^T: the support function is h(v) = |L v|.
Matrix3d supportMatrix(const ConvexShape& shape) { return shape.radii.asDiagonal() * shape.rotation.transpose(); }

// M = R D^2 R^T = L^T L, the matrix of the support function h(v) = sqrt(v' M v).
Symmetric3 shapeMatrix(const ConvexShape& shape) {
  Symmetric3 m;
  for (int k = 0; k < 3; ++k) m.addOuter(shape.radii[k] * shape.radii[k], shape.rotation.col(k));
  return m;
}

// The dual at a unit v: s, its gradient g = x_B(-v) - x_A(v) in R^3, the
// support offsets x_A(v) - c_A = M_A v / h_A and c_B - x_B(-v) = M_B v / h_B.
struct DualPoint {
  Vector3d v, xa, xb, g;
  double ha, hb, s;
  double inverse_ha, inverse_hb;  // 1 / h_A(v), 1 / h_B(v)
};

// An upper bound of s on the cap of radius rho around a unit w, from
// s = s(w), g2 = |grad s(w)|^2 and k <= the support functions' curvature on
// the cap. Along a great circle from w, s'' = -s - k_A - k_B <= -s - k, so
// s(phi) <= (s + k) cos phi + G sin phi - k (Sturm comparison; G, the
// tangential gradient, bounds s'(0)), at most |g'| cos(max(0, theta' - rho)) - k
// for the shifted s + k = |g'| cos theta'. (k = 0 gives the concavity
// bound s(v) <= grad s(w) . v. Both sides of the select are computed: the scan vectorises.)
inline double capBound(double s, double g2, double k, double cos_rho, double sin_rho) {
  const double excess = g2 - s * s, shifted = s + k, tangential2 = excess > 0.0 ? excess : 0.0;
  const double r = std::sqrt(shifted * shifted + tangential2);
  const double tilted = shifted * cos_rho + std::sqrt(tangential2) * sin_rho;
  return (shifted >= r * cos_rho ? r : tilted) - k;
}

struct Dual {
  Symmetric3 ma, mb;
  Vector3d c;
  double length;
  // (r_min r_mid)^2 and r_max of each: the support function's curvature is at least the first over |L v|^3.
  double curvature_a, max_radius_a, curvature_b, max_radius_b;
  // r_min^2 / r_max of A plus that of B: the least radius of curvature of
  // each ellipsoid, so along every great circle s'' + s <= -curvature_floor.
  double curvature_floor;
  double gradient_tolerance;

  Dual(const ConvexShape& a, const ConvexShape& b)
      : ma(shapeMatrix(a)), mb(shapeMatrix(b)), c(b.center - a.center) {
    max_radius_a = a.radii.maxCoeff();
    max_radius_b = b.radii.maxCoeff();
    length = std::max(max_radius_a, max_radius_b);
    const double mid_min_a = a.radii.prod() / max_radius_a, mid_min_b = b.radii.prod() / max_radius_b;
    curvature_a = mid_min_a * mid_min_a;
    curvature_b = mid_min_b * mid_min_b;
    const double min_radius_a = a.radii.minCoeff(), min_radius_b = b.radii.minCoeff();
    curvature_floor = min_radius_a * min_radius_a / max_radius_a + min_radius_b * min_radius_b / max_radius_b;
    gradient_tolerance = kGradientTolerance * length;
  }

  // Whether a stationary point of value s is the global maximum by the
  // curvature certificate: with k = curvature_floor, along every great
  // circle from the stationary point s'' <= -s - k and s' = 0 there, so
  // (Sturm comparison) s(phi) <= (s + k) cos phi - k, below s everywhere
  // else once s + k > 0. (Geometrically: the Minkowski difference A - B is a
  // convex body plus a ball of radius k, and an overlap shallower than k has
  // one nearest boundary point.) The margin keeps what a gradient G at the
  // tolerance could add elsewhere, G^2 / (2 (s + k)), at rounding level.
  // s > 0 (separated) is the case k = 0: concavity.
  bool certifiedByCurvature(double s) const { return s + curvature_floor > 1e-4 * length; }

  // A lower bound of the curvature k_A + k_B of the support functions on the
  // cap of radius rho around a unit w with h_A(w) = ha, h_B(w) = hb:
  // k_A = |L e x L v|^2 / |L v|^3 >= (r_min r_mid)^2 / |L v|^3 (L = D R^T,
  // e a unit tangent; |L e x L v| = det L |L^-T (e x v)|), and on the cap
  // |L v| <= min(r_max, h_A(w) + rho r_max). (Ternaries, not std::min: the scan vectorises.)
  double curvatureBound(double ha, double hb, double rho) const {
    const double la_cap = ha + rho * max_radius_a, lb_cap = hb + rho * max_radius_b;
    const double la = la_cap < max_radius_a ? la_cap : max_radius_a, lb = lb_cap < max_radius_b ? lb_cap : max_radius_b;
    return curvature_a / (la * la * la) + curvature_b / (lb * lb * lb);
  }

  // capBound on the cap of radius rho around p.v.
  double capBound(const DualPoint& p, double rho, double cos_rho, double sin_rho) const {
    return articula::contact::capBound(p.s, p.g.squaredNorm(), curvatureBound(p.ha, p.hb, rho), cos_rho, sin_rho);
  }

  // An upper bound of s on the cap of radius rho around w, below `beat` if
  // the cap can be shown to be: the cap's own bound, else (depth > 0) the
  // highest of 7 caps of radius 0.55 rho that cover it, one at w and six
  // around it at 0.866 rho (in the plane, radius rho / 2 just covers; 0.55
  // leaves room for the sphere's curvature at rho <= 0.5). Stops at the first
  // child that stays at or above `beat`.
  double refinedCapBound(const Vector3d& w, double rho, double beat) const {
    return refinedCapBound<0>(eval(w), capLevels(rho), beat);
  }

  // The radii of a cap and of its refinements, level by level, with their
  // cosines and sines: computed once per radius (the sample set's), as the
  // warm path bounds several caps per call.
  struct CapLevels {
    double rho[kRefinements + 1], cos_rho[kRefinements + 1], sin_rho[kRefinements + 1];
    double cos_ring[kRefinements + 1], sin_ring[kRefinements + 1];  // of 0.866 rho: where a level's six caps sit
  };
  static const CapLevels& capLevels(double rho) {
    thread_local CapLevels levels{{NAN}, {}, {}, {}, {}};
    if (levels.rho[0] == rho) return levels;
    for (int l = 0; l <= kRefinements; ++l, rho *= 0.55) {
      levels.rho[l] = rho;
      levels.cos_rho[l] = std::cos(rho), levels.sin_rho[l] = std::sin(rho);
      levels.cos_ring[l] = std::cos(0.866 * rho), levels.sin_ring[l] = std::sin(0.866 * rho);
    }
    return levels;
  }

  template <int level>
  double refinedCapBound(const DualPoint& p, const CapLevels& levels, double beat) const {
    const double own = capBound(p, levels.rho[level], levels.cos_rho[level], levels.sin_rho[level]);
    if constexpr (level == kRefinements) {
      return own;
    } else {
      if (own < beat) return own;
      const geometry::TangentFrame f = geometry::householderFrameUnit(p.v);
      double highest = refinedCapBound<level + 1>(p, levels, beat);  // the centre cap
      for (int k = 0; k < 6 && highest < beat; ++k) {
        const Vector3d t = kHexagon[k][0] * f.t + kHexagon[k][1] * f.b;
        highest = std::max(highest, refinedCapBound<level + 1>(
                                        eval(levels.cos_ring[level] * p.v + levels.sin_ring[level] * t), levels, beat));
      }
      return highest;
    }
  }

  // The dual at the direction of w (any non-zero length). The support points
  // and the gradient are 0-homogeneous, so they are computed from w itself:
  // normalising w first would put a square root and a division on the
  // iteration's chain of dependent operations (the latency of a Newton step).
  DualPoint eval(const Vector3d& w) const {
    DualPoint p;
    const double norm = w.norm(), inverse_norm = 1.0 / norm;
    p.v = w * inverse_norm;
    const Vector3d maw = ma * w, mbw = mb * w;
    const double ha = std::sqrt(w.dot(maw)), hb = std::sqrt(w.dot(mbw));  // h(w) = |w| h(v)
    const double inverse_ha = 1.0 / ha, inverse_hb = 1.0 / hb;
    p.xa = maw * inverse_ha;
    p.xb = mbw * inverse_hb;
    p.g = c - p.xa - p.xb;
    p.ha = ha * inverse_norm;
    p.hb = hb * inverse_norm;
    p.inverse_ha = inverse_ha * norm;
    p.inverse_hb = inverse_hb * norm;
    p.s = p.v.dot(c) - p.ha - p.hb;
    return p;
  }

  // Newton step on the sphere at p: the tangent step (capped at 0.5 rad),
  // the squared tangential gradient, and the model's gain r . d / 2 when the
  // Hessian is negative definite (NaN when it had to be shifted).
  //
  // s is 1-homogeneous, so its Hessian in R^3,
  //   H = -(M_A - x_A x_A') / h_A - (M_B - x_B x_B') / h_B,
  // has H v = 0, and the Riemannian Hessian on the tangent plane is H - s I.
  // The 3x3 matrix K = H - s I + (s - L) v v' equals it there and has v as
  // an eigenvector (eigenvalue -L), so K d = -r with r tangent gives the
  // tangent Newton step directly, without a tangent frame; the tangent
  // block's trace and determinant are tr K + L and -det K / L.
  struct Step {
    Vector3d d;
    double gradient2, gain;
  };
  Step newtonStep(const DualPoint& p) const {
    const Vector3d r = p.g - p.g.dot(p.v) * p.v;
    const double ia = p.inverse_ha, ib = p.inverse_hb;
    Symmetric3 k{-(ma.xx * ia + mb.xx * ib) - p.s, -(ma.yy * ia + mb.yy * ib) - p.s, -(ma.zz * ia + mb.zz * ib) - p.s,
                 -(ma.xy * ia + mb.xy * ib),       -(ma.xz * ia + mb.xz * ib),       -(ma.yz * ia + mb.yz * ib)};
    k.addOuter(ia, p.xa);
    k.addOuter(ib, p.xb);
    k.addOuter(p.s - length, p.v);
    // Where the sphere makes the tangent block indefinite (overlap, s < 0)
    // or nearly singular, shift it to negative definite (a trust-region-like step).
    const double mean = 0.5 * (k.xx + k.yy + k.zz + length), det = -k.determinant() / length;
    const double dev = std::sqrt(std::max(0.0, mean * mean - det));
    const double top = mean + dev, bottom = mean - dev;
    const bool definite = top < -1e-6 * std::max(std::fabs(bottom), length);
    if (!definite) {
      const double shift = top + std::max({top, 0.1 * std::fabs(bottom), 1e-3 * length});
      k.xx -= shift, k.yy -= shift, k.zz -= shift;
      k.addOuter(shift, p.v);
    }
    const Vector3d d = -k.solve(r);  // tangent: v is an eigenvector of K
    const double gain = definite ? 0.5 * r.dot(d) : NAN;
    const double norm = d.norm();
    return {norm > 0.5 ? Vector3d(d * (0.5 / norm)) : d, r.squaredNorm(), gain};  // at most about 0.5 rad at once
  }

  double gradient2(const DualPoint& p) const { return (p.g - p.g.dot(p.v) * p.v).squaredNorm(); }

  // Newton ascent on the sphere from p, backtracking on s; returns the
  // stationary point (or the last point when the iteration cap or a stalled
  // line search stops it). With `found` (maxima already reached, the best
  // value `beat`), gives up early, unconverged, once the iterate is heading
  // for one of them or the Newton model puts this maximum well below `beat`.
  //
  // `ceiling`: what the ascent could still reach from where it stopped: s at
  // a maximum, the Newton model's s + 4 gain when it gave up on that, -inf
  // when it was heading for a maximum already reached, +inf otherwise.
  DualPoint ascend(DualPoint p, int max_iterations, int& iterations, bool& converged, double& ceiling,
                   const std::vector<Vector3d>* found = nullptr, double beat = 0.0) const {
    converged = false;
    ceiling = INFINITY;
    const double tolerance2 = gradient_tolerance * gradient_tolerance;
    for (int it = 0; it < max_iterations; ++it) {
      if (gradient2(p) <= tolerance2) {
        converged = true;
        ceiling = p.s;
        return p;
      }
      ++iterations;
      const Step step = newtonStep(p);
      if (found && p.s + 4.0 * step.gain < beat) {  // false when the gain is NaN
        ceiling = p.s + 4.0 * step.gain;
        return p;
      }
      bool accepted = false;
      const double rounding = 1e-15 * (std::fabs(p.s) + p.ha + p.hb);
      for (double alpha = 1.0; alpha >= 1.0 / 64.0; alpha *= 0.5) {
        const DualPoint q = eval(p.v + alpha * step.d);
        if (q.s >= p.s - rounding) {
          p = q;
          accepted = true;
          break;
        }
      }
      if (found && std::any_of(found->begin(), found->end(), [&](const Vector3d& f) { return f.dot(p.v) > kSame; })) {
        ceiling = -INFINITY;
        return p;
      }
      if (!accepted) {
        // No ascent possible: a maximum to rounding when the gradient is tiny.
        converged = step.gradient2 <= 1e6 * tolerance2;
        if (converged) ceiling = p.s;
        return p;
      }
    }
    return p;
  }
};

// s at every direction of the set and an upper bound of s on its cap:
// s_out[i], bound_out[i] for v_i, [i + count/2] for -v_i.
// With x_A = M_A v / h_A and x_B = M_B v / h_B, g(v) = c - x_A - x_B and
// g(-v) = c + x_A + x_B. (Separate arrays and __restrict: the loop vectorises.)
void boundDual(const DirectionSet& set, const Dual& dual, double* __restrict s_out, double* __restrict bound_out) {
  const int half = set.count / 2;
  const double* __restrict x = set.x.data();
  const double* __restrict y = set.y.data();
  const double* __restrict z = set.z.data();
  const double a0 = dual.ma.xx, a1 = dual.ma.yy, a2 = dual.ma.zz, a3 = dual.ma.xy, a4 = dual.ma.xz, a5 = dual.ma.yz;
  const double b0 = dual.mb.xx, b1 = dual.mb.yy, b2 = dual.mb.zz, b3 = dual.mb.xy, b4 = dual.mb.xz, b5 = dual.mb.yz;
  const double cx = dual.c.x(), cy = dual.c.y(), cz = dual.c.z();
  const double rho = set.rho, cos_rho = set.cos_rho, sin_rho = set.sin_rho;
  for (int i = 0; i < half; ++i) {
    const double vx = x[i], vy = y[i], vz = z[i];
    const double ax = a0 * vx + a3 * vy + a4 * vz, ay = a3 * vx + a1 * vy + a5 * vz, az = a4 * vx + a5 * vy + a2 * vz;  // M_A v
    const double bx = b0 * vx + b3 * vy + b4 * vz, by = b3 * vx + b1 * vy + b5 * vz, bz = b4 * vx + b5 * vy + b2 * vz;  // M_B v
    const double ha = std::sqrt(vx * ax + vy * ay + vz * az), hb = std::sqrt(vx * bx + vy * by + vz * bz);
    const double ia = 1.0 / ha, ib = 1.0 / hb;
    const double sx = ax * ia + bx * ib, sy = ay * ia + by * ib, sz = az * ia + bz * ib;  // x_A + x_B
    const double vc = cx * vx + cy * vy + cz * vz, h = ha + hb;
    const double up = vc - h, down = -vc - h;
    const double gux = cx - sx, guy = cy - sy, guz = cz - sz, gdx = cx + sx, gdy = cy + sy, gdz = cz + sz;
    const double k = dual.curvatureBound(ha, hb, rho);
    s_out[i] = up;
    s_out[i + half] = down;
    bound_out[i] = capBound(up, gux * gux + guy * guy + guz * guz, k, cos_rho, sin_rho);
    bound_out[i + half] = capBound(down, gdx * gdx + gdy * gdy + gdz * gdz, k, cos_rho, sin_rho);
  }
}

// Marks the samples within 2 rho of a maximum reached (bound -inf).
void settleSamples(const DirectionSet& set, const Vector3d& maximum, double* __restrict bound) {
  const int half = set.count / 2;
  const double* __restrict x = set.x.data();
  const double* __restrict y = set.y.data();
  const double* __restrict z = set.z.data();
  const double mx = maximum.x(), my = maximum.y(), mz = maximum.z(), limit = set.cos_settled;
  for (int i = 0; i < half; ++i) {
    const double d = x[i] * mx + y[i] * my + z[i] * mz;
    bound[i] = d >= limit ? -INFINITY : bound[i];
    bound[i + half] = -d >= limit ? -INFINITY : bound[i + half];
  }
}

// The index of the largest value above `floor` (the first of equal ones), or
// -1. Branch-free (with unpredictable comparisons, branches made such scans
// slow, perf), and in four interleaved lanes merged at the end: one lane's
// chain of dependent compare-selects made the scan latency-bound (callgrind).
int highestAbove(const double* values, int n, double floor) {
  constexpr int kLanes = 4;
  int top[kLanes];
  double top_value[kLanes];
  std::fill(top, top + kLanes, -1);
  std::fill(top_value, top_value + kLanes, floor);
  for (int i = 0; i < n; i += kLanes)
    for (int lane = 0; lane < kLanes && i + lane < n; ++lane) {
      const bool better = values[i + lane] > top_value[lane];
      top[lane] = better ? i + lane : top[lane];
      top_value[lane] = better ? values[i + lane] : top_value[lane];
    }
  int best = -1;
  double best_value = floor;
  for (int lane = 0; lane < kLanes; ++lane)
    if (top[lane] >= 0 && (top_value[lane] > best_value || (top_value[lane] == best_value && top[lane] < best))) {
      best = top[lane];
      best_value = top_value[lane];
    }
  return best;
}

}  // namespace

ContactResult ellipsoidContact(const ConvexShape& a, const ConvexShape& b, const ContactOptions& options,
                               const ContactResult* warm_start) {
  if (!a.quadric || !b.quadric) throw UsageError("ellipsoidContact: both shapes must be ellipsoids (exponents 2)");
  options.validate();
  const Dual dual(a, b);
  // Whether the curvature certificate may stop a search (the option turns it off to check it).
  const auto stopsByCurvature = [&](double s) { return options.curvature_certificate && dual.certifiedByCurvature(s); };
  ContactResult result;
  ContactSummary& summary = result.summary;

  DualPoint best;
  bool have = false, converged = false;
  // Ascends from `start`; keeps the best converged maximum; returns where it ended (nullptr: did not converge).
  DualPoint last;
  thread_local std::vector<std::pair<double, Vector3d>> ends;  // ceiling and end of each ascent: rivals of the answer
  ends.clear();
  auto consider = [&](const DualPoint& start, const std::vector<Vector3d>* found = nullptr) -> const DualPoint* {
    ++summary.starts;
    bool ok = false;
    double ceiling = INFINITY;
    last = dual.ascend(start, options.max_iterations, summary.iterations, ok, ceiling, converged ? found : nullptr,
                       best.s);
    ends.push_back({ceiling, last.v});
    if ((ok && (!converged || last.s > best.s)) || !have) {
      best = last;
      have = true;
      converged = converged || ok;
    }
    return ok ? &last : nullptr;
  };

  if (warm_start) {
    summary.warm_started = true;
    const double len = warm_start->normal.norm();
    const Vector3d warm_normal = warm_start->normal / len;
    if (std::isfinite(len) && len > 0.0) consider(dual.eval(warm_normal));
    if (have && converged && best.s > 0.0) {
      summary.termination = "warm start, separated (dual certificate)";
    } else if (have && converged && stopsByCurvature(best.s)) {
      summary.termination = "warm start, overlap within the curvature bound (curvature certificate)";
      result.search = warm_start->search;  // for a later step that goes deeper
    } else if (have && converged && warm_start->search && best.v.dot(warm_normal) > kMoved) {
      // Overlap: the answer stands while what the last global search saw
      // stays below it: the dual has moved by at most `drift` since, so a
      // bound from then, plus drift, still holds. Where that is not enough,
      // a watched cap is bounded again here and a rival's Newton model is
      // asked again here; if either could beat the answer, search again.
      const DualSearchState& previous = *warm_start->search;
      result.search = warm_start->search;
      const double drift = (dual.c - previous.offset).norm() + (supportMatrix(a) - previous.l_a).norm() +
                           (supportMatrix(b) - previous.l_b).norm();
      bool safe = previous.outside_bound + drift < best.s;
      for (int k = 0; k < previous.watch_count && safe; ++k)
        if (!(previous.watch_bounds[k] + drift < best.s))
          safe = dual.refinedCapBound(previous.watch[k], previous.cap_radius, best.s) < best.s;
      for (int k = 0; k < previous.rival_count && safe; ++k) {
        if (previous.rival_ceilings[k] + drift < best.s) continue;
        const DualPoint r = dual.eval(previous.rivals[k]);
        safe = r.s + 4.0 * dual.newtonStep(r).gain < best.s;  // false when the Hessian is not definite
      }
      if (safe) summary.termination = "warm start, overlap (the last search's bounds, moved since, stay below)";
    }
  } else {
    const double len = dual.c.norm();
    const Vector3d v0 = len > 0.0 ? Vector3d(dual.c / len) : Vector3d::UnitX();
    const DualPoint p0 = dual.eval(v0);
    if (p0.s > 0.0) {  // separated for sure: the concave ascent ends at the global maximum
      consider(p0);
      if (converged && best.s > 0.0) summary.termination = "separated (dual certificate)";
    } else if (stopsByCurvature(p0.s)) {
      // The ascent only climbs, so it ends at a stationary point above -k:
      // the global maximum by the curvature certificate, without sampling.
      consider(p0);
      if (converged && dual.certifiedByCurvature(best.s))
        summary.termination = "overlap within the curvature bound (curvature certificate)";
    }
  }

  if (!summary.termination) {
    // Overlap, or close to it: sample the dual, bound it on every sample's
    // cap (capBound), and ascend from the best sample; then, while some cap's
    // bound beats the best maximum found, ascend from the sample with the
    // highest bound. Samples within 2 rho of a maximum reached are taken to
    // lie in its basin; every other cap ends up bounded below the answer.
    summary.global_search = true;
    const DirectionSet& set = directionSet(options.sample_directions);
    const int n = set.count;
    thread_local std::vector<double> s, initial, bound;  // bound: -inf once ascended from or settled
    s.resize(static_cast<size_t>(n));
    initial.resize(static_cast<size_t>(n));
    boundDual(set, dual, s.data(), initial.data());
    bound = initial;
    thread_local std::vector<Vector3d> found;  // maxima reached so far
    found.clear();
    auto settle = [&](const Vector3d& maximum) {
      found.push_back(maximum);
      settleSamples(set, maximum, bound.data());
    };
    if (converged) settle(best.v);
    const double margin = 1e-12 * dual.length;
    bool open = true;  // the ascent limit stopped the search before every cap was below the answer
    bool curvature = false;  // a maximum reached is above -k: the rest need not be bounded
    for (int ascents = 0; ascents < kMaxAscents; ++ascents) {
      if (converged && stopsByCurvature(best.s)) {
        open = false;
        curvature = true;
        break;
      }
      const int top = found.empty() ? highestAbove(s.data(), n, -INFINITY) : highestAbove(bound.data(), n, best.s + margin);
      if (top < 0) {
        open = false;
        break;
      }
      bound[static_cast<size_t>(top)] = -INFINITY;
      s[static_cast<size_t>(top)] = -INFINITY;
      if (const DualPoint* end = consider(dual.eval(set.directions[static_cast<size_t>(top)]), &found)) settle(end->v);
    }
    // For warm starts: where the other ascents ended (maxima, or where an
    // ascent gave up) are the rivals the next step follows; the caps no
    // maximum settled are summed up by their highest bounds, the first few
    // watched one by one and the rest by one bound.
    auto search_state = std::make_shared<DualSearchState>();
    DualSearchState& state = *search_state;
    std::sort(ends.begin(), ends.end(), [](const auto& l, const auto& r) { return l.first > r.first; });
    state.rival_count = 0;
    bool untracked = false;  // more rivals than a warm start follows: it searches again
    for (const auto& end : ends) {
      // Named references, not a structured binding: lambdas may capture those only from C++20 (Clang refuses).
      const double ceiling = end.first;
      const Vector3d& v = end.second;
      if (ceiling == -INFINITY || v.dot(best.v) > kSame ||
          std::any_of(state.rivals, state.rivals + state.rival_count, [&](const Vector3d& r) { return r.dot(v) > kSame; }))
        continue;
      if (state.rival_count == DualSearchState::kRivals) {
        untracked = true;
        break;
      }
      state.rival_ceilings[state.rival_count] = ceiling;
      state.rivals[state.rival_count++] = v;
    }
    constexpr int kKept = DualSearchState::kWatched + 1;
    std::pair<double, int> highest[kKept];
    std::fill(highest, highest + kKept, std::make_pair(-INFINITY, -1));
    // (A sample an ascent left keeps its bound: where that ascent went says
    // nothing about its cap once the pair has moved.)
    for (const Vector3d& f : found) settleSamples(set, f, initial.data());
    for (int i = 0; i < n; ++i) {
      const double value = initial[static_cast<size_t>(i)];  // -inf: settled
      int k = kKept;
      for (; k > 0 && highest[k - 1].first < value; --k)
        if (k < kKept) highest[k] = highest[k - 1];
      if (k < kKept) highest[k] = {value, i};
    }
    state.watch_count = 0;
    for (int k = 0; k < DualSearchState::kWatched && highest[k].second >= 0; ++k) {
      state.watch_bounds[state.watch_count] = highest[k].first;
      state.watch[state.watch_count++] = set.directions[static_cast<size_t>(highest[k].second)];
    }
    state.outside_bound = untracked ? INFINITY : highest[kKept - 1].first;
    state.cap_radius = set.rho;
    state.l_a = supportMatrix(a);
    state.l_b = supportMatrix(b);
    state.offset = dual.c;
    result.search = std::move(search_state);
    summary.termination = !converged        ? "no ascent converged; best point of the dual reported"
                          : best.s > 0.0    ? "separated (dual certificate, after sampling)"
                          : curvature       ? "overlap: a maximum reached is above -k (curvature certificate)"
                          : open            ? "overlap: best maximum; the ascent limit left caps unresolved"
                                            : "overlap: no sample's cap bound beats the best maximum";
  }
  summary.status = converged ? ContactStatus::Converged : ContactStatus::NotConverged;

  const Vector3d& v = best.v;
  result.normal = v;
  result.distance = best.s;
  result.point_a = a.center + best.xa;
  result.point_b = b.center - best.xb;
  result.canonical_a = a.radii.cwiseProduct(a.rotation.transpose() * v) * best.inverse_ha;
  result.canonical_b = -b.radii.cwiseProduct(b.rotation.transpose() * v) * best.inverse_hb;
  summary.certified = converged && (best.s > 0.0 || dual.certifiedByCurvature(best.s));
  summary.residual = (best.g - best.s * v).norm() / dual.length;
  return result;
}

}  // namespace articula::contact
