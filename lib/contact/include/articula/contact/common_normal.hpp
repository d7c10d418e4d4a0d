#pragma once
// Minimum signed distance between two smooth convex bodies (sphere, ellipsoid,
// superellipsoid) by the common-normal system of thesis eq. 5.23, solved by
// Newton-Raphson (eq. 5.22) with the analytic 6x6 Jacobian (eq. 5.26-5.28).
//
// Unknowns: the canonical coordinates u_A, u_B of the two points (q^G of
// eq. 5.24 up to the diagonal scaling D). Residual (rows 3-4 divided by a
// length L so that every row is dimensionless):
//   [ n_A . t_B, n_A . b_B, d . t_B / L, d . b_B / L, F_A(u_A), F_B(u_B) ],
// with n_A the unit outward normal of A, (t_B, b_B) the tangent frame of B's
// unit normal (Householder or square plate) and d = x_B - x_A.
//
// Finding the right solution every time: the support-function dual
//   s(v) = v . (c_B - c_A) - h_A(v) - h_B(-v),   signed distance = max_|v|=1 s(v)
// has, at a common-normal pair with opposite normals, s(n_A) = n_A . d and a
// stationary point. s is concave and 1-homogeneous, so a stationary point with
// s > 0 is the global maximum: a separated answer is certified. So is an
// overlap shallower than k, the sum of the bodies' least radii of curvature
// (leastRadiusOfCurvature): each body is a convex body plus a ball of that
// radius, and a stationary point with s > -k is the dual's only maximum.
// Otherwise (deeper overlap) the dual is sampled over the sphere and Newton
// is started from the best distinct directions; the answer is the largest s
// found (the minimum penetration depth). Newton is damped by a backtracking line search;
// on a singular Jacobian or a rejected step it takes Levenberg-Marquardt
// steps; when every start stalls, a hill climb on the dual gives the start.
// Signed distance (table 5.2): d = sign(n_A . d_AB) |d_AB|, > 0 apart, < 0 overlap.
#include <cmath>
#include <memory>
#include <string>

#include <Eigen/Core>

#include "articula/contact/convex_shape.hpp"
#include "articula/geometry/frames.hpp"

