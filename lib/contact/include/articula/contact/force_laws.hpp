#pragma once
// Compliant contact force laws, in plain Eigen (no engine types), for any
// multibody or DEM code: the normal force from the penetration depth and its
// rate (Hertz, Hunt-Crossley, Lankarani-Nikravesh), regularised Coulomb
// friction with an optional Stribeck peak and viscous part, resolved in the
// contact's Householder tangent frame (thesis ch. 4), and the force and
// moment each body receives. Units are the caller's, consistently (SI in the
// dynamics: m, kg, s, N).
#include <utility>

#include <Eigen/Core>

namespace articula::contact {

enum class NormalLaw {
  Hertz,               // F = K d^n (elastic)
  HuntCrossley,        // F = K d^n (1 + 3/2 c d')  (Hunt & Crossley 1975, in Simbody's form)
  LankaraniNikravesh,  // F = K d^n (1 + 3 (1 - e^2) / 4 d' / v0)  (Lankarani & Nikravesh 1990)
};

struct NormalForceLaw {
  NormalLaw law = NormalLaw::HuntCrossley;
  double stiffness = 0;     // K, force / length^exponent
  double exponent = 1.5;    // n: 1.5 for Hertzian point contact, 1 for a linear spring
  double dissipation = 0;   // Hunt-Crossley c (time / length); see huntCrossleyDissipation
  double restitution = 1;   // Lankarani-Nikravesh nominal e, in (0, 1] (a free impact rebounds faster when e < ~0.9)
  double impact_speed = 0;  // Lankarani-Nikravesh v0 > 0: the approach speed when the contact began
  /// Throws InvalidParameter naming the first value out of its range.
  void validate() const;
  /// The normal force, >= 0 (no adhesion: a damping term that would pull is
  /// cut at zero); 0 when depth <= 0. depth_rate > 0 while approaching.
  double force(double depth, double depth_rate) const;
};

/// Hunt-Crossley dissipation c = (1 - e) / v0 for restitution e at impact
/// speed v0 (the first-order relation; restitutionOfHuntCrossley gives the
/// exact one).
double huntCrossleyDissipation(double restitution, double impact_speed);

/// The exact coefficient of restitution of a free impact under F = K d^n
/// (1 + a d') for a = 3/2 c (Hunt-Crossley) at impact speed v0: the root e in
/// (0, 1] of a v0 (1 + e) = ln((1 + a v0) / (1 - a v0 e)), from integrating
/// m v dv / dd = -K d^n (1 + a v) over the impact (independent of m, K, n).
double restitutionOfLinearDamping(double a_times_v0);

/// Effective modulus of two elastic bodies: 1 / E* = (1 - nu1^2) / E1 + (1 - nu2^2) / E2.
double effectiveModulus(double e1, double nu1, double e2, double nu2);

/// Hertz stiffness K = 4/3 E* sqrt(R) (F = K d^1.5) from the relative
/// principal curvatures k1, k2 of the two surfaces at the contact (the sums
/// of both bodies' curvatures along the principal directions, concave
/// negative: a ball of radius r in a bowl of radius R gives 1/r - 1/R), with
/// R = 1 / sqrt(k1 k2) (Greenwood's equivalent radius; exact for circular
/// contact, within a few per cent of the elliptical solution for k1/k2 up to
/// 5). Throws InvalidParameter unless k1, k2 > 0 (the surfaces must curve
/// apart).
double hertzStiffness(double k1, double k2, double effective_modulus);

struct FrictionLaw {
  double dynamic = 0;          // mu_d: Coulomb coefficient while sliding
  double static_peak = -1;     // mu_s: the Stribeck peak at the transition speed (< 0: equal to mu_d, plain Coulomb)
  double viscous = 0;          // mu_v: extra coefficient per unit slip speed
  double transition_speed = 1e-3;  // v_t: below it friction grows linearly with slip speed (regularised Coulomb)
  void validate() const;
  /// The friction coefficient at slip speed v >= 0 (Simbody's HuntCrossleyForce form):
  /// mu(v) = min(v / v_t, 1) (mu_d + 2 (mu_s - mu_d) / (1 + (v / v_t)^2)) + mu_v v.
  double coefficient(double slip_speed) const;
};

/// One contact as the geometry and the bodies' motion give it (world frame).
struct ContactState {
  Eigen::Vector3d point_a = Eigen::Vector3d::Zero();  // deepest point of A inside B (or closest, when apart)
  Eigen::Vector3d point_b = Eigen::Vector3d::Zero();  // deepest point of B inside A
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // unit, from A towards B: B is pushed along it
  double depth = 0;                                   // penetration, > 0 in contact
  Eigen::Vector3d velocity_a = Eigen::Vector3d::Zero();  // of A's material point at the contact
  Eigen::Vector3d velocity_b = Eigen::Vector3d::Zero();  // of B's material point at the contact
};

struct ContactForce {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();     // where it acts: midway between the two points
  Eigen::Vector3d on_b = Eigen::Vector3d::Zero();      // total force on B (A receives -on_b)
  double normal = 0;                                   // normal force, >= 0
  Eigen::Vector2d friction_tb = Eigen::Vector2d::Zero();  // friction on B in the Householder frame (t, b) of the normal
  Eigen::Vector2d slip_tb = Eigen::Vector2d::Zero();      // slip velocity of B relative to A in that frame
  double depth = 0;                                    // penetration, > 0 in contact
  double depth_rate = 0;                               // d' > 0 while approaching
};

/// The contact's force: normal law on depth and depth rate, friction
/// opposing the slip of B on A in the tangent plane, zero when apart.
ContactForce contactForce(const ContactState& state, const NormalForceLaw& normal_law, const FrictionLaw& friction);

struct BodyLoad {
  Eigen::Vector3d force = Eigen::Vector3d::Zero();
  Eigen::Vector3d moment = Eigen::Vector3d::Zero();  // about the reference point given
};

/// The force and moment on A (about reference_a) and on B (about reference_b).
std::pair<BodyLoad, BodyLoad> bodyLoads(const ContactForce& contact, const Eigen::Vector3d& reference_a,
                                        const Eigen::Vector3d& reference_b);

}  // namespace articula::contact
