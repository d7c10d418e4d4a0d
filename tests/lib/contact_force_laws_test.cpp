// Contact force laws against closed forms: the Hertz elastic impact (peak
// depth, rebound, duration), the Hunt-Crossley and Lankarani-Nikravesh
// restitution from the exact first integral of a damped impact, the static
// Hertz depth a damped drop settles at, the friction coefficient's shape,
// Newton's third law of the loads, and a tangential force that stays
// continuous while the normal turns across every coordinate plane.
#include <cmath>
#include <functional>

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "articula/contact/force_laws.hpp"
#include "articula/core/error.hpp"

namespace {

using articula::contact::ContactState;
using articula::contact::FrictionLaw;
using articula::contact::NormalForceLaw;
using articula::contact::NormalLaw;
using Eigen::Vector3d;

struct Impact {
  double peak_depth = 0, rebound_speed = 0, duration = 0, final_depth = 0;
};

// A body of mass m dropped onto a rigid plane at speed v0 (and gravity g),
// the depth d >= 0 its penetration: m d'' = m g - F(d, d'), integrated by
// classical Runge-Kutta with step h until it leaves the plane or t_end.
Impact dropOnPlane(const NormalForceLaw& law, double m, double v0, double g, double h, double t_end) {
  double d = 0, v = v0, t = 0;
  Impact out;
  const auto a = [&](double depth, double rate) { return g - law.force(depth, rate) / m; };
  bool left = false;
  while (t < t_end) {
    const double k1d = v, k1v = a(d, v);
    const double k2d = v + 0.5 * h * k1v, k2v = a(d + 0.5 * h * k1d, v + 0.5 * h * k1v);
    const double k3d = v + 0.5 * h * k2v, k3v = a(d + 0.5 * h * k2d, v + 0.5 * h * k2v);
    const double k4d = v + h * k3v, k4v = a(d + h * k3d, v + h * k3v);
    const double d_next = d + h / 6 * (k1d + 2 * k2d + 2 * k3d + k4d);
    const double v_next = v + h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v);
    if (g == 0 && d_next < 0) {  // left the plane: interpolate the crossing linearly in d
      const double f = d / (d - d_next);
      out.duration = t + f * h;
      out.rebound_speed = -(v + f * (v_next - v));
      left = true;
      break;
    }
    d = d_next, v = v_next, t += h;
    out.peak_depth = std::max(out.peak_depth, d);
  }
  if (!left) out.final_depth = d;
  return out;
}

TEST(ForceLaws, HertzImpactMatchesItsClosedForm) {
  NormalForceLaw hertz;
  hertz.law = NormalLaw::Hertz;
  hertz.stiffness = 140e6;  // the thesis's PTFE ball, N/m^1.5
  const double m = 1.0, v0 = 0.5;
  const Impact impact = dropOnPlane(hertz, m, v0, 0.0, 1e-7, 1.0);
  // Energy: m v0^2 / 2 = K d^2.5 / 2.5 at the peak; duration 2.9432 d_max / v0 (Johnson, Contact Mechanics 11.2).
  const double peak = std::pow(5.0 * m * v0 * v0 / (4.0 * hertz.stiffness), 0.4);
  EXPECT_NEAR(impact.peak_depth, peak, 1e-6 * peak);
  EXPECT_NEAR(impact.rebound_speed, v0, 1e-6 * v0);
  EXPECT_NEAR(impact.duration, 2.9432 * peak / v0, 1e-4 * impact.duration);
}

