#pragma once
// A simulation scene as `articula simulate` reads it (docs/formats.md): rigid
// bodies under gravity, free or hinged to a parent body by a revolute joint
// with passive stiffness and damping, each with contact surfaces (sphere,
// ellipsoid, superellipsoid in the thesis form) against a plane or inside a
// spherical or ellipsoidal cavity fixed in ground, or against another body's surface (each
// given by its parameters, or as fitted: a model of a fits.json), or
// contact points against a plane (the point elements surfaces are compared
// with); the contact laws, the integrator and the output.
// SI units; angles in degrees in the file.
#include <filesystem>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "articula/contact/convex_shape.hpp"
#include "articula/dynamics/compliant_contact.hpp"

namespace articula::dynamics {

/// A revolute joint to a parent body, given in both bodies' frames: at
/// angle 0 the child's frame is the parent's turned by nothing and shifted
/// so that the two joint points coincide.
struct SceneJoint {
  int parent = -1;  // index into Scene::bodies (an earlier body); -1: the body is free
  Eigen::Vector3d point_in_parent = Eigen::Vector3d::Zero(), point_in_child = Eigen::Vector3d::Zero();
  Eigen::Vector3d axis = Eigen::Vector3d::UnitY();  // unit, in the parent's (and at angle 0 the child's) frame
  double stiffness = 0;      // N m / rad, towards rest_angle
  double damping = 0;        // N m s / rad
  double rest_angle_deg = 0;
  double angle_deg = 0;      // initial angle
  double rate_deg_s = 0;     // initial rate
};

struct SceneBody {
  std::string name;
  SceneJoint joint;  // a hinged body takes its pose and velocity from its parent and the joint
  double mass = 1;
  Eigen::Vector3d inertia = Eigen::Vector3d::Ones();  // principal moments about the centre of mass (body axes), kg m^2
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d angles_deg = Eigen::Vector3d::Zero();  // body-fixed x-y-z rotation (phi, theta, psi)
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();  // ground frame, rad/s
};

struct SceneContact {
  int body = 0;                         // index into Scene::bodies
  contact::ConvexShape shape;           // in the body's frame
  bool point_contact = false;           // a contact point (at `station`) against a plane, not a shape
  Eigen::Vector3d station = Eigen::Vector3d::Zero();  // the point, in the body's frame
  bool cavity = false;                  // against a spherical cavity
  int other_body = -1;                  // against another body's shape (>= 0), else a plane or a cavity
  contact::ConvexShape other_shape;     // in that body's frame
  Eigen::Vector3d point = Eigen::Vector3d::Zero(), normal = Eigen::Vector3d::UnitZ();  // plane, or cavity centre
  double cavity_radius = 0;             // a spherical cavity
  bool ellipsoidal_cavity = false;      // else the cavity is this ellipsoid (ground frame)
  contact::ConvexShape cavity_shape;
  ContactLaws laws;
};

enum class IntegratorKind { RungeKuttaMerson, CPodes, SemiExplicitEuler };

struct Scene {
  std::vector<SceneBody> bodies;
  std::vector<SceneContact> contacts;
  Eigen::Vector3d gravity = Eigen::Vector3d(0, 0, -9.81);
  IntegratorKind integrator = IntegratorKind::RungeKuttaMerson;
  double accuracy = 1e-6;
  double duration = 1;
  double output_interval = 0.01;
};

/// Reads and checks a scene file; throws InputError naming the file and the
/// first field that is missing, of the wrong type or out of its range.
Scene readScene(const std::filesystem::path& path);

/// The same from a parsed document; `where` names it in messages, and
/// relative paths in it (a shape's "fits") are taken from `folder`.
Scene sceneFromJson(const nlohmann::json& document, const std::string& where,
                    const std::filesystem::path& folder = {});

}  // namespace articula::dynamics
