#include "articula/contact/force_laws.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include <Eigen/Geometry>

#include "articula/core/error.hpp"
#include "articula/geometry/frames.hpp"

namespace articula::contact {
namespace {

void require(bool ok, const char* parameter, const char* expected, double found) {
  if (!ok) throw InvalidParameter(parameter, expected, found);
}

}  // namespace

void NormalForceLaw::validate() const {
  require(std::isfinite(stiffness) && stiffness > 0, "contact stiffness", "> 0", stiffness);
  require(std::isfinite(exponent) && exponent >= 1 && exponent <= 3, "contact force exponent", "1 to 3", exponent);
  switch (law) {
    case NormalLaw::Hertz: break;
    case NormalLaw::HuntCrossley:
      require(std::isfinite(dissipation) && dissipation >= 0, "Hunt-Crossley dissipation", ">= 0", dissipation);
      break;
    case NormalLaw::LankaraniNikravesh:
      require(restitution > 0 && restitution <= 1, "Lankarani-Nikravesh restitution", "(0, 1]", restitution);
      require(std::isfinite(impact_speed) && impact_speed > 0, "Lankarani-Nikravesh impact speed", "> 0", impact_speed);
      break;
  }
}

double NormalForceLaw::force(double depth, double depth_rate) const {
  if (!(depth > 0)) return 0.0;
  const double elastic = stiffness * std::pow(depth, exponent);
  double damping = 0.0;
  if (law == NormalLaw::HuntCrossley) damping = 1.5 * dissipation * depth_rate;
  if (law == NormalLaw::LankaraniNikravesh)
    damping = 0.75 * (1.0 - restitution * restitution) * depth_rate / impact_speed;
  return std::max(0.0, elastic * (1.0 + damping));
}

double huntCrossleyDissipation(double restitution, double impact_speed) {
  require(restitution > 0 && restitution <= 1, "restitution", "(0, 1]", restitution);
  require(std::isfinite(impact_speed) && impact_speed > 0, "impact speed", "> 0", impact_speed);
  return (1.0 - restitution) / impact_speed;
}

double restitutionOfLinearDamping(double x) {
  require(std::isfinite(x) && x >= 0, "damping times impact speed", ">= 0", x);
  if (x == 0) return 1.0;
  // g(e) = x (1 + e) - ln((1 + x) / (1 - x e)) is positive at e = 0 and
  // falls to -inf at e = 1/x (or is negative at e = 1): bisection, 200
  // halvings reach the double resolution of any root in (0, 1].
  const auto g = [x](double e) { return x * (1.0 + e) - std::log1p(x) + std::log1p(-x * e); };
  double lo = 0.0, hi = std::min(1.0, 1.0 / x);
  if (g(hi) >= 0) return hi;
  for (int i = 0; i < 200 && hi - lo > 1e-16; ++i) {
    const double mid = 0.5 * (lo + hi);
    (g(mid) > 0 ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

double effectiveModulus(double e1, double nu1, double e2, double nu2) {
  require(e1 > 0 && std::isfinite(e1), "Young's modulus of body 1", "> 0", e1);
  require(e2 > 0 && std::isfinite(e2), "Young's modulus of body 2", "> 0", e2);
  require(nu1 > -1 && nu1 < 0.5, "Poisson's ratio of body 1", "(-1, 0.5)", nu1);
  require(nu2 > -1 && nu2 < 0.5, "Poisson's ratio of body 2", "(-1, 0.5)", nu2);
  return 1.0 / ((1.0 - nu1 * nu1) / e1 + (1.0 - nu2 * nu2) / e2);
}

double hertzStiffness(double k1, double k2, double effective_modulus) {
  require(k1 > 0 && std::isfinite(k1), "first relative curvature", "> 0 (surfaces that curve apart)", k1);
  require(k2 > 0 && std::isfinite(k2), "second relative curvature", "> 0 (surfaces that curve apart)", k2);
  require(effective_modulus > 0 && std::isfinite(effective_modulus), "effective modulus", "> 0", effective_modulus);
  return 4.0 / 3.0 * effective_modulus * std::sqrt(1.0 / std::sqrt(k1 * k2));
}

void FrictionLaw::validate() const {
  require(std::isfinite(dynamic) && dynamic >= 0, "dynamic friction", ">= 0", dynamic);
  require(std::isfinite(static_peak), "static friction", "a number (< 0: the dynamic one)", static_peak);
  require(std::isfinite(viscous) && viscous >= 0, "viscous friction", ">= 0", viscous);
  require(std::isfinite(transition_speed) && transition_speed > 0, "friction transition speed", "> 0", transition_speed);
}

double FrictionLaw::coefficient(double v) const {
  const double mu_s = static_peak < 0 ? dynamic : static_peak;
  const double r = v / transition_speed;
  return std::min(r, 1.0) * (dynamic + 2.0 * (mu_s - dynamic) / (1.0 + r * r)) + viscous * v;
}

ContactForce contactForce(const ContactState& s, const NormalForceLaw& normal_law, const FrictionLaw& friction) {
  ContactForce f;
  f.point = 0.5 * (s.point_a + s.point_b);
  f.depth = s.depth;
  const Eigen::Vector3d relative = s.velocity_b - s.velocity_a;  // of B on A
  f.depth_rate = -relative.dot(s.normal);  // B moving against the normal: approaching
  // Friction in the Householder frame of the normal: continuous as the
  // normal turns (thesis ch. 4), so the reported components are too.
  const geometry::TangentFrame frame = geometry::householderFrameUnit(s.normal);
  f.slip_tb = Eigen::Vector2d(relative.dot(frame.t), relative.dot(frame.b));
  if (!(s.depth > 0)) return f;
  f.normal = normal_law.force(s.depth, f.depth_rate);
  const double slip = f.slip_tb.norm();
  if (slip > 0 && f.normal > 0) f.friction_tb = -f.normal * friction.coefficient(slip) / slip * f.slip_tb;
  f.on_b = f.normal * s.normal + f.friction_tb.x() * frame.t + f.friction_tb.y() * frame.b;
  return f;
}

std::pair<BodyLoad, BodyLoad> bodyLoads(const ContactForce& contact, const Eigen::Vector3d& reference_a,
                                        const Eigen::Vector3d& reference_b) {
  BodyLoad a, b;
  b.force = contact.on_b;
  a.force = -contact.on_b;
  b.moment = (contact.point - reference_b).cross(b.force);
  a.moment = (contact.point - reference_a).cross(a.force);
  return {a, b};
}

}  // namespace articula::contact