TEST(ForceLaws, DampedImpactsReboundAsTheirFirstIntegralSays) {
  const double m = 1.0, v0 = 0.8;
  NormalForceLaw hc;
  hc.law = NormalLaw::HuntCrossley;
  hc.stiffness = 140e6;
  hc.dissipation = articula::contact::huntCrossleyDissipation(0.9, v0);  // (1 - e) / v0
  hc.validate();
  const Impact a = dropOnPlane(hc, m, v0, 0.0, 1e-7, 1.0);
  const double x = 1.5 * hc.dissipation * v0;
  EXPECT_NEAR(a.rebound_speed / v0, articula::contact::restitutionOfLinearDamping(x), 1e-6);
  // The peak depth from m (v0/a - ln(1 + a v0)/a^2) = K d^2.5 / 2.5, a = 3/2 c.
  const double damping = 1.5 * hc.dissipation;
  const double peak =
      std::pow(2.5 * m * (v0 / damping - std::log1p(damping * v0) / (damping * damping)) / hc.stiffness, 0.4);
  EXPECT_NEAR(a.peak_depth, peak, 1e-6 * peak);
  // The first-order relation c = (1 - e) / v0 is near the exact one for e = 0.9.
  EXPECT_NEAR(a.rebound_speed / v0, 0.9, 0.02);

  NormalForceLaw ln;
  ln.law = NormalLaw::LankaraniNikravesh;
  ln.stiffness = 140e6;
  ln.restitution = 0.9;
  ln.impact_speed = v0;
  ln.validate();
  const Impact b = dropOnPlane(ln, m, v0, 0.0, 1e-7, 1.0);
  const double exact = articula::contact::restitutionOfLinearDamping(0.75 * (1 - 0.81));
  EXPECT_NEAR(b.rebound_speed / v0, exact, 1e-6);
  // Lankarani-Nikravesh aim at e, exactly only as e -> 1: 0.913 for 0.9.
  EXPECT_NEAR(exact, 0.913, 0.001);
  // No damping, no loss.
  EXPECT_EQ(articula::contact::restitutionOfLinearDamping(0.0), 1.0);
}

TEST(ForceLaws, ADampedDropSettlesAtTheHertzDepth) {
  NormalForceLaw hc;
  hc.law = NormalLaw::HuntCrossley;
  hc.stiffness = 140e6;
  hc.dissipation = 2.0;
  const double m = 1.0, g = 9.81;
  const Impact rest = dropOnPlane(hc, m, 0.05, g, 2e-6, 3.0);
  const double depth = std::pow(m * g / hc.stiffness, 2.0 / 3.0);
  EXPECT_NEAR(rest.final_depth, depth, 1e-6 * depth);
}

TEST(ForceLaws, HertzStiffnessFromCurvatures) {
  // Steel ball of radius 10 mm on a steel plane: K = 4/3 E* sqrt(R).
  const double e_star = articula::contact::effectiveModulus(210e9, 0.3, 210e9, 0.3);
  EXPECT_NEAR(e_star, 210e9 / (2 * (1 - 0.09)), 1.0);
  EXPECT_NEAR(articula::contact::hertzStiffness(100.0, 100.0, e_star), 4.0 / 3.0 * e_star * std::sqrt(0.01), 1e-3);
  // A ball of 0.1 m in a bowl of 1 m: relative curvature 1/0.1 - 1/1 (conformal, stiffer).
  EXPECT_NEAR(articula::contact::hertzStiffness(9.0, 9.0, e_star), 4.0 / 3.0 * e_star * std::sqrt(1.0 / 9.0), 1e-3);
  EXPECT_THROW(articula::contact::hertzStiffness(9.0, -1.0, e_star), articula::InvalidParameter);
}

TEST(ForceLaws, FrictionCoefficientIsRegularisedCoulombWithAStribeckPeak) {
  FrictionLaw coulomb;
  coulomb.dynamic = 0.3;
  coulomb.transition_speed = 0.01;
  EXPECT_DOUBLE_EQ(coulomb.coefficient(0.0), 0.0);
  EXPECT_NEAR(coulomb.coefficient(0.005), 0.15, 1e-15);  // linear below the transition
  EXPECT_NEAR(coulomb.coefficient(0.01), 0.3, 1e-15);
  EXPECT_NEAR(coulomb.coefficient(10.0), 0.3, 1e-15);
  FrictionLaw stribeck = coulomb;
  stribeck.static_peak = 0.5;
  stribeck.viscous = 0.1;
  EXPECT_NEAR(stribeck.coefficient(0.01), 0.5 + 0.001, 1e-15);  // the peak at the transition
  EXPECT_NEAR(stribeck.coefficient(1.0), 0.3 + 2 * 0.2 / (1 + 1e4) + 0.1, 1e-15);
  EXPECT_LT(stribeck.coefficient(0.1), stribeck.coefficient(0.01));  // falls towards mu_d
}

