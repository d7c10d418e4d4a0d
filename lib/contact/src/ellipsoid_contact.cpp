#include "articula/contact/ellipsoid_contact.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "articula/core/error.hpp"
#include "articula/geometry/frames.hpp"

namespace articula::contact {

using Eigen::Matrix3d;
using Eigen::Vector3d;

namespace {

constexpr int kNeighbours = 6;    // sample-graph neighbours for "local maximum"
constexpr int kMaxAscents = 6;    // Newton ascents from samples, at most
constexpr double kSame = 0.999;     // an ascent this close to a maximum reached goes there
constexpr double kMoved = 0.98;     // a warm ascent that turned the normal further may have changed basin
constexpr double kDistinct = 0.85;  // samples with v . w above this are not distinct starts
constexpr double kGradientTolerance = 1e-11;  // |tangential grad s| / length

// Antipodal directions (a Fibonacci lattice on the upper half, then its
// negation), the products x^2, y^2, z^2, 2xy, 2xz, 2yz of each upper
// direction (v'Mv is then one 6-term dot product and serves v and -v), each
// direction's nearest neighbours and the directions within kDistinct of it,
// and the covering radius of the set. Cached per count.
struct DirectionSet {
  int count = 0;
  std::vector<Vector3d> directions;                     // count; [i + count/2] = -[i]
  std::vector<std::array<double, 6>> monomials;         // count / 2
  std::vector<std::array<int, kNeighbours>> neighbours;  // count
  std::vector<std::vector<int>> near;                    // count
  double cos_cover = 1.0, sin_cover = 0.0;              // covering radius rho
};

const DirectionSet& directionSet(int count) {
  thread_local DirectionSet set;
  if (set.count == count) return set;
  set.count = count;
  const int half = count / 2;
  set.directions.assign(static_cast<size_t>(2 * half), Vector3d::Zero());
  set.monomials.clear();
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < half; ++i) {
    const double z = 1.0 - (i + 0.5) / half;  // (0, 1): the upper half
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    const Vector3d v(r * std::cos(golden * i), r * std::sin(golden * i), z);
    set.directions[static_cast<size_t>(i)] = v;
    set.directions[static_cast<size_t>(i + half)] = -v;
    set.monomials.push_back({v.x() * v.x(), v.y() * v.y(), v.z() * v.z(), 2.0 * v.x() * v.y(), 2.0 * v.x() * v.z(),
                             2.0 * v.y() * v.z()});
  }
  const int n = 2 * half;
  set.neighbours.resize(static_cast<size_t>(n));
  set.near.assign(static_cast<size_t>(n), {});
  std::vector<std::pair<double, int>> order(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) order[static_cast<size_t>(j)] = {-set.directions[i].dot(set.directions[j]), j};
    std::partial_sort(order.begin(), order.begin() + kNeighbours + 1, order.end());
    for (int k = 0; k < kNeighbours; ++k) set.neighbours[static_cast<size_t>(i)][k] = order[k + 1].second;
    for (int j = 0; j < n; ++j)
      if (set.directions[i].dot(set.directions[j]) > kDistinct) set.near[static_cast<size_t>(i)].push_back(j);
  }
  // Covering radius: the largest angle from a dense probe set to its nearest direction.
  double cos_cover = 1.0;
  const int probes = 4000;
  for (int p = 0; p < probes; ++p) {
    const double z = 1.0 - (2.0 * p + 1.0) / probes, r = std::sqrt(std::max(0.0, 1.0 - z * z));
    const Vector3d w(r * std::cos(golden * p * 1.0001), r * std::sin(golden * p * 1.0001), z);
    double nearest = -1.0;
    for (const Vector3d& d : set.directions) nearest = std::max(nearest, d.dot(w));
    cos_cover = std::min(cos_cover, nearest);
  }
  // Margin for the probe set's own spacing (about 0.06 rad at 4,000 probes).
  const double rho = std::acos(cos_cover) + 0.06;
  set.cos_cover = std::cos(rho);
  set.sin_cover = std::sin(rho);
  return set;
}

// The dual, its gradient g = x_B(-v) - x_A(v) and the pieces of its Hessian at a unit v.
struct DualPoint {
  Vector3d v, mav, mbv, g;
  double ha, hb, s;
};

struct Dual {
  Matrix3d ma, mb;
  std::array<double, 6> ma6, mb6;  // xx, yy, zz, xy, xz, yz
  Vector3d c;
  double length;
  double gradient_tolerance;

