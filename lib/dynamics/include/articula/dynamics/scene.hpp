#pragma once
// A simulation scene as `articula simulate` reads it (docs/formats.md): free
// rigid bodies under gravity, each with contact surfaces (sphere, ellipsoid,
// superellipsoid in the thesis form) against a plane or inside a spherical
// cavity fixed in ground, or against another body's surface; the contact
// laws, the integrator and the output.
// SI units; angles in degrees in the file.
#include <filesystem>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "articula/contact/convex_shape.hpp"
#include "articula/dynamics/compliant_contact.hpp"

namespace articula::dynamics {

struct SceneBody {
  std::string name;
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
  bool cavity = false;                  // against a spherical cavity
  int other_body = -1;                  // against another body's shape (>= 0), else a plane or a cavity
  contact::ConvexShape other_shape;     // in that body's frame
  Eigen::Vector3d point = Eigen::Vector3d::Zero(), normal = Eigen::Vector3d::UnitZ();  // plane, or cavity centre
  double cavity_radius = 0;
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
  nlohmann::json source;  // the file as read, for provenance
};

/// Reads and checks a scene file; throws InputError naming the file and the
/// first field that is missing, of the wrong type or out of its range.
Scene readScene(const std::filesystem::path& path);

/// The same from a parsed document; `where` names it in messages.
Scene sceneFromJson(const nlohmann::json& document, const std::string& where);

}  // namespace articula::dynamics
