#include "articula/contact/common_normal.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <vector>

#include <Eigen/Cholesky>

#include "articula/contact/ellipsoid_contact.hpp"
#include "articula/contact/frame_derivatives.hpp"
#include "articula/core/error.hpp"
#include "articula/geometry/fibonacci.hpp"

namespace articula::contact {

using Eigen::Matrix3d;
using Eigen::Vector3d;

void ContactOptions::validate() const {
  if (frame != geometry::FrameMethod::Householder && frame != geometry::FrameMethod::SquarePlate)
    throw UsageError(std::string("contact options: frame must be Householder or SquarePlate, found ") +
                     geometry::frameMethodName(frame));
  if (max_iterations < 1 || max_iterations > 10000)
    throw UsageError("contact options: max_iterations must be in [1, 10000], found " + std::to_string(max_iterations));
  if (!(step_tolerance > 0.0) || !(step_tolerance < 1e-2))
    throw UsageError("contact options: step_tolerance must be in (0, 1e-2), found " + std::to_string(step_tolerance));
  if (!(residual_tolerance > 0.0) || !(residual_tolerance < 1e-2))
    throw UsageError("contact options: residual_tolerance must be in (0, 1e-2), found " +
                     std::to_string(residual_tolerance));
  if (sample_directions < 6 || sample_directions > 100000)
    throw UsageError("contact options: sample_directions must be in [6, 100000], found " +
                     std::to_string(sample_directions));
  if (global_starts < 1 || global_starts > sample_directions)
    throw UsageError("contact options: global_starts must be in [1, sample_directions], found " +
                     std::to_string(global_starts));
}

const char* statusName(ContactStatus status) {
  return status == ContactStatus::Converged ? "converged" : "not_converged";
}

std::string ContactSummary::briefReport() const {
  std::ostringstream s;
  s << statusName(status) << " (" << termination << "), iterations " << iterations << ", starts " << starts
    << ", damped steps " << damped_steps << ", |Phi| " << residual << (warm_started ? ", warm" : ", cold")
    << (global_search ? ", global search" : "") << (certified ? ", certified" : "");
  return s.str();
}

namespace {

struct PointData {
  Vector3d u;         // canonical point
  Vector3d x;         // global point
  Vector3d n;         // unit outward normal
  double normal_len;  // |global gradient|
  CanonicalEvaluation e;
};

// `near`: the last iterate's data, whose powers a nearby point updates by series.
PointData pointData(const ConvexShape& s, const Vector3d& u, const PointData* near = nullptr) {
  PointData p;
  p.u = u;
  p.e = near ? evaluateCanonical(s, u, near->u, near->e) : evaluateCanonical(s, u);
  p.x = toGlobal(s, u);
  const Vector3d g = s.rotation * p.e.gradient.cwiseQuotient(s.radii);  // A g_l, A = R D^-1
  p.normal_len = g.norm();
  p.n = g / p.normal_len;
  return p;
}

// d n / d u for the unit normal: (I - n n^T) / |g| * R D^-1 diag(H_l).
Matrix3d unitNormalJacobian(const ConvexShape& s, const PointData& p) {
  const Matrix3d m = s.rotation * p.e.hessian_diagonal.cwiseQuotient(s.radii).asDiagonal();
  return (m - p.n * (p.n.transpose() * m)) / p.normal_len;
}

}  // namespace

namespace {

// The residual's pieces at (u_A, u_B), kept so that the Jacobian (needed only
// for a step, not for a line-search trial or the final check) and the answer
// reuse them without evaluating the powers again.
struct SystemPoint {
  PointData pa, pb;
  FrameWithDerivatives f;
  Vector3d d;
};

void residual(const ConvexShape& a, const ConvexShape& b, const Vector3d& u_a, const Vector3d& u_b,
              geometry::FrameMethod frame, double inv_l, SystemPoint& p, Vector6d& phi,
              const SystemPoint* near = nullptr) {
  p.pa = pointData(a, u_a, near ? &near->pa : nullptr);
  p.pb = pointData(b, u_b, near ? &near->pb : nullptr);
  p.f = frameWithDerivatives(p.pb.n, frame);
  p.d = p.pb.x - p.pa.x;
  phi << p.pa.n.dot(p.f.t), p.pa.n.dot(p.f.b), p.d.dot(p.f.t) * inv_l, p.d.dot(p.f.b) * inv_l, p.pa.e.value,
      p.pb.e.value;
}

void jacobian(const ConvexShape& a, const ConvexShape& b, const SystemPoint& p, double inv_l, Matrix6d& J) {
  const FrameWithDerivatives& f = p.f;
  const Matrix3d dna = unitNormalJacobian(a, p.pa);
  const Matrix3d dnb = unitNormalJacobian(b, p.pb);
  // Rows through d t / d u_B = dt_dn dnb (and b): vector-matrix products only.
  using Row = Eigen::RowVector3d;
  const Row na_dt = (p.pa.n.transpose() * f.dt_dn) * dnb, na_db = (p.pa.n.transpose() * f.db_dn) * dnb;
  const Row d_dt = (p.d.transpose() * f.dt_dn) * dnb, d_db = (p.d.transpose() * f.db_dn) * dnb;
  // t^T R D = (R^T t)^T D.
  const Row ta = (a.rotation.transpose() * f.t).cwiseProduct(a.radii).transpose();
  const Row ba = (a.rotation.transpose() * f.b).cwiseProduct(a.radii).transpose();
  const Row tb = (b.rotation.transpose() * f.t).cwiseProduct(b.radii).transpose();
  const Row bb = (b.rotation.transpose() * f.b).cwiseProduct(b.radii).transpose();
  J.block<1, 3>(0, 0) = f.t.transpose() * dna;
  J.block<1, 3>(0, 3) = na_dt;
  J.block<1, 3>(1, 0) = f.b.transpose() * dna;
  J.block<1, 3>(1, 3) = na_db;
  J.block<1, 3>(2, 0) = -ta * inv_l;
  J.block<1, 3>(2, 3) = (tb + d_dt) * inv_l;
  J.block<1, 3>(3, 0) = -ba * inv_l;
  J.block<1, 3>(3, 3) = (bb + d_db) * inv_l;
  J.block<1, 3>(4, 0) = p.pa.e.gradient.transpose();
  J.block<1, 3>(4, 3).setZero();
  J.block<1, 3>(5, 0).setZero();
  J.block<1, 3>(5, 3) = p.pb.e.gradient.transpose();
}

}  // namespace

void commonNormalSystem(const ConvexShape& a, const ConvexShape& b, const Vector3d& u_a, const Vector3d& u_b,
                        geometry::FrameMethod frame, double length, Vector6d& phi, Matrix6d& J) {
  SystemPoint p;
  residual(a, b, u_a, u_b, frame, 1.0 / length, p, phi);
  jacobian(a, b, p, 1.0 / length, J);
}

double dualSeparation(const ConvexShape& a, const ConvexShape& b, const Vector3d& v, Vector3d* u_a, Vector3d* u_b) {
  const Vector3d ua = supportCanonical(a, v), ub = supportCanonical(b, -v);
  if (u_a) *u_a = ua;
  if (u_b) *u_b = ub;
  return v.dot(toGlobal(b, ub) - toGlobal(a, ua));
}

namespace {

// A Fibonacci lattice on the upper half sphere (`half` directions), cached
// per count; with its negation, the antipodal sample set of the global search.
const std::vector<Vector3d>& upperHalfDirections(int half) {
  thread_local std::vector<Vector3d> cache;
  if (static_cast<int>(cache.size()) != half) {
    cache.resize(static_cast<size_t>(half));
    for (int i = 0; i < half; ++i) cache[static_cast<size_t>(i)] = geometry::fibonacciDirection(i, half, 0.0);
  }
  return cache;
}

// h(v) = max over the body of v . (x - c).
double supportValue(const ConvexShape& s, const Vector3d& v) {
  return v.dot(s.rotation * s.radii.cwiseProduct(supportCanonical(s, v)));
}

// Solves J x = rhs for the common-normal Jacobian, whose rows 4 and 5 are
// [grad F_A, 0] and [0, grad F_B]: each of them eliminates one unknown of its
// point (the largest gradient component, a safe pivot), which leaves a 4x4
// system for Gaussian elimination with partial pivoting (a third of the work
// of the dense 6x6). False when a pivot falls below 1e-14 of the largest
// entry (singular to working precision). Hand-written: Eigen's PartialPivLU
// takes its blocked dynamic-size path even for a fixed 6x6, and with rcond()
// it was most of the solver's time (perf).
bool solveCommonNormal(const Matrix6d& J, const Vector6d& rhs, Vector6d& x) {
  const double scale = J.cwiseAbs().maxCoeff();
  if (!(scale > 0.0) || !std::isfinite(scale)) return false;
  const double tiny = 1e-14 * scale;
  int pivot[2], keep[4], kept = 0;
  double factor[4][2], inv_gradient[2];  // row r of the top block minus factor * (row 4 + block) zeroes column pivot[block]
  for (int block = 0; block < 2; ++block) {
    const int row = 4 + block, c0 = 3 * block;
    int p = c0;
    for (int k = c0 + 1; k < c0 + 3; ++k)
      if (std::fabs(J(row, k)) > std::fabs(J(row, p))) p = k;
    if (!(std::fabs(J(row, p)) > tiny)) return false;
    pivot[block] = p;
    for (int k = c0; k < c0 + 3; ++k)
      if (k != p) keep[kept++] = k;
    inv_gradient[block] = 1.0 / J(row, p);
    for (int r = 0; r < 4; ++r) factor[r][block] = J(r, p) * inv_gradient[block];
  }
  double m[4][5];  // the reduced system [M | b] over the unknowns keep[0..3]
  for (int r = 0; r < 4; ++r) {
    for (int j = 0; j < 4; ++j) {
      const int block = keep[j] / 3;
      m[r][j] = J(r, keep[j]) - factor[r][block] * J(4 + block, keep[j]);
    }
    m[r][4] = rhs[r] - factor[r][0] * rhs[4] - factor[r][1] * rhs[5];
  }
  double inv_pivot[4];
  for (int k = 0; k < 4; ++k) {
    int p = k;
    for (int i = k + 1; i < 4; ++i)
      if (std::fabs(m[i][k]) > std::fabs(m[p][k])) p = i;
    if (!(std::fabs(m[p][k]) > tiny)) return false;
    if (p != k)
      for (int j = k; j < 5; ++j) std::swap(m[p][j], m[k][j]);
    inv_pivot[k] = 1.0 / m[k][k];
    for (int i = k + 1; i < 4; ++i) {
      const double f = m[i][k] * inv_pivot[k];
      for (int j = k + 1; j < 5; ++j) m[i][j] -= f * m[k][j];
    }
  }
  double y[4];
  for (int k = 3; k >= 0; --k) {
    double sum = m[k][4];
    for (int j = k + 1; j < 4; ++j) sum -= m[k][j] * y[j];
    y[k] = sum * inv_pivot[k];
  }
  for (int j = 0; j < 4; ++j) x[keep[j]] = y[j];
  for (int block = 0; block < 2; ++block) {
    const int row = 4 + block, p = pivot[block];
    double sum = rhs[row];
    for (int k = 3 * block; k < 3 * block + 3; ++k)
      if (k != p) sum -= J(row, k) * x[k];
    x[p] = sum * inv_gradient[block];
  }
  return x.allFinite();
}

struct Solver {
  const ConvexShape& a;
  const ConvexShape& b;
  const ContactOptions& options;
  double length;
  ContactSummary& summary;

