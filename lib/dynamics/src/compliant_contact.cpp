#include "articula/dynamics/compliant_contact.hpp"

#include <cmath>
#include <vector>

#include "articula/contact/plane_contact.hpp"
#include "articula/core/error.hpp"

namespace articula::dynamics {
namespace {

Eigen::Vector3d toEigen(const SimTK::Vec3& v) { return {v[0], v[1], v[2]}; }
SimTK::Vec3 toSimTK(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

Eigen::Matrix3d toEigen(const SimTK::Rotation& r) {
  Eigen::Matrix3d m;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) m(i, j) = r[i][j];
  return m;
}

enum class PairKind { ShapeOnPlane, SphereInCavity };

struct Pair {
  PairKind kind;
  SimTK::MobilizedBodyIndex body;
  contact::ConvexShape shape;                  // ShapeOnPlane: in the body's frame
  double radius = 0, cavity_radius = 0;        // SphereInCavity
  Eigen::Vector3d point = Eigen::Vector3d::Zero(), normal = Eigen::Vector3d::UnitZ();  // plane, or cavity centre
  ContactLaws laws;
};

}  // namespace

class CompliantContact::Element : public SimTK::Force::Custom::Implementation {
 public:
  explicit Element(const SimTK::SimbodyMatterSubsystem& matter) : matter_(matter) {}

  std::vector<Pair> pairs;
  mutable ContactCounters counters;

  // The contact of pair p at `state`: A is the moving body, B the ground.
  contact::ContactState stateOf(const Pair& p, const SimTK::State& state, SimTK::Vec3& station) const {
    const SimTK::MobilizedBody& body = matter_.getMobilizedBody(p.body);
    const SimTK::Transform& X_GB = body.getBodyTransform(state);
    contact::ContactState s;
    if (p.kind == PairKind::ShapeOnPlane) {
      contact::ConvexShape world = p.shape;
      world.center = toEigen(X_GB * toSimTK(p.shape.center));
      world.rotation = toEigen(X_GB.R()) * p.shape.rotation;
      const contact::ContactResult r = contact::shapePlaneContact(world, p.point, p.normal);
      s.point_a = r.point_a;
      s.point_b = r.point_b;
      s.normal = r.normal;  // outward of the shape: towards the plane's solid
      s.depth = -r.distance;
    } else {
      const Eigen::Vector3d center = toEigen(X_GB.p());
      Eigen::Vector3d u = center - p.point;
      const double offset = u.norm();
      // At the cavity's centre every direction is as near: take any (no contact there unless r >= R).
      u = offset > 0 ? Eigen::Vector3d(u / offset) : Eigen::Vector3d::UnitZ();
      s.point_a = center + p.radius * u;
      s.point_b = p.point + p.cavity_radius * u;
      s.normal = u;
      s.depth = offset + p.radius - p.cavity_radius;
    }
    const Eigen::Vector3d at = 0.5 * (s.point_a + s.point_b);
    station = X_GB.shiftBaseStationToFrame(toSimTK(at));
    s.velocity_a = toEigen(body.findStationVelocityInGround(state, station));
    return s;
  }

  void calcForce(const SimTK::State& state, SimTK::Vector_<SimTK::SpatialVec>& body_forces, SimTK::Vector_<SimTK::Vec3>&,
                 SimTK::Vector&) const override {
    for (const Pair& p : pairs) {
      SimTK::Vec3 station;
      const contact::ContactState s = stateOf(p, state, station);
      ++counters.evaluations;
      if (!(s.depth > 0)) continue;
      ++counters.in_contact;
      const contact::ContactForce f = contact::contactForce(s, p.laws.normal, p.laws.friction);
      matter_.getMobilizedBody(p.body).applyForceToBodyPoint(state, station, toSimTK(-f.on_b), body_forces);
    }
  }

  // The elastic energy stored in the contacts: K d^(n+1) / (n+1) per pair.
  SimTK::Real calcPotentialEnergy(const SimTK::State& state) const override {
    double energy = 0;
    for (const Pair& p : pairs) {
      SimTK::Vec3 station;
      const contact::ContactState s = stateOf(p, state, station);
      if (s.depth > 0)
        energy += p.laws.normal.stiffness * std::pow(s.depth, p.laws.normal.exponent + 1) / (p.laws.normal.exponent + 1);
    }
    return energy;
  }

  bool dependsOnlyOnPositions() const override { return false; }

  const SimTK::SimbodyMatterSubsystem& matter_;
};

CompliantContact::CompliantContact(SimTK::GeneralForceSubsystem& forces) {
  const SimTK::MultibodySystem& system = forces.getMultibodySystem();
  element_ = new Element(system.getMatterSubsystem());
  SimTK::Force::Custom(forces, element_);  // the subsystem owns the element from here
}

CompliantContact::~CompliantContact() = default;

void CompliantContact::addShapeOnPlane(const SimTK::MobilizedBody& body, const contact::ConvexShape& shape,
                                       const Eigen::Vector3d& plane_point, const Eigen::Vector3d& plane_normal,
                                       const ContactLaws& laws) {
  laws.normal.validate();
  laws.friction.validate();
  if (!(plane_normal.allFinite() && plane_normal.norm() > 0 && plane_point.allFinite()))
    throw InvalidParameter("contact plane normal", "a finite non-zero vector", plane_normal.norm());
  Pair p{PairKind::ShapeOnPlane, body.getMobilizedBodyIndex(), shape, 0, 0, plane_point, plane_normal.normalized(), laws};
  element_->pairs.push_back(p);
}

void CompliantContact::addSphereInCavity(const SimTK::MobilizedBody& body, double radius,
                                         const Eigen::Vector3d& cavity_center, double cavity_radius,
                                         const ContactLaws& laws) {
  laws.normal.validate();
  laws.friction.validate();
  if (!(radius > 0 && std::isfinite(radius))) throw InvalidParameter("ball radius", "> 0", radius);
  if (!(cavity_radius > radius && std::isfinite(cavity_radius)))
    throw InvalidParameter("cavity radius", "larger than the ball's", cavity_radius);
  Pair p{PairKind::SphereInCavity, body.getMobilizedBodyIndex(), {}, radius, cavity_radius, cavity_center,
         Eigen::Vector3d::UnitZ(), laws};
  element_->pairs.push_back(p);
}

const ContactCounters& CompliantContact::counters() const { return element_->counters; }

std::vector<contact::ContactForce> CompliantContact::forces(const SimTK::State& state) const {
  std::vector<contact::ContactForce> out;
  for (const Pair& p : element_->pairs) {
    SimTK::Vec3 station;
    const contact::ContactState s = element_->stateOf(p, state, station);
    out.push_back(contact::contactForce(s, p.laws.normal, p.laws.friction));
  }
  return out;
}

}  // namespace articula::dynamics
