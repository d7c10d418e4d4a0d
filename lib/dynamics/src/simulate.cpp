#include "articula/dynamics/simulate.hpp"

#include <chrono>
#include <cmath>
#include <limits>
#include <memory>

#include <Simbody.h>

#include "articula/core/atomic_file.hpp"
#include "articula/core/error.hpp"
#include "articula/core/number_text.hpp"
#include "articula/dynamics/compliant_contact.hpp"
#include "articula/geometry/pose.hpp"

namespace articula::dynamics {
namespace {

SimTK::Vec3 toSimTK(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

std::unique_ptr<SimTK::Integrator> makeIntegrator(IntegratorKind kind, const SimTK::System& system) {
  switch (kind) {
    case IntegratorKind::CPodes: return std::make_unique<SimTK::CPodesIntegrator>(system);
    case IntegratorKind::SemiExplicitEuler: return std::make_unique<SimTK::SemiExplicitEuler2Integrator>(system);
    case IntegratorKind::RungeKuttaMerson: break;
  }
  return std::make_unique<SimTK::RungeKuttaMersonIntegrator>(system);
}

std::string csvNumber(double v) {
  std::string text;
  appendNumber(text, v, 10);
  return text;
}

}  // namespace

const std::vector<std::string>& simulationOutputs() {
  static const std::vector<std::string> names = {"trajectory.csv", "contacts.csv", "steps.csv"};
  return names;
}

nlohmann::json SimulationSummary::toJson() const {
  return {{"simulated_s", simulated_seconds}, {"wall_s", wall_seconds},       {"steps", steps},
          {"mean_step_s", mean_step},         {"min_step_s", min_step},       {"max_step_s", max_step},
          {"contact_evaluations", contact_evaluations}, {"output_rows", output_rows},
          {"energy_start_j", energy_start},   {"energy_end_j", energy_end}};
}

SimulationSummary simulateScene(const Scene& scene, const std::filesystem::path& folder,
                                const std::function<void(double)>& progress, SimulationSeries* series) {
  const auto wall_start = std::chrono::steady_clock::now();
  SimTK::MultibodySystem system;
  SimTK::SimbodyMatterSubsystem matter(system);
  SimTK::GeneralForceSubsystem forces(system);
  const double g = scene.gravity.norm();
  if (g > 0) SimTK::Force::Gravity(forces, matter, SimTK::UnitVec3(toSimTK(scene.gravity / g)), g);
  std::vector<SimTK::MobilizedBody> bodies;
  std::vector<bool> hinged;
  for (const SceneBody& b : scene.bodies) {
    const SimTK::Body::Rigid body(SimTK::MassProperties(b.mass, SimTK::Vec3(0), SimTK::Inertia(toSimTK(b.inertia))));
    const SceneJoint& j = b.joint;
    hinged.push_back(j.parent >= 0);
    if (j.parent < 0) {
      bodies.push_back(SimTK::MobilizedBody::Free(matter.Ground(), SimTK::Transform(), body, SimTK::Transform()));
      continue;
    }
    // Simbody's pin turns about the common z axis of its two frames.
    const SimTK::Rotation z_along_axis(SimTK::UnitVec3(toSimTK(j.axis)), SimTK::ZAxis);
    SimTK::MobilizedBody::Pin pin(bodies[static_cast<size_t>(j.parent)], SimTK::Transform(z_along_axis, toSimTK(j.point_in_parent)),
                                  body, SimTK::Transform(z_along_axis, toSimTK(j.point_in_child)));
    const double degree = M_PI / 180.0;
    if (j.stiffness > 0)
      SimTK::Force::MobilityLinearSpring(forces, pin, SimTK::MobilizerQIndex(0), j.stiffness, j.rest_angle_deg * degree);
    if (j.damping > 0) SimTK::Force::MobilityLinearDamper(forces, pin, SimTK::MobilizerUIndex(0), j.damping);
    bodies.push_back(pin);
  }
  CompliantContact contact(forces);
  for (const SceneContact& c : scene.contacts) {
    const SimTK::MobilizedBody& body = bodies[static_cast<size_t>(c.body)];
    if (c.other_body >= 0)
      contact.addShapePair(body, c.shape, bodies[static_cast<size_t>(c.other_body)], c.other_shape, c.laws);
    else if (c.cavity && c.ellipsoidal_cavity)
      contact.addSphereInEllipsoidalCavity(body, c.shape.radii[0], c.cavity_shape, c.laws);
    else if (c.cavity)
      contact.addSphereInCavity(body, c.shape.radii[0], c.point, c.cavity_radius, c.laws);
    else if (c.point_contact)
      contact.addPointOnPlane(body, c.station, c.point, c.normal, c.laws);
    else
      contact.addShapeOnPlane(body, c.shape, c.point, c.normal, c.laws);
  }
  system.realizeTopology();
  SimTK::State state = system.getDefaultState();
  // Parents before children (the scene's order): a hinged body's pose follows its parent's.
  for (size_t i = 0; i < bodies.size(); ++i) {
    const SceneBody& b = scene.bodies[i];
    if (hinged[i]) {
      const double degree = M_PI / 180.0;
      bodies[i].setOneQ(state, SimTK::MobilizerQIndex(0), b.joint.angle_deg * degree);
      bodies[i].setOneU(state, SimTK::MobilizerUIndex(0), b.joint.rate_deg_s * degree);
      continue;
    }
    const Eigen::Matrix3d R = geometry::rotationFromAngles(b.angles_deg * M_PI / 180.0);
    const SimTK::Mat33 m(R(0, 0), R(0, 1), R(0, 2), R(1, 0), R(1, 1), R(1, 2), R(2, 0), R(2, 1), R(2, 2));
    bodies[i].setQToFitTransform(state, SimTK::Transform(SimTK::Rotation(m, true), toSimTK(b.position)));
    bodies[i].setUToFitVelocity(state, SimTK::SpatialVec(toSimTK(b.angular_velocity), toSimTK(b.velocity)));
  }
  const std::unique_ptr<SimTK::Integrator> integrator = makeIntegrator(scene.integrator, system);
  integrator->setAccuracy(scene.accuracy);
  integrator->setReturnEveryInternalStep(true);
  integrator->initialize(state);

  std::string trajectory = "time_s";
  for (const SceneBody& b : scene.bodies)
    for (const char* column : {"x_m", "y_m", "z_m", "qw", "qx", "qy", "qz", "vx_m_s", "vy_m_s", "vz_m_s", "wx_rad_s",
                               "wy_rad_s", "wz_rad_s"})
      trajectory += "," + b.name + "_" + column;
  trajectory += ",kinetic_j,potential_j,total_j\n";
  std::string contacts = "time_s,contact,depth_m,normal_n,friction_t_n,friction_b_n,x_m,y_m,z_m\n";
  std::string steps = "time_s,step_s\n";
  SimulationSummary summary;
  summary.min_step = std::numeric_limits<double>::infinity();
  // What the figures show: each body's height along gravity, each contact's
  // normal force (NaN while apart), every step's size.
  SimulationSeries drawn;
  std::vector<TimeSeries>& heights = drawn.heights;
  std::vector<TimeSeries>& normal_forces = drawn.normal_forces;
  TimeSeries& step_sizes = drawn.step_sizes;
  heights.resize(bodies.size());
  normal_forces.resize(scene.contacts.size());
  for (size_t i = 0; i < bodies.size(); ++i) heights[i].label = scene.bodies[i].name;
  for (size_t k = 0; k < scene.contacts.size(); ++k)
    normal_forces[k].label = "contact " + std::to_string(k) + " (" + scene.bodies[static_cast<size_t>(scene.contacts[k].body)].name + ")";
  const Eigen::Vector3d up = g > 0 ? Eigen::Vector3d(-scene.gravity / g) : Eigen::Vector3d::UnitZ();
  const auto writeRow = [&](const SimTK::State& s) {
    system.realize(s, SimTK::Stage::Dynamics);
    trajectory += csvNumber(s.getTime());
    for (size_t i = 0; i < bodies.size(); ++i) {
      const SimTK::MobilizedBody& body = bodies[i];
      const SimTK::Transform& X = body.getBodyTransform(s);
      heights[i].t.push_back(s.getTime());
      heights[i].value.push_back(up.dot(Eigen::Vector3d(X.p()[0], X.p()[1], X.p()[2])));
      const SimTK::Quaternion q = X.R().convertRotationToQuaternion();
      const SimTK::SpatialVec& V = body.getBodyVelocity(s);
      for (double v : {X.p()[0], X.p()[1], X.p()[2], q[0], q[1], q[2], q[3], V[1][0], V[1][1], V[1][2], V[0][0], V[0][1],
                       V[0][2]})
        trajectory += "," + csvNumber(v);
    }
    const double kinetic = system.calcKineticEnergy(s), potential = system.calcPotentialEnergy(s);
    trajectory += "," + csvNumber(kinetic) + "," + csvNumber(potential) + "," + csvNumber(kinetic + potential) + "\n";
    const auto forces_now = contact.forces(s);
    for (size_t k = 0; k < forces_now.size(); ++k) {
      const contact::ContactForce& f = forces_now[k];
      normal_forces[k].t.push_back(s.getTime());
      normal_forces[k].value.push_back(f.normal > 0 ? f.normal : NAN);
      if (!(f.normal > 0)) continue;
      contacts += csvNumber(s.getTime()) + "," + std::to_string(k) + "," + csvNumber(f.depth) + "," + csvNumber(f.normal) + "," + csvNumber(f.friction_tb.x()) + "," +
                  csvNumber(f.friction_tb.y()) + "," + csvNumber(f.point.x()) + "," + csvNumber(f.point.y()) + "," +
                  csvNumber(f.point.z()) + "\n";
    }
    ++summary.output_rows;
    if (progress) progress(s.getTime());
    return kinetic + potential;
  };
  summary.energy_start = writeRow(integrator->getState());
  long long report = 1;
  const auto reportTime = [&] { return std::min(scene.duration, static_cast<double>(report) * scene.output_interval); };
  while (true) {
    const SimTK::Integrator::SuccessfulStepStatus status = integrator->stepTo(reportTime());
    if (status == SimTK::Integrator::TimeHasAdvanced) {
      const double h = integrator->getPreviousStepSizeTaken();
      ++summary.steps;
      summary.min_step = std::min(summary.min_step, h);
      summary.max_step = std::max(summary.max_step, h);
      steps += csvNumber(integrator->getTime()) + "," + csvNumber(h) + "\n";
      step_sizes.t.push_back(integrator->getTime());
      step_sizes.value.push_back(h);
    } else if (status == SimTK::Integrator::ReachedReportTime) {
      summary.energy_end = writeRow(integrator->getState());
      if (integrator->getTime() >= scene.duration) break;
      ++report;
    } else if (status == SimTK::Integrator::EndOfSimulation) {
      break;
    }
    if (integrator->isSimulationOver()) break;
  }
  if (integrator->getTime() < scene.duration)
    throw ProcessingError("the integrator stopped at t = " + csvNumber(integrator->getTime()) + " s: " +
                          SimTK::Integrator::getTerminationReasonString(integrator->getTerminationReason()));
  summary.simulated_seconds = integrator->getTime();
  summary.mean_step = summary.steps ? summary.simulated_seconds / static_cast<double>(summary.steps) : 0;
  if (summary.steps == 0) summary.min_step = 0;
  summary.contact_evaluations = contact.counters().evaluations;
  // In the order of simulationOutputs().
  const std::string contents[] = {trajectory, contacts, steps};
  for (size_t i = 0; i < simulationOutputs().size(); ++i) writeFileAtomically(folder / simulationOutputs()[i], contents[i]);
  if (series) *series = std::move(drawn);
  summary.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  return summary;
}

}  // namespace articula::dynamics