  // Best answer so far (largest signed distance among converged starts).
  bool have = false;
  double best = -std::numeric_limits<double>::infinity();
  Vector3d best_ua = Vector3d::Zero(), best_ub = Vector3d::Zero(), best_normal = Vector3d::UnitX();
  double best_residual = 0.0;

  // Damped Newton from (u_a, u_b); on success records the candidate and returns its distance.
  bool newton(Vector3d u_a, Vector3d u_b, double* distance) {
    ++summary.starts;
    const double inv_l = 1.0 / length;
    Vector6d q, phi, trial_phi, delta;
    q << u_a, u_b;
    Matrix6d J;
    // The current point and a trial one; accepting a trial swaps the roles
    // by pointer (std::swap of the points themselves copied hundreds of bytes three times).
    SystemPoint points[2];
    SystemPoint* point = &points[0];
    SystemPoint* trial_point = &points[1];
    residual(a, b, q.head<3>(), q.tail<3>(), options.frame, inv_l, *point, phi);
    if (!phi.allFinite()) return false;
    bool have_jacobian = false;
    auto needJacobian = [&] {
      if (!have_jacobian) jacobian(a, b, *point, inv_l, J);
      have_jacobian = true;
      return J.allFinite();
    };
    // A trial point replaces the current one when it lowers the merit enough.
    auto tryPoint = [&](const Vector6d& trial, double required) {
      residual(a, b, trial.head<3>(), trial.tail<3>(), options.frame, inv_l, *trial_point, trial_phi, point);
      const double trial_merit = trial_phi.squaredNorm();
      if (!(trial_phi.allFinite() && trial_merit <= required)) return false;
      q = trial;
      phi = trial_phi;
      std::swap(point, trial_point);
      have_jacobian = false;
      return true;
    };
    double merit = phi.squaredNorm();
    bool converged = false;
    // A start that has needed this many Levenberg-Marquardt steps is far from
    // any contact pair: on the bench's 800 overlapping superellipsoid pairs,
    // 72 of the 73 starts that took more failed, after up to 40 iterations
    // (the costliest part of a cold search). The other starts and the dual
    // hill climb cover it.
    constexpr int kMaxDampedSteps = 8;
    int damped_steps = 0;
    for (int it = 0; it < options.max_iterations; ++it) {
      if (std::sqrt(merit) <= options.residual_tolerance) {
        converged = true;
        break;
      }
      if (!needJacobian()) return false;
      ++summary.iterations;
      bool accepted = false;
      if (solveCommonNormal(J, -phi, delta)) {
        const double norm = delta.norm();
        if (norm > 0.5) delta *= 0.5 / norm;  // a point never needs to move more than this at once
        for (double alpha = 1.0; alpha >= 1.0 / 64.0; alpha *= 0.5) {
          if (tryPoint(q + alpha * delta, (1.0 - 1e-4 * alpha) * merit)) {
            delta *= alpha;
            accepted = true;
            break;
          }
        }
      }
      const bool damped = !accepted;
      if (damped) {
        // Levenberg-Marquardt: singular Jacobian, or a Newton direction that does not descend.
        const Matrix6d JtJ = J.transpose() * J;
        const Vector6d g = J.transpose() * phi;
        double mu = 1e-6 * (JtJ.trace() / 6.0 + 1e-30);
        for (int k = 0; k < 12 && !accepted; ++k, mu *= 10.0) {
          Matrix6d M = JtJ;
          M.diagonal().array() += mu;
          delta = -M.ldlt().solve(g);
          accepted = tryPoint(q + delta, std::nextafter(merit, 0.0));
        }
        ++summary.damped_steps;
        if (!accepted || ++damped_steps == kMaxDampedSteps) {
          merit = phi.squaredNorm();
          // Stalled, or damped too often: at rounding level this is convergence, otherwise a failed start.
          converged = std::sqrt(merit) <= 1e-11;
          break;
        }
      }
      merit = phi.squaredNorm();
      // A tiny Levenberg-Marquardt step (large damping) says nothing about convergence.
      if (!damped && delta.norm() <= options.step_tolerance) {
        converged = true;
        break;
      }
    }
    if (!converged && std::sqrt(merit) <= 1e-11) converged = true;  // iteration cap at rounding level
    if (!converged) return false;
    const PointData& pa = point->pa;
    if (pa.n.dot(point->pb.n) > -0.5) return false;  // parallel normals, same sense: not a contact pair
    const double signed_distance = std::copysign(point->d.norm(), pa.n.dot(point->d));
    if (distance) *distance = signed_distance;
    if (!have || signed_distance > best) {
      have = true;
      best = signed_distance;
      best_ua = q.head<3>();
      best_ub = q.tail<3>();
      best_normal = pa.n;
      best_residual = std::sqrt(merit);
    }
    return true;
  }