namespace articula::contact {

/// Which formulation solves a pair of ellipsoids (other pairs always use the common-normal system).
enum class ContactSolver {
  Auto,          // ellipsoid pairs: Newton on the support-function dual (ellipsoid_contact.hpp)
  CommonNormal,  // always the common-normal system of eq. 5.23 (thesis behaviour, e.g. to compare frames)
};

struct ContactOptions {
  ContactSolver solver = ContactSolver::Auto;
  geometry::FrameMethod frame = geometry::FrameMethod::Householder;  // or SquarePlate (common-normal system)
  int max_iterations = 40;          // Newton iterations per start
  double step_tolerance = 1e-13;    // stop when |delta u| (canonical, dimensionless) is below
  double residual_tolerance = 1e-14;  // or when |Phi| (dimensionless) is below
  int sample_directions = 64;       // dual samples for the global search (overlap)
  int global_starts = 3;            // common-normal system: Newton starts from the best distinct samples
  bool verify_warm_overlap = false;  // warm start and overlap: also run the global search
  // An overlap shallower than the bodies' least radii of curvature is
  // certified without the global search (ellipsoid pairs: ellipsoid_contact.hpp;
  // others: the first Newton start's answer, and with verify_warm_overlap a
  // warm start's); false searches anyway (to check the certificate).
  bool curvature_certificate = true;
  /// Throws UsageError naming the first bad field.
  void validate() const;
};

enum class ContactStatus {
  Converged,     // Newton converged; separated answers (and overlaps above -k) are certified global
  NotConverged,  // no Newton start converged: the answer is the dual hill climb's
};
const char* statusName(ContactStatus status);  // "converged", "not_converged"

struct ContactSummary {
  ContactStatus status = ContactStatus::NotConverged;
  const char* termination = nullptr;  // why the solver stopped, in words (static string)
  int iterations = 0;        // Newton iterations over every start
  int starts = 0;            // Newton starts
  int damped_steps = 0;      // Levenberg-Marquardt steps (singular Jacobian or rejected Newton step)
  bool warm_started = false;
  bool global_search = false;  // the dual was sampled
  bool certified = false;      // the answer is proven the dual's global maximum: separated (concavity), or
                               // an overlap shallower than the bodies' least radii of curvature (cold, or
                               // searched; a warm overlap only with verify_warm_overlap)
  double residual = 0.0;       // |Phi| at the answer
  std::string briefReport() const;
};

/// What the global search of the support-function dual (overlapping
/// ellipsoids, ellipsoid_contact.hpp) leaves for warm starts, so that they
/// keep the answer without searching again while they can prove it: where
/// the other ascents ended (rivals) with the most they could still reach,
/// the sample caps whose bounds came closest to the answer (watched) with
/// those bounds, and one bound of the dual everywhere else; all at the
/// search's pose (L = D R^T of each shape, c_B - c_A). The dual has moved by
/// at most |delta c| + |delta L_A|_F + |delta L_B|_F since.
struct DualSearchState {
  static constexpr int kRivals = 3, kWatched = 8;
  int rival_count = 0;
  Eigen::Vector3d rivals[kRivals];  // (set where rival_count says)
  double rival_ceilings[kRivals] = {};
  int watch_count = 0;
  Eigen::Vector3d watch[kWatched];   // (set where watch_count says)
  double watch_bounds[kWatched] = {};
  double cap_radius = 0.0;          // of the search's sample caps (rad)
  double outside_bound = INFINITY;  // s beyond the answer, the rivals and the watched caps
  Eigen::Matrix3d l_a = Eigen::Matrix3d::Zero(), l_b = Eigen::Matrix3d::Zero();
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
};

struct ContactResult {
  double distance = 0.0;                                    // signed, mm
  Eigen::Vector3d point_a = Eigen::Vector3d::Zero();        // on A (mm)
  Eigen::Vector3d point_b = Eigen::Vector3d::Zero();        // on B (mm)
  Eigen::Vector3d normal = Eigen::Vector3d::UnitX();        // unit outward normal of A at point_a
  Eigen::Vector3d canonical_a = Eigen::Vector3d::UnitX();   // u_A: warm start of the next call
  Eigen::Vector3d canonical_b = -Eigen::Vector3d::UnitX();  // u_B
  // Ellipsoid pairs: what the last global search saw, for warm starts
  // (ellipsoid_contact.hpp); null when no search is behind this result.
  // Shared and immutable: a warm start passes it on without a copy, and a
  // result stays small (184 bytes, not 720) for callers that keep one per pair.
  std::shared_ptr<const DualSearchState> search;
  ContactSummary summary;
};

/// The minimum signed distance between A and B. `warm_start` (the previous
/// time step's result, section 5.4.5) seeds Newton; nullptr means cold.
/// Two ellipsoids go to ellipsoidContact unless options.solver is CommonNormal.
ContactResult computeContact(const ConvexShape& a, const ConvexShape& b, const ContactOptions& options = {},
                             const ContactResult* warm_start = nullptr);

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

/// The residual Phi of eq. 5.23 (scaled as above, L = `length`) and its
/// analytic Jacobian d Phi / d [u_A; u_B] at canonical points u_A, u_B.
void commonNormalSystem(const ConvexShape& a, const ConvexShape& b, const Eigen::Vector3d& u_a,
                        const Eigen::Vector3d& u_b, geometry::FrameMethod frame, double length, Vector6d& phi,
                        Matrix6d& jacobian);

/// The dual s(v) for a unit direction v (mm), with the support points.
double dualSeparation(const ConvexShape& a, const ConvexShape& b, const Eigen::Vector3d& v,
                      Eigen::Vector3d* u_a = nullptr, Eigen::Vector3d* u_b = nullptr);

}  // namespace articula::contact
