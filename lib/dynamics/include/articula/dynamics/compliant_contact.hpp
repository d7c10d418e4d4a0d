#pragma once
// Compliant contact on Simbody: a force element (Simbody's Force::Custom)
// that evaluates articula's contact geometry for every registered pair at
// each force evaluation and applies the force laws of contact/force_laws.hpp
// at the contact points. Pairs: a convex shape (sphere, ellipsoid,
// superellipsoid) on a body against a plane fixed in ground (the closed form
// of thesis section 5.3), a sphere inside a spherical or ellipsoidal cavity
// fixed in ground (conformal contact, thesis section 5.2.7), two convex shapes on any two
// bodies (the common-normal / dual solver, warm-started per pair), and a
// point on a body against a plane (the point elements of foot-ground
// models, thesis ch. 6). SI units.
#include <memory>

#include <Simbody.h>

#include "articula/contact/convex_shape.hpp"
#include "articula/contact/force_laws.hpp"

namespace articula::dynamics {

struct ContactLaws {
  contact::NormalForceLaw normal;
  contact::FrictionLaw friction;
};

/// What the element did, for summaries and benchmarks.
struct ContactCounters {
  long long evaluations = 0;  // pair evaluations (one per pair per force evaluation)
  long long in_contact = 0;   // of those, with positive depth
  long long warm_starts = 0;  // shape pairs solved from their previous answer
};

class CompliantContact {
 public:
  /// Adds the element to `forces` (Simbody owns it; this handle registers pairs).
  explicit CompliantContact(SimTK::GeneralForceSubsystem& forces);
  ~CompliantContact();
  CompliantContact(const CompliantContact&) = delete;
  CompliantContact& operator=(const CompliantContact&) = delete;

  /// `shape` given in the body's frame (centre, rotation, radii, exponents)
  /// against the plane through `plane_point` with outward normal
  /// `plane_normal` (ground frame; the solid lies on the other side).
  void addShapeOnPlane(const SimTK::MobilizedBody& body, const contact::ConvexShape& shape,
                       const Eigen::Vector3d& plane_point, const Eigen::Vector3d& plane_normal, const ContactLaws& laws);

  /// The point `station` (the body's frame) against the plane through
  /// `plane_point` with outward normal `plane_normal` (ground): depth is how
  /// far the point lies beyond the plane.
  void addPointOnPlane(const SimTK::MobilizedBody& body, const Eigen::Vector3d& station,
                       const Eigen::Vector3d& plane_point, const Eigen::Vector3d& plane_normal, const ContactLaws& laws);

  /// A ball of `radius` centred at the body's origin inside a spherical
  /// cavity of `cavity_radius` centred at `cavity_center` (ground).
  void addSphereInCavity(const SimTK::MobilizedBody& body, double radius, const Eigen::Vector3d& cavity_center,
                         double cavity_radius, const ContactLaws& laws);

  /// A ball of `radius` centred at the body's origin inside the ellipsoid
  /// `cavity` (ground frame; exponents 2): the exact closest point of the
  /// cavity's surface to the ball's centre (distance/ellipsoid_distance.hpp)
  /// gives the depth and the normal. The ball must be no larger than the
  /// cavity's tightest curvature (radius a_min^2 / a_max), or it could
  /// touch at two places; InvalidParameter otherwise.
  void addSphereInEllipsoidalCavity(const SimTK::MobilizedBody& body, double radius,
                                    const contact::ConvexShape& cavity, const ContactLaws& laws);

  /// Two convex shapes, each given in its body's frame (either body may be
  /// Ground): the minimum signed distance of contact/common_normal.hpp,
  /// warm-started from this pair's previous answer (thesis section 5.4.5).
  void addShapePair(const SimTK::MobilizedBody& body_a, const contact::ConvexShape& shape_a,
                    const SimTK::MobilizedBody& body_b, const contact::ConvexShape& shape_b, const ContactLaws& laws);

  const ContactCounters& counters() const;

  /// The contact forces of every pair at `state` (Stage::Velocity or later), in
  /// registration order, for output.
  std::vector<contact::ContactForce> forces(const SimTK::State& state) const;

 private:
  class Element;
  Element* element_;  // owned by the force subsystem
};

}  // namespace articula::dynamics
