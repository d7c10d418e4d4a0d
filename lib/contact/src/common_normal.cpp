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
  Vector3d x;         // global point
  Vector3d n;         // unit outward normal
  double normal_len;  // |global gradient|
  CanonicalEvaluation e;
};

PointData pointData(const ConvexShape& s, const Vector3d& u) {
  PointData p;
  p.e = evaluateCanonical(s, u);
  p.x = toGlobal(s, u);
  const Vector3d g = s.rotation * p.e.gradient.cwiseQuotient(s.radii);  // A g_l, A = R D^-1
  p.normal_len = g.norm();
  p.n = g / p.normal_len;
  return p;
}

// d n / d u for the unit normal: (I - n n^T) / |g| * R D^-1 diag(H_l).
Matrix3d unitNormalJacobian(const ConvexShape& s, const PointData& p) {
  const Matrix3d A = s.rotation * s.radii.cwiseInverse().asDiagonal();
  return (Matrix3d::Identity() - p.n * p.n.transpose()) / p.normal_len * A * p.e.hessian_diagonal.asDiagonal();
}

}  // namespace

void commonNormalSystem(const ConvexShape& a, const ConvexShape& b, const Vector3d& u_a, const Vector3d& u_b,
                        geometry::FrameMethod frame, double length, Vector6d& phi, Matrix6d& J) {
  const PointData pa = pointData(a, u_a), pb = pointData(b, u_b);
  const FrameWithDerivatives f = frameWithDerivatives(pb.n, frame);
  const Vector3d d = pb.x - pa.x;
  const double inv_l = 1.0 / length;
  phi << pa.n.dot(f.t), pa.n.dot(f.b), d.dot(f.t) * inv_l, d.dot(f.b) * inv_l, pa.e.value, pb.e.value;

  const Matrix3d dna = unitNormalJacobian(a, pa);
  const Matrix3d dnb = unitNormalJacobian(b, pb);
  const Matrix3d dt = f.dt_dn * dnb, db = f.db_dn * dnb;
  const Matrix3d Ba = a.rotation * a.radii.asDiagonal(), Bb = b.rotation * b.radii.asDiagonal();
  J.block<1, 3>(0, 0) = f.t.transpose() * dna;
  J.block<1, 3>(0, 3) = pa.n.transpose() * dt;
  J.block<1, 3>(1, 0) = f.b.transpose() * dna;
  J.block<1, 3>(1, 3) = pa.n.transpose() * db;
  J.block<1, 3>(2, 0) = -f.t.transpose() * Ba * inv_l;
  J.block<1, 3>(2, 3) = (f.t.transpose() * Bb + d.transpose() * dt) * inv_l;
  J.block<1, 3>(3, 0) = -f.b.transpose() * Ba * inv_l;
  J.block<1, 3>(3, 3) = (f.b.transpose() * Bb + d.transpose() * db) * inv_l;
  J.block<1, 3>(4, 0) = pa.e.gradient.transpose();
  J.block<1, 3>(4, 3).setZero();
  J.block<1, 3>(5, 0).setZero();
  J.block<1, 3>(5, 3) = pb.e.gradient.transpose();
}

double dualSeparation(const ConvexShape& a, const ConvexShape& b, const Vector3d& v, Vector3d* u_a, Vector3d* u_b) {
  const Vector3d ua = supportCanonical(a, v), ub = supportCanonical(b, -v);
  if (u_a) *u_a = ua;
  if (u_b) *u_b = ub;
  return v.dot(toGlobal(b, ub) - toGlobal(a, ua));
}