  Dual(const ConvexShape& a, const ConvexShape& b) {
    ma = a.rotation * a.radii.cwiseAbs2().asDiagonal() * a.rotation.transpose();
    mb = b.rotation * b.radii.cwiseAbs2().asDiagonal() * b.rotation.transpose();
    ma6 = {ma(0, 0), ma(1, 1), ma(2, 2), ma(0, 1), ma(0, 2), ma(1, 2)};
    mb6 = {mb(0, 0), mb(1, 1), mb(2, 2), mb(0, 1), mb(0, 2), mb(1, 2)};
    c = b.center - a.center;
    length = std::max(a.radii.maxCoeff(), b.radii.maxCoeff());
    gradient_tolerance = kGradientTolerance * length;
  }

  DualPoint eval(const Vector3d& v) const {
    DualPoint p;
    p.v = v;
    p.mav.noalias() = ma * v;
    p.mbv.noalias() = mb * v;
    p.ha = std::sqrt(v.dot(p.mav));
    p.hb = std::sqrt(v.dot(p.mbv));
    p.g = c - p.mav / p.ha - p.mbv / p.hb;
    p.s = v.dot(c) - p.ha - p.hb;
    return p;
  }

  // Newton step on the sphere at p: the tangent step (capped at 0.5 rad),
  // the squared tangential gradient, and the model's gain r . d / 2 when the
  // Hessian is negative definite (NaN when it had to be shifted).
  struct Step {
    Vector3d d;
    double gradient2, gain;
  };
  Step newtonStep(const DualPoint& p) const {
    const geometry::TangentFrame f = geometry::householderFrameUnit(p.v);
    const double r1 = f.t.dot(p.g), r2 = f.b.dot(p.g);
    // Tangential Hessian of s: -(M_A - M_A v v'M_A / h_A^2) / h_A - (same for B) - s I.
    const Vector3d mat = ma * f.t, mab = ma * f.b, mbt = mb * f.t, mbb = mb * f.b;
    const double ta = f.t.dot(p.mav) / p.ha, ba = f.b.dot(p.mav) / p.ha;
    const double tb = f.t.dot(p.mbv) / p.hb, bb = f.b.dot(p.mbv) / p.hb;
    double h11 = -(f.t.dot(mat) - ta * ta) / p.ha - (f.t.dot(mbt) - tb * tb) / p.hb - p.s;
    double h12 = -(f.t.dot(mab) - ta * ba) / p.ha - (f.t.dot(mbb) - tb * bb) / p.hb;
    double h22 = -(f.b.dot(mab) - ba * ba) / p.ha - (f.b.dot(mbb) - bb * bb) / p.hb - p.s;
    // Where the sphere makes it indefinite (overlap, s < 0) or nearly
    // singular, shift it to negative definite (a trust-region-like step).
    const double mean = 0.5 * (h11 + h22), dev = std::sqrt(0.25 * (h11 - h22) * (h11 - h22) + h12 * h12);
    const double top = mean + dev, bottom = mean - dev;
    const bool definite = top < -1e-6 * std::max(std::fabs(bottom), length);
    if (!definite) {
      const double shift = top + std::max({top, 0.1 * std::fabs(bottom), 1e-3 * length});
      h11 -= shift;
      h22 -= shift;
    }
    const double det = h11 * h22 - h12 * h12;
    double d1 = -(h22 * r1 - h12 * r2) / det, d2 = -(h11 * r2 - h12 * r1) / det;
    const double gain = definite ? 0.5 * (r1 * d1 + r2 * d2) : NAN;
    const double norm = std::sqrt(d1 * d1 + d2 * d2);
    if (norm > 0.5) d1 *= 0.5 / norm, d2 *= 0.5 / norm;  // at most about 0.5 rad at once
    return {d1 * f.t + d2 * f.b, r1 * r1 + r2 * r2, gain};
  }

  double gradient2(const DualPoint& p) const { return (p.g - p.g.dot(p.v) * p.v).squaredNorm(); }

