#include "articula/dynamics/compliant_contact.hpp"

#include <cmath>
#include <optional>
#include <vector>

#include "articula/contact/common_normal.hpp"
#include "articula/contact/plane_contact.hpp"
#include "articula/core/error.hpp"
#include "articula/distance/ellipsoid_distance.hpp"

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

enum class PairKind { ShapeOnPlane, PointOnPlane, SphereInCavity, SphereInEllipsoid, ShapePair };

struct Pair {
  PairKind kind = PairKind::ShapeOnPlane;
  SimTK::MobilizedBodyIndex body;
  contact::ConvexShape shape;                  // ShapeOnPlane, ShapePair (A): in the body's frame; SphereInEllipsoid: the cavity, in ground
  double radius = 0, cavity_radius = 0;        // SphereInCavity
  Eigen::Vector3d station = Eigen::Vector3d::Zero();  // PointOnPlane: in the body's frame
  Eigen::Vector3d point = Eigen::Vector3d::Zero(), normal = Eigen::Vector3d::UnitZ();  // plane, or cavity centre
  ContactLaws laws;
  SimTK::MobilizedBodyIndex body_b;            // ShapePair: B and its shape in its frame
  contact::ConvexShape shape_b;
  // The pair's last answer: the next evaluation's warm start. Simbody also
  // evaluates trial states (rejected steps, Runge-Kutta stages); any nearby
  // answer is a good start, and the solver's certificates keep the result
  // the global one.
  mutable std::optional<contact::ContactResult> last;
};

contact::ConvexShape inGround(const contact::ConvexShape& shape, const SimTK::Transform& X_GB) {
  contact::ConvexShape world = shape;
  world.center = toEigen(X_GB * toSimTK(shape.center));
  world.rotation = toEigen(X_GB.R()) * shape.rotation;
  return world;
}

}  // namespace

class CompliantContact::Element : public SimTK::Force::Custom::Implementation {
 public:
  explicit Element(const SimTK::SimbodyMatterSubsystem& matter) : matter_(matter) {}

  std::vector<Pair> pairs;
  mutable ContactCounters counters;

  // A pair's contact and where its force acts, in each body's frame.
  struct Evaluated {
    contact::ContactState state;
    SimTK::Vec3 station, station_b;  // station_b: shape pairs only
  };