namespace {

// Unit directions spread evenly over the sphere (Fibonacci lattice), cached per count.
const std::vector<Vector3d>& sphereDirections(int count) {
  thread_local std::vector<Vector3d> cache;
  if (static_cast<int>(cache.size()) != count) {
    cache.resize(static_cast<size_t>(count));
    const double golden = M_PI * (3.0 - std::sqrt(5.0));
    for (int i = 0; i < count; ++i) {
      const double z = 1.0 - (2.0 * i + 1.0) / count;
      const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
      cache[static_cast<size_t>(i)] = Vector3d(r * std::cos(golden * i), r * std::sin(golden * i), z);
    }
  }
  return cache;
}

// Solves J x = rhs by Gaussian elimination with partial pivoting; false when a
// pivot falls below 1e-14 of the largest entry (singular to working precision).
// Hand-written: Eigen's PartialPivLU takes its blocked dynamic-size path even
// for a fixed 6x6, and with rcond() it was most of the solver's time (perf).
bool solve6(Matrix6d J, Vector6d rhs, Vector6d& x) {
  const double scale = J.cwiseAbs().maxCoeff();
  if (!(scale > 0.0) || !std::isfinite(scale)) return false;
  for (int k = 0; k < 6; ++k) {
    int p = k;
    for (int i = k + 1; i < 6; ++i)
      if (std::fabs(J(i, k)) > std::fabs(J(p, k))) p = i;
    if (!(std::fabs(J(p, k)) > 1e-14 * scale)) return false;
    if (p != k) {
      J.row(p).swap(J.row(k));
      std::swap(rhs[p], rhs[k]);
    }
    const double inv = 1.0 / J(k, k);
    for (int i = k + 1; i < 6; ++i) {
      const double f = J(i, k) * inv;
      if (f == 0.0) continue;
      for (int j = k + 1; j < 6; ++j) J(i, j) -= f * J(k, j);
      rhs[i] -= f * rhs[k];
    }
  }
  for (int k = 5; k >= 0; --k) {
    double sum = rhs[k];
    for (int j = k + 1; j < 6; ++j) sum -= J(k, j) * x[j];
    x[k] = sum / J(k, k);
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
  Vector3d best_ua = Vector3d::Zero(), best_ub = Vector3d::Zero();
  double best_residual = 0.0;

  // Damped Newton from (u_a, u_b); on success records the candidate and returns its distance.
  bool newton(Vector3d u_a, Vector3d u_b, double* distance) {
    ++summary.starts;
    Vector6d q, phi, trial_phi, delta;
    q << u_a, u_b;
    Matrix6d J, trial_J;
    commonNormalSystem(a, b, q.head<3>(), q.tail<3>(), options.frame, length, phi, J);
    if (!phi.allFinite() || !J.allFinite()) return false;
    double merit = phi.squaredNorm();
    bool converged = false;
    for (int it = 0; it < options.max_iterations; ++it) {
      if (std::sqrt(merit) <= options.residual_tolerance) {
        converged = true;
        break;
      }
      ++summary.iterations;
      bool accepted = false;
      if (solve6(J, -phi, delta)) {
        const double norm = delta.norm();
        if (norm > 0.5) delta *= 0.5 / norm;  // a point never needs to move more than this at once
        for (double alpha = 1.0; alpha >= 1.0 / 64.0; alpha *= 0.5) {
          const Vector6d trial = q + alpha * delta;
          commonNormalSystem(a, b, trial.head<3>(), trial.tail<3>(), options.frame, length, trial_phi, trial_J);
          const double trial_merit = trial_phi.squaredNorm();
          if (trial_phi.allFinite() && trial_merit <= (1.0 - 1e-4 * alpha) * merit) {
            delta *= alpha;
            q = trial;
            phi = trial_phi;
            J = trial_J;
            merit = trial_merit;
            accepted = true;
            break;
          }
        }
      }
      if (!accepted) {
        // Levenberg-Marquardt: singular Jacobian, or a Newton direction that does not descend.
        const Matrix6d JtJ = J.transpose() * J;
        const Vector6d g = J.transpose() * phi;
        double mu = 1e-6 * (JtJ.trace() / 6.0 + 1e-30);
        for (int k = 0; k < 12 && !accepted; ++k, mu *= 10.0) {
          Matrix6d M = JtJ;
          M.diagonal().array() += mu;
          delta = -M.ldlt().solve(g);
          const Vector6d trial = q + delta;
          commonNormalSystem(a, b, trial.head<3>(), trial.tail<3>(), options.frame, length, trial_phi, trial_J);
          const double trial_merit = trial_phi.squaredNorm();
          if (trial_phi.allFinite() && trial_merit < merit) {
            q = trial;
            phi = trial_phi;
            J = trial_J;
            merit = trial_merit;
            accepted = true;
          }
        }
        ++summary.damped_steps;
        if (!accepted) {
          // Stalled: at rounding level this is convergence, otherwise a failed start.
          converged = std::sqrt(merit) <= 1e-11;
          break;
        }
      }
      if (delta.norm() <= options.step_tolerance) {
        converged = true;
        break;
      }
    }
    if (!converged && std::sqrt(merit) <= 1e-11) converged = true;  // iteration cap at rounding level
    if (!converged) return false;
    const PointData pa = pointData(a, q.head<3>()), pb = pointData(b, q.tail<3>());
    if (pa.n.dot(pb.n) > -0.5) return false;  // parallel normals, same sense: not a contact pair
    const Vector3d d = pb.x - pa.x;
    const double signed_distance = std::copysign(d.norm(), pa.n.dot(d));
    if (distance) *distance = signed_distance;
    if (!have || signed_distance > best) {
      have = true;
      best = signed_distance;
      best_ua = q.head<3>();
      best_ub = q.tail<3>();
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

}  // namespace

ContactResult computeContact(const ConvexShape& a, const ConvexShape& b, const ContactOptions& options,
                             const ContactResult* warm_start) {
  options.validate();
  if (options.solver == ContactSolver::Auto && a.quadric && b.quadric) return ellipsoidContact(a, b, options, warm_start);
  ContactResult result;
  ContactSummary& summary = result.summary;
  bool hill_climb_answer = false;
  Solver solver{a, b, options, std::max(boundingRadius(a), boundingRadius(b)), summary};

  double distance = 0.0;
  bool done = false;
  if (warm_start) {
    summary.warm_started = true;
    if (solver.newton(warm_start->canonical_a, warm_start->canonical_b, &distance))
      done = distance > 0.0 || !options.verify_warm_overlap;
    if (done) summary.termination = distance > 0.0 ? "warm start, separated" : "warm start, local solution kept";
  }
  if (!done) {
    // Cold start from the centre-to-centre direction: a separated answer is final.
    Vector3d v = b.center - a.center;
    v = v.norm() > 0.0 ? Vector3d(v.normalized()) : Vector3d::UnitX();
    if (solver.startFromDirection(v, &distance) && distance > 0.0) {
      done = true;
      summary.termination = "separated (dual certificate)";
    }
  }
  if (!done) {
    // Overlap (or a failed start): sample the dual, start from the best distinct directions.
    summary.global_search = true;
    const auto& dirs = sphereDirections(options.sample_directions);
    std::vector<std::pair<double, int>> samples(dirs.size());
    for (size_t i = 0; i < dirs.size(); ++i) samples[i] = {dualSeparation(a, b, dirs[i]), static_cast<int>(i)};
    std::sort(samples.begin(), samples.end(), [](const auto& l, const auto& r) { return l.first > r.first; });
    std::vector<Vector3d> chosen;
    for (const auto& [s, i] : samples) {
      const Vector3d& d = dirs[static_cast<size_t>(i)];
      if (std::any_of(chosen.begin(), chosen.end(), [&](const Vector3d& c) { return c.dot(d) > 0.85; })) continue;
      chosen.push_back(d);
      solver.startFromDirection(d, nullptr);
      if (static_cast<int>(chosen.size()) >= options.global_starts) break;
    }
    const double sampled_max = samples.front().first;
    if (!solver.have || solver.best < sampled_max - 1e-12 * solver.length) {
      double s_climb = 0.0;
      const Vector3d v = solver.climb(dirs[static_cast<size_t>(samples.front().second)], &s_climb);
      if (!solver.startFromDirection(v, nullptr) || solver.best < s_climb - 1e-9 * solver.length) {
        // No Newton start reached the dual's maximum: report the hill climb's answer.
        Vector3d ua, ub;
        dualSeparation(a, b, v, &ua, &ub);
        solver.have = true;
        solver.best = s_climb;
        solver.best_ua = ua;
        solver.best_ub = ub;
        hill_climb_answer = true;
        summary.termination = "no Newton start converged to the dual maximum; dual hill climb answer";
      }
    }
    if (!summary.termination)
      summary.termination = solver.best > 0.0 ? "separated (dual certificate, after global search)"
                                              : "overlap: best of the global search";
  }
  if (!hill_climb_answer) summary.status = ContactStatus::Converged;

  result.canonical_a = solver.best_ua;
  result.canonical_b = solver.best_ub;
  result.point_a = toGlobal(a, solver.best_ua);
  result.point_b = toGlobal(b, solver.best_ub);
  const Vector3d g = a.rotation * evaluateCanonical(a, solver.best_ua).gradient.cwiseQuotient(a.radii);
  result.normal = g.normalized();
  const Vector3d d = result.point_b - result.point_a;
  result.distance = std::copysign(d.norm(), result.normal.dot(d));
  summary.certified = result.distance > 0.0 && summary.status == ContactStatus::Converged;
  summary.residual = solver.best_residual;
  return result;
}

}  // namespace articula::contact