  // Newton ascent on the sphere from p, backtracking on s; returns the
  // stationary point (or the last point when the iteration cap or a stalled
  // line search stops it). With `found` (maxima already reached, the best
  // value `beat`), gives up early, unconverged, once the iterate is heading
  // for one of them or the Newton model puts this maximum well below `beat`.
  DualPoint ascend(DualPoint p, int max_iterations, int& iterations, bool& converged,
                   const std::vector<Vector3d>* found = nullptr, double beat = 0.0) const {
    converged = false;
    const double tolerance2 = gradient_tolerance * gradient_tolerance;
    for (int it = 0; it < max_iterations; ++it) {
      if (gradient2(p) <= tolerance2) {
        converged = true;
        return p;
      }
      ++iterations;
      const Step step = newtonStep(p);
      if (found && p.s + 4.0 * step.gain < beat) return p;  // false when the gain is NaN
      bool accepted = false;
      const double rounding = 1e-15 * (std::fabs(p.s) + p.ha + p.hb);
      for (double alpha = 1.0; alpha >= 1.0 / 64.0; alpha *= 0.5) {
        const DualPoint q = eval((p.v + alpha * step.d).normalized());
        if (q.s >= p.s - rounding) {
          p = q;
          accepted = true;
          break;
        }
      }
      if (found && std::any_of(found->begin(), found->end(), [&](const Vector3d& f) { return f.dot(p.v) > kSame; }))
        return p;
      if (!accepted) {
        // No ascent possible: a maximum to rounding when the gradient is tiny.
        converged = step.gradient2 <= 1e6 * tolerance2;
        return p;
      }
    }
    return p;
  }
};

}  // namespace