  // The contact of pair p at `state`: A is the moving body, B the ground or,
  // for a shape pair, the other body.
  Evaluated evaluate(const Pair& p, const SimTK::State& state) const {
    Evaluated e;
    contact::ContactState& s = e.state;
    const SimTK::MobilizedBody& body = matter_.getMobilizedBody(p.body);
    const SimTK::Transform& X_GB = body.getBodyTransform(state);
    if (p.kind == PairKind::ShapePair) {
      const SimTK::Transform& X_GB2 = matter_.getMobilizedBody(p.body_b).getBodyTransform(state);
      const contact::ContactResult r = contact::computeContact(inGround(p.shape, X_GB), inGround(p.shape_b, X_GB2), {},
                                                               p.last ? &*p.last : nullptr);
      p.last = r;
      s.point_a = r.point_a;
      s.point_b = r.point_b;
      s.normal = r.normal;  // outward of A at its point: towards B
      s.depth = -r.distance;
    } else if (p.kind == PairKind::ShapeOnPlane) {
      const contact::ContactResult r = contact::shapePlaneContact(inGround(p.shape, X_GB), p.point, p.normal);
      s.point_a = r.point_a;
      s.point_b = r.point_b;
      s.normal = r.normal;  // outward of the shape: towards the plane's solid
      s.depth = -r.distance;
    } else if (p.kind == PairKind::PointOnPlane) {
      s.point_a = toEigen(X_GB * toSimTK(p.station));
      s.depth = p.normal.dot(p.point - s.point_a);
      s.point_b = s.point_a + s.depth * p.normal;
      s.normal = -p.normal;  // into the plane's solid, as for a shape
    } else if (p.kind == PairKind::SphereInEllipsoid) {
      const Eigen::Vector3d center = toEigen(X_GB.p());
      const Eigen::Vector3d local = p.shape.rotation.transpose() * (center - p.shape.center);
      Eigen::Vector3d closest;
      const double signed_distance = distance::ellipsoidClosestPoint(p.shape.radii, local, closest);
      // Outward of the cavity at its closest point: from the centre to it
      // inside; at the cavity's own centre along its shortest axis (any
      // nearest point will do: no contact there unless r >= a_min).
      Eigen::Vector3d n = closest - local;
      if (signed_distance > 0) n = -n;
      if (!(n.norm() > 0)) {
        Eigen::Index shortest = 0;
        p.shape.radii.minCoeff(&shortest);
        n = Eigen::Vector3d::Unit(shortest);
      }
      const Eigen::Vector3d u = p.shape.rotation * n.normalized();
      s.point_a = center + p.radius * u;
      s.point_b = p.shape.center + p.shape.rotation * closest;
      s.normal = u;
      s.depth = p.radius + signed_distance;
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
    e.station = X_GB.shiftBaseStationToFrame(toSimTK(at));
    s.velocity_a = toEigen(body.findStationVelocityInGround(state, e.station));
    if (p.kind == PairKind::ShapePair) {
      const SimTK::MobilizedBody& b = matter_.getMobilizedBody(p.body_b);
      e.station_b = b.getBodyTransform(state).shiftBaseStationToFrame(toSimTK(at));
      s.velocity_b = toEigen(b.findStationVelocityInGround(state, e.station_b));
    }
    return e;
  }

  void calcForce(const SimTK::State& state, SimTK::Vector_<SimTK::SpatialVec>& body_forces, SimTK::Vector_<SimTK::Vec3>&,
                 SimTK::Vector&) const override {
    for (const Pair& p : pairs) {
      counters.warm_starts += p.kind == PairKind::ShapePair && p.last;
      const Evaluated e = evaluate(p, state);
      ++counters.evaluations;
      if (!(e.state.depth > 0)) continue;
      ++counters.in_contact;
      const contact::ContactForce f = contact::contactForce(e.state, p.laws.normal, p.laws.friction);
      matter_.getMobilizedBody(p.body).applyForceToBodyPoint(state, e.station, toSimTK(-f.on_b), body_forces);
      if (p.kind == PairKind::ShapePair)
        matter_.getMobilizedBody(p.body_b).applyForceToBodyPoint(state, e.station_b, toSimTK(f.on_b), body_forces);
    }
  }

  // The elastic energy stored in the contacts: K d^(n+1) / (n+1) per pair.
  SimTK::Real calcPotentialEnergy(const SimTK::State& state) const override {
    double energy = 0;
    for (const Pair& p : pairs) {
      const double depth = evaluate(p, state).state.depth;
      if (depth > 0) energy += p.laws.normal.stiffness * std::pow(depth, p.laws.normal.exponent + 1) / (p.laws.normal.exponent + 1);
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

namespace {

// A pair of `kind` on `body` with checked laws; the caller fills in its geometry.
Pair newPair(PairKind kind, const SimTK::MobilizedBody& body, const ContactLaws& laws) {
  laws.normal.validate();
  laws.friction.validate();
  Pair p;
  p.kind = kind;
  p.body = body.getMobilizedBodyIndex();
  p.laws = laws;
  return p;
}

// A pair against the plane through `point` with outward `normal` (ground).
Pair newPlanePair(PairKind kind, const SimTK::MobilizedBody& body, const Eigen::Vector3d& point,
                  const Eigen::Vector3d& normal, const ContactLaws& laws) {
  if (!(normal.allFinite() && normal.norm() > 0 && point.allFinite()))
    throw InvalidParameter("contact plane normal", "a finite non-zero vector", normal.norm());
  Pair p = newPair(kind, body, laws);
  p.point = point;
  p.normal = normal.normalized();
  return p;
}

}  // namespace

void CompliantContact::addShapeOnPlane(const SimTK::MobilizedBody& body, const contact::ConvexShape& shape,
                                       const Eigen::Vector3d& plane_point, const Eigen::Vector3d& plane_normal,
                                       const ContactLaws& laws) {
  Pair p = newPlanePair(PairKind::ShapeOnPlane, body, plane_point, plane_normal, laws);
  p.shape = shape;
  element_->pairs.push_back(p);
}

void CompliantContact::addPointOnPlane(const SimTK::MobilizedBody& body, const Eigen::Vector3d& station,
                                       const Eigen::Vector3d& plane_point, const Eigen::Vector3d& plane_normal,
                                       const ContactLaws& laws) {
  if (!station.allFinite()) throw InvalidParameter("contact point", "finite coordinates", station.norm());
  Pair p = newPlanePair(PairKind::PointOnPlane, body, plane_point, plane_normal, laws);
  p.station = station;
  element_->pairs.push_back(p);
}

void CompliantContact::addSphereInCavity(const SimTK::MobilizedBody& body, double radius,
                                         const Eigen::Vector3d& cavity_center, double cavity_radius,
                                         const ContactLaws& laws) {
  if (!(radius > 0 && std::isfinite(radius))) throw InvalidParameter("ball radius", "> 0", radius);
  if (!(cavity_radius > radius && std::isfinite(cavity_radius)))
    throw InvalidParameter("cavity radius", "larger than the ball's", cavity_radius);
  Pair p = newPair(PairKind::SphereInCavity, body, laws);
  p.radius = radius;
  p.cavity_radius = cavity_radius;
  p.point = cavity_center;
  element_->pairs.push_back(p);
}

void CompliantContact::addSphereInEllipsoidalCavity(const SimTK::MobilizedBody& body, double radius,
                                                    const contact::ConvexShape& cavity, const ContactLaws& laws) {
  if (!cavity.quadric) throw InvalidParameter("cavity exponents", "2, 2, 2 (an ellipsoid)", cavity.exponents.maxCoeff());
  const double tightest = cavity.radii.minCoeff() * cavity.radii.minCoeff() / cavity.radii.maxCoeff();
  if (!(radius > 0 && radius <= tightest))
    throw InvalidParameter("ball radius", "> 0 and at most the cavity's tightest radius of curvature, " +
                                              std::to_string(tightest), radius);
  Pair p = newPair(PairKind::SphereInEllipsoid, body, laws);
  p.radius = radius;
  p.shape = cavity;
  element_->pairs.push_back(p);
}

void CompliantContact::addShapePair(const SimTK::MobilizedBody& body_a, const contact::ConvexShape& shape_a,
                                    const SimTK::MobilizedBody& body_b, const contact::ConvexShape& shape_b,
                                    const ContactLaws& laws) {
  if (body_a.getMobilizedBodyIndex() == body_b.getMobilizedBodyIndex())
    throw InvalidParameter("contact pair", "two different bodies", static_cast<double>(body_a.getMobilizedBodyIndex()));
  Pair p = newPair(PairKind::ShapePair, body_a, laws);
  p.shape = shape_a;
  p.body_b = body_b.getMobilizedBodyIndex();
  p.shape_b = shape_b;
  element_->pairs.push_back(p);
}

const ContactCounters& CompliantContact::counters() const { return element_->counters; }

std::vector<contact::ContactForce> CompliantContact::forces(const SimTK::State& state) const {
  std::vector<contact::ContactForce> out;
  for (const Pair& p : element_->pairs)
    out.push_back(contact::contactForce(element_->evaluate(p, state).state, p.laws.normal, p.laws.friction));
  return out;
}

}  // namespace articula::dynamics