TEST(ForceLaws, FrictionOpposesSlipAndLoadsBalance) {
  NormalForceLaw law;
  law.law = NormalLaw::Hertz;
  law.stiffness = 1e6;
  FrictionLaw friction;
  friction.dynamic = 0.4;
  friction.transition_speed = 1e-4;
  ContactState s;
  s.normal = Vector3d(0.3, -0.2, 0.9).normalized();
  s.point_a = Vector3d(1, 2, 3);
  s.point_b = s.point_a - 1e-3 * s.normal;
  s.depth = 1e-3;
  s.velocity_a = Vector3d(0.1, 0, 0);
  s.velocity_b = Vector3d(-0.2, 0.3, 0.05);
  const articula::contact::ContactForce f = articula::contact::contactForce(s, law, friction);
  const Vector3d relative = s.velocity_b - s.velocity_a;
  const Vector3d slip = relative - relative.dot(s.normal) * s.normal;
  const Vector3d tangential = f.on_b - f.on_b.dot(s.normal) * s.normal;
  EXPECT_NEAR(f.on_b.dot(s.normal), law.stiffness * std::pow(1e-3, 1.5), 1e-9);
  EXPECT_NEAR(tangential.norm(), 0.4 * f.normal, 1e-12);
  EXPECT_NEAR(tangential.normalized().dot(-slip.normalized()), 1.0, 1e-14);
  EXPECT_NEAR(f.slip_tb.norm(), slip.norm(), 1e-15);
  const Vector3d origin_a(0, 0, 0), origin_b(1, 1, 1);
  const auto [on_a, on_b] = articula::contact::bodyLoads(f, origin_a, origin_b);
  EXPECT_LT((on_a.force + on_b.force).norm(), 1e-15);
  // Moments about one point add up to zero (one force line).
  const Vector3d moment_b_about_a = on_b.moment + (origin_b - origin_a).cross(on_b.force);
  EXPECT_LT((on_a.moment + moment_b_about_a).norm(), 1e-12);
  EXPECT_LT((on_b.moment - (f.point - origin_b).cross(f.on_b)).norm(), 1e-15);
  // Apart: no force at all.
  s.depth = -1e-4;
  EXPECT_EQ(articula::contact::contactForce(s, law, friction).on_b, Vector3d::Zero());
}

// The friction components are taken in the Householder frame, which flips
// where the normal crosses the plane n_x = 0; the force itself must not
// notice that or any other plane: it equals, at every step of normals
// turning about four axes, the frame-free Coulomb force N n - mu N s/|s|,
// which is continuous wherever the slip s is not zero.
TEST(ForceLaws, TangentialForceIsContinuousAsTheNormalCrossesAnyPlane) {
  NormalForceLaw law;
  law.law = NormalLaw::Hertz;
  law.stiffness = 1e6;
  FrictionLaw friction;
  friction.dynamic = 0.5;
  friction.transition_speed = 1e-3;
  ContactState s;
  s.depth = 1e-3;
  s.velocity_b = Vector3d(0.3, -0.4, 0.5);
  const int steps = 20000;
  double largest_component_jump = 0;
  for (const Vector3d& axis : {Vector3d(0, 0, 1), Vector3d(0, 1, 0), Vector3d(1, 0, 0), Vector3d(1, 1, 1).normalized()}) {
    const Vector3d u = axis.unitOrthogonal(), w = axis.cross(u);
    Eigen::Vector2d previous_components = Eigen::Vector2d::Zero();
    double worst = 0;
    for (int i = 0; i <= steps; ++i) {
      const double angle = 2 * M_PI * i / steps;
      s.normal = std::cos(angle) * u + std::sin(angle) * w;
      const articula::contact::ContactForce f = articula::contact::contactForce(s, law, friction);
      const double normal = law.force(s.depth, 0);
      const Vector3d slip = s.velocity_b - s.velocity_b.dot(s.normal) * s.normal;
      const Vector3d frame_free = normal * s.normal - friction.coefficient(slip.norm()) * normal * slip.normalized();
      worst = std::max(worst, (f.on_b - frame_free).norm());
      if (i > 0) largest_component_jump = std::max(largest_component_jump, (f.friction_tb - previous_components).norm());
      previous_components = f.friction_tb;
    }
    EXPECT_LT(worst, 1e-12) << "normal turning about " << axis.transpose();
  }
  // The frame did flip on the way (so the sweep crossed its switching plane).
  EXPECT_GT(largest_component_jump, 1.0);
}

TEST(ForceLaws, OutOfRangeParametersAreRefused) {
  NormalForceLaw law;
  law.stiffness = -1;
  EXPECT_THROW(law.validate(), articula::InvalidParameter);
  law.stiffness = 1;
  law.law = NormalLaw::LankaraniNikravesh;
  law.restitution = 0.9;
  EXPECT_THROW(law.validate(), articula::InvalidParameter);  // no impact speed
  FrictionLaw friction;
  friction.transition_speed = 0;
  EXPECT_THROW(friction.validate(), articula::InvalidParameter);
}

}  // namespace