  bool startFromDirection(const Vector3d& v, double* distance) {
    Vector3d ua, ub;
    dualSeparation(a, b, v, &ua, &ub);
    return newton(ua, ub, distance);
  }

  // Hill climb of s(v) on the sphere: slow but sure; the last resort for a start.
  Vector3d climb(Vector3d v, double* s_out) {
    Vector3d ua, ub;
    double s = dualSeparation(a, b, v, &ua, &ub);
    double step = 0.2;
    for (int it = 0; it < 400 && step > 1e-12; ++it) {
      const Vector3d g = toGlobal(b, ub) - toGlobal(a, ua);  // gradient of s
      const Vector3d gt = g - g.dot(v) * v;
      if (gt.norm() <= 1e-15 * length) break;
      const Vector3d trial = (v + step * gt.normalized()).normalized();
      Vector3d tua, tub;
      const double ts = dualSeparation(a, b, trial, &tua, &tub);
      if (ts > s) {
        v = trial, s = ts, ua = tua, ub = tub;
        step = std::min(0.5, step * 1.5);
      } else {
        step *= 0.5;
      }
    }
    *s_out = s;
    return v;
  }
};

// Whether a stationary point of the dual with value s is its global maximum.
// Each body is a convex body plus a ball of its least radius of curvature
// (leastRadiusOfCurvature), so along every great circle s'' + s <= -k with
// k the sum of the two radii, and from a stationary point (Sturm comparison)
// s(phi) <= (s + k) cos phi - k, below s elsewhere once s + k > 0. The margin
// is the ellipsoid path's: what a gradient at the tolerance could add elsewhere
// stays at rounding level.
bool certifiedByCurvature(const ConvexShape& a, const ConvexShape& b, double s, double length) {
  return s + leastRadiusOfCurvature(a) + leastRadiusOfCurvature(b) > 1e-4 * length;
}

}  // namespace

ContactResult computeContact(const ConvexShape& a, const ConvexShape& b, const ContactOptions& options,
                             const ContactResult* warm_start) {
  if (options.solver == ContactSolver::Auto && a.quadric && b.quadric)
    return ellipsoidContact(a, b, options, warm_start);  // validates the options
  options.validate();
  ContactResult result;
  ContactSummary& summary = result.summary;
  bool hill_climb_answer = false, certified_overlap = false;
  Solver solver{a, b, options, std::max(boundingRadius(a), boundingRadius(b)), summary};
  // A converged start's overlap that the curvature certificate proves global.
  auto certifiesOverlap = [&](double s) {
    certified_overlap = options.curvature_certificate && certifiedByCurvature(a, b, s, solver.length);
    return certified_overlap;
  };

  double distance = 0.0;
  bool done = false;
  if (warm_start) {
    summary.warm_started = true;
    if (solver.newton(warm_start->canonical_a, warm_start->canonical_b, &distance)) {
      if (distance > 0.0) {
        done = true;
        summary.termination = "warm start, separated";
      } else if (!options.verify_warm_overlap) {
        done = true;
        summary.termination = "warm start, local solution kept";
      } else if (certifiesOverlap(distance)) {
        done = true;
        summary.termination = "warm start, overlap within the curvature bound (curvature certificate)";
      }
    }
  }
  if (!done) {
    // Cold start from the centre-to-centre direction: a separated answer is
    // final, and so is an overlap within the curvature bound.
    Vector3d v = b.center - a.center;
    v = v.norm() > 0.0 ? Vector3d(v.normalized()) : Vector3d::UnitX();
    if (solver.startFromDirection(v, &distance)) {
      if (distance > 0.0) {
        done = true;
        summary.termination = "separated (dual certificate)";
      } else if (certifiesOverlap(distance)) {
        done = true;
        summary.termination = "overlap within the curvature bound (curvature certificate)";
      }
    }
  }
  if (!done) {
    // Overlap (or a failed start): sample the dual, start from the best distinct directions.
    summary.global_search = true;
    // Antipodal samples: both bodies are centrally symmetric (h(-v) = h(v)),
    // so s(v) = v . (c_B - c_A) - h_A(v) - h_B(v) and s(-v) share one support
    // point per body, half the support mappings of a full lattice.
    const Vector3d centres = b.center - a.center;
    std::vector<std::pair<double, Vector3d>> samples;
    samples.reserve(static_cast<size_t>(options.sample_directions));
    for (const Vector3d& v : upperHalfDirections(options.sample_directions / 2)) {
      const double h = supportValue(a, v) + supportValue(b, v), along = v.dot(centres);
      samples.emplace_back(along - h, v);
      samples.emplace_back(-along - h, -v);
    }
    std::sort(samples.begin(), samples.end(), [](const auto& l, const auto& r) { return l.first > r.first; });
    std::vector<Vector3d> chosen;
    for (const auto& sample : samples) {
      // A named reference, not a structured binding: lambdas may capture those only from C++20 (Clang refuses).
      const Vector3d& d = sample.second;
      if (std::any_of(chosen.begin(), chosen.end(), [&](const Vector3d& c) { return c.dot(d) > 0.85; })) continue;
      chosen.push_back(d);
      solver.startFromDirection(d, nullptr);
      if (static_cast<int>(chosen.size()) >= options.global_starts) break;
    }
    const double sampled_max = samples.front().first;
    if (!solver.have || solver.best < sampled_max - 1e-12 * solver.length) {
      double s_climb = 0.0;
      const Vector3d v = solver.climb(samples.front().second, &s_climb);
      if (!solver.startFromDirection(v, nullptr) || solver.best < s_climb - 1e-9 * solver.length) {
        // No Newton start reached the dual's maximum: report the hill climb's answer.
        Vector3d ua, ub;
        dualSeparation(a, b, v, &ua, &ub);
        solver.have = true;
        solver.best = s_climb;
        solver.best_ua = ua;
        solver.best_ub = ub;
        solver.best_normal = a.rotation * evaluateCanonical(a, ua).gradient.cwiseQuotient(a.radii).normalized();
        hill_climb_answer = true;
        summary.termination = "no Newton start converged to the dual maximum; dual hill climb answer";
      }
    }
    if (!summary.termination)
      summary.termination = solver.best > 0.0 ? "separated (dual certificate, after global search)"
                                              : "overlap: best of the global search";
    // The search's answer may lie above -k where the first start's did not.
    if (!hill_climb_answer && solver.best <= 0.0)
      certified_overlap = certifiedByCurvature(a, b, solver.best, solver.length);
  }
  if (!hill_climb_answer) summary.status = ContactStatus::Converged;

  result.canonical_a = solver.best_ua;
  result.canonical_b = solver.best_ub;
  result.point_a = toGlobal(a, solver.best_ua);
  result.point_b = toGlobal(b, solver.best_ub);
  result.normal = solver.best_normal;
  const Vector3d d = result.point_b - result.point_a;
  result.distance = std::copysign(d.norm(), result.normal.dot(d));
  summary.certified = (result.distance > 0.0 || certified_overlap) && summary.status == ContactStatus::Converged;
  summary.residual = solver.best_residual;
  return result;
}

}  // namespace articula::contact