ContactResult ellipsoidContact(const ConvexShape& a, const ConvexShape& b, const ContactOptions& options,
                               const ContactResult* warm_start) {
  if (!a.quadric || !b.quadric) throw UsageError("ellipsoidContact: both shapes must be ellipsoids (exponents 2)");
  options.validate();
  const Dual dual(a, b);
  ContactResult result;
  ContactSummary& summary = result.summary;

  DualPoint best;
  bool have = false, converged = false;
  // Ascends from `start`; keeps the best converged maximum; returns where it ended (nullptr: did not converge).
  DualPoint last;
  thread_local std::vector<std::pair<double, Vector3d>> ends;  // where ascents ended: rivals of the answer
  ends.clear();
  auto consider = [&](const DualPoint& start, const std::vector<Vector3d>* found = nullptr) -> const DualPoint* {
    ++summary.starts;
    bool ok = false;
    last = dual.ascend(start, options.max_iterations, summary.iterations, ok, converged ? found : nullptr, best.s);
    ends.push_back({last.s, last.v});
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
    } else if (have && converged && warm_start->rival_count >= 0 && best.v.dot(warm_normal) > kMoved) {
      // Overlap: still the global maximum unless a rival of the previous step,
      // one Newton step on, is predicted to come near it.
      bool safe = true;
      result.rival_count = warm_start->rival_count;
      for (int k = 0; k < warm_start->rival_count && safe; ++k) {
        const DualPoint r = dual.eval(warm_start->rivals[k]);
        const Dual::Step step = dual.newtonStep(r);
        safe = r.s + 4.0 * step.gain < best.s;  // false when the Hessian is not definite
        result.rivals[k] = (r.v + step.d).normalized();
      }
      if (safe) summary.termination = "warm start, overlap (the previous step's rivals stay below)";
    }
  } else {
    const double len = dual.c.norm();
    const Vector3d v0 = len > 0.0 ? Vector3d(dual.c / len) : Vector3d::UnitX();
    const DualPoint p0 = dual.eval(v0);
    if (p0.s > 0.0) {  // separated for sure: the concave ascent ends at the global maximum
      consider(p0);
      if (converged && best.s > 0.0) summary.termination = "separated (dual certificate)";
    }
  }

  if (!summary.termination) {
    // Overlap, or close to it: sample the dual; ascend from the samples that
    // are local maxima among their neighbours and from the best
    // `global_starts` mutually distant samples (a narrow basin can fall
    // between samples and hold no sampled maximum), best first, skipping a
    // sample when a maximum already reached lies in its cap or when its cap
    // bound s(v) <= g . v <= |g| cos(max(0, theta - rho)) cannot beat the best.
    summary.global_search = true;
    const DirectionSet& set = directionSet(options.sample_directions);
    const int half = set.count / 2, n = 2 * half;
    thread_local std::vector<double> s;
    s.resize(static_cast<size_t>(n));
    for (int i = 0; i < half; ++i) {
      const auto& m = set.monomials[static_cast<size_t>(i)];
      double qa = 0.0, qb = 0.0;
      for (int k = 0; k < 6; ++k) qa += dual.ma6[k] * m[k], qb += dual.mb6[k] * m[k];
      const double h = std::sqrt(qa) + std::sqrt(qb), vc = dual.c.dot(set.directions[static_cast<size_t>(i)]);
      s[static_cast<size_t>(i)] = vc - h;
      s[static_cast<size_t>(i + half)] = -vc - h;
    }
    // (Branch-free scans: with unpredictable comparisons, branches made these
    // loops a third of a cold overlap query, perf.)
    thread_local std::vector<std::pair<double, int>> candidates;
    thread_local std::vector<double> masked;  // s, with -inf where a chosen start excludes a sample
    candidates.clear();
    masked.assign(s.begin(), s.end());
    for (int k = 0; k < options.global_starts; ++k) {
      int top = 0;
      double top_value = masked[0];
      for (int i = 1; i < n; ++i) {
        const double value = masked[static_cast<size_t>(i)];
        const bool better = value > top_value;
        top = better ? i : top;
        top_value = better ? value : top_value;
      }
      if (top_value == -INFINITY) break;
      for (int j : set.near[static_cast<size_t>(top)]) masked[static_cast<size_t>(j)] = -INFINITY;
      candidates.push_back({s[static_cast<size_t>(top)], top});
    }
    const size_t distinct = candidates.size();
    for (int i = 0; i < n; ++i) {
      const double si = s[static_cast<size_t>(i)];
      const auto& nb = set.neighbours[static_cast<size_t>(i)];
      bool local_max = true;
      for (int k = 0; k < kNeighbours; ++k) local_max &= si >= s[static_cast<size_t>(nb[k])];
      if (local_max && std::none_of(candidates.begin(), candidates.begin() + static_cast<long>(distinct),
                                    [&](const auto& c) { return c.second == i; }))
        candidates.push_back({si, i});
    }
    std::sort(candidates.begin(), candidates.end(), [](const auto& l, const auto& r) { return l.first > r.first; });
    thread_local std::vector<Vector3d> found;  // maxima reached so far
    found.clear();
    if (converged) found.push_back(best.v);
    int ascents = 0;
    for (const auto& [si, i] : candidates) {
      const Vector3d& w = set.directions[static_cast<size_t>(i)];
      if (std::any_of(found.begin(), found.end(), [&](const Vector3d& f) { return f.dot(w) >= set.cos_cover; }))
        continue;  // a maximum already reached lies in its cap
      const DualPoint p = dual.eval(w);
      if (converged) {
        const double gn = p.g.norm(), cos_t = gn > 0.0 ? p.s / gn : 1.0;
        const double sin_t = std::sqrt(std::max(0.0, 1.0 - cos_t * cos_t));
        const double cap_bound = cos_t >= set.cos_cover ? gn : gn * (cos_t * set.cos_cover + sin_t * set.sin_cover);
        if (cap_bound <= best.s) continue;
      }
      if (ascents++ >= kMaxAscents) break;
      if (const DualPoint* end = consider(p, &found)) found.push_back(end->v);
    }
    // The best other ends are the rivals a warm start of the next step follows.
    std::sort(ends.begin(), ends.end(), [](const auto& l, const auto& r) { return l.first > r.first; });
    result.rival_count = 0;
    for (const auto& [value, v] : ends) {
      if (result.rival_count == 2) break;
      if (v.dot(best.v) > kSame ||
          std::any_of(result.rivals, result.rivals + result.rival_count, [&](const Vector3d& r) { return r.dot(v) > kSame; }))
        continue;
      result.rivals[result.rival_count++] = v;
    }
    summary.termination = !converged        ? "no ascent converged; best point of the dual reported"
                          : best.s > 0.0    ? "separated (dual certificate, after sampling)"
                                            : "overlap: best sampled maximum";
  }
  summary.status = converged ? ContactStatus::Converged : ContactStatus::NotConverged;

  const Vector3d& v = best.v;
  result.normal = v;
  result.distance = best.s;
  result.point_a = a.center + best.mav / best.ha;
  result.point_b = b.center - best.mbv / best.hb;
  result.canonical_a = a.radii.cwiseProduct(a.rotation.transpose() * v) / best.ha;
  result.canonical_b = -b.radii.cwiseProduct(b.rotation.transpose() * v) / best.hb;
  summary.certified = converged && best.s > 0.0;
  summary.residual = (best.g - best.s * v).norm() / dual.length;
  return result;
}

}  // namespace articula::contact
