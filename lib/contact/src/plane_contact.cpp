#include "articula/contact/plane_contact.hpp"

#include <cmath>

#include "articula/core/error.hpp"
#include "articula/geometry/power.hpp"

namespace articula::contact {

using Eigen::Vector3d;

double pointPlaneDistance(const Vector3d& point, const Vector3d& plane_point, const Vector3d& plane_normal) {
  return plane_normal.dot(point - plane_point) / plane_normal.norm();
}

namespace {

Vector3d unitPlaneNormal(const Vector3d& n) {
  const double len = n.norm();
  if (!std::isfinite(len) || !(len > 0.0)) throw InvalidParameter("plane normal", "a non-zero finite vector", len);
  return n / len;
}

// The better of the two candidates x+ and x- = 2c - x+ (central symmetry).
ContactResult pickCandidate(const Vector3d& center, const Vector3d& x_plus, const Vector3d& u_plus,
                            const Vector3d& plane_point, const Vector3d& n) {
  const Vector3d x_minus = 2.0 * center - x_plus;
  const double d_plus = n.dot(x_plus - plane_point), d_minus = n.dot(x_minus - plane_point);
  const bool plus = d_plus <= d_minus;
  ContactResult r;
  r.distance = plus ? d_plus : d_minus;
  r.point_a = plus ? x_plus : x_minus;
  r.point_b = r.point_a - r.distance * n;
  r.normal = -n;
  r.canonical_a = plus ? u_plus : Vector3d(-u_plus);
  r.canonical_b = r.point_b;
  r.summary.status = ContactStatus::Converged;
  r.summary.termination = "closed form";
  r.summary.certified = r.distance > 0.0;
  return r;
}

}  // namespace

ContactResult shapePlaneContact(const ConvexShape& shape, const Vector3d& plane_point, const Vector3d& plane_normal) {
  const Vector3d n = unitPlaneNormal(plane_normal);
  // Candidate with outward normal -n (facing the plane); its mirror faces away.
  // (The support mapping takes any length: the normalisation stays off its path.)
  const Vector3d u = supportCanonical(shape, -plane_normal);
  return pickCandidate(shape.center, toGlobal(shape, u), u, plane_point, n);
}

ContactResult barrPlaneContact(const Vector3d& center, const Eigen::Matrix3d& rotation, const Vector3d& radii,
                               double epsilon1, double epsilon2, const Vector3d& plane_point,
                               const Vector3d& plane_normal) {
  for (auto [name, e] : {std::pair{"epsilon1", epsilon1}, std::pair{"epsilon2", epsilon2}})
    if (!std::isfinite(e) || !(e > 0.0) || e > 1.0) throw InvalidParameter(name, "a value in (0, 1]", e);
  const ConvexShape frame = makeConvexShape(center, rotation, radii);  // validates the pose and radii
  const Vector3d n = unitPlaneNormal(plane_normal);
  // Eq. 5.11: the direction the candidate's normal must have, in local axes.
  const Vector3d m = -(rotation.transpose() * n);
  const double a = radii[0], b = radii[1], c = radii[2];
  // Eq. 5.13: tan(eta)^(2 - e1) = b m_y / (a m_x), quadrant from the signs.
  const double p1 = 1.0 / (2.0 - epsilon1), p2 = 1.0 / (2.0 - epsilon2);
  const double eta = std::atan2(geometry::signedPower(b * m.y(), p1), geometry::signedPower(a * m.x(), p1));
  // Eq. 5.14: tan(omega)^(2 - e2) = c m_z cos(eta)^(2 - e1) / (a m_x), or with
  // sin(eta) and b m_y; cos(omega) >= 0, the sign of omega is that of m_z.
  const bool use_x = std::fabs(a * m.x()) > std::fabs(b * m.y());
  const double trig = use_x ? std::fabs(std::cos(eta)) : std::fabs(std::sin(eta));
  const double lateral = use_x ? std::fabs(a * m.x()) : std::fabs(b * m.y());
  const double omega = lateral == 0.0 ? std::copysign(M_PI / 2.0, m.z())  // the pole (0, 0, +-c): 0/0 in eq. 5.14
                                      : std::atan2(geometry::signedPower(c * m.z(), p2) * std::pow(trig, (2.0 - epsilon1) * p2),
                                                   std::pow(lateral, p2));
  // Eq. 2.16.
  const double ce = geometry::signedPower(std::cos(omega), epsilon2);
  const Vector3d u(geometry::signedPower(std::cos(eta), epsilon1) * ce,
                   geometry::signedPower(std::sin(eta), epsilon1) * ce, geometry::signedPower(std::sin(omega), epsilon2));
  return pickCandidate(center, toGlobal(frame, u), u, plane_point, n);
}

}  // namespace articula::contact
