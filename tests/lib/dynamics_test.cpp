// Compliant contact on Simbody against closed forms and Simbody's own
// contact: a ball settles on a plane at the Hertz depth; with no damping and
// no friction a bouncing ball keeps its energy; a ball rolling without slip
// at the bottom of a spherical bowl oscillates with the period of the rigid
// rolling solution; a sphere dropped with spin on a plane follows Simbody's
// HuntCrossleyForce with the same parameters; an ellipsoid rests where
// Simbody's elliptical Hertz contact puts it; a body hinged by a scene's
// revolute joint oscillates with the torsion pendulum's period and keeps its
// energy; a body on four contact points rests at their Hertz depth.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <Simbody.h>

#include "articula/contact/convex_shape.hpp"
#include "articula/core/error.hpp"
#include "articula/dynamics/compliant_contact.hpp"
#include "articula/dynamics/scene.hpp"
#include "articula/dynamics/simulate.hpp"
#include "articula/testsupport/ball_world.hpp"

namespace {

using articula::contact::NormalLaw;
using articula::dynamics::CompliantContact;
using articula::dynamics::ContactLaws;
using Eigen::Vector3d;

using articula::testsupport::BallWorld;
using articula::testsupport::kGravity;
using articula::testsupport::Simulation;

articula::contact::ConvexShape sphere(double r) {
  return articula::contact::makeConvexShape(Vector3d::Zero(), Eigen::Matrix3d::Identity(), Vector3d::Constant(r));
}

ContactLaws hertzLaws(double stiffness, NormalLaw law, double dissipation, double mu) {
  ContactLaws laws;
  laws.normal.law = law;
  laws.normal.stiffness = stiffness;
  laws.normal.dissipation = dissipation;
  laws.friction.dynamic = mu;
  laws.friction.transition_speed = 1e-3;
  return laws;
}

/// The period of an oscillation sampled as x(t): twice the mean time between
/// its first `crossings` zero crossings (linear interpolation between
/// samples); NaN when it crosses fewer times.
double periodFromZeroCrossings(const std::vector<double>& t, const std::vector<double>& x, size_t crossings) {
  std::vector<double> at;
  for (size_t i = 1; i < t.size() && at.size() < crossings; ++i)
    if ((x[i - 1] < 0) != (x[i] < 0)) at.push_back(t[i - 1] + (t[i] - t[i - 1]) * x[i - 1] / (x[i - 1] - x[i]));
  if (at.size() < crossings || crossings < 2) return std::nan("");
  return 2 * (at.back() - at.front()) / static_cast<double>(at.size() - 1);
}

/// The ball's x every millisecond for `seconds` of a run.
void sampleX(const BallWorld& w, Simulation& run, double seconds, std::vector<double>& t, std::vector<double>& x) {
  const double dt = 1e-3;
  t.push_back(0);
  x.push_back(w.ball.getBodyOriginLocation(run.integrator.getState())[0]);
  for (int i = 1; i * dt <= seconds; ++i) {
    t.push_back(i * dt);
    x.push_back(w.ball.getBodyOriginLocation(run.stepTo(i * dt))[0]);
  }
}

TEST(Dynamics, ABallSettlesOnAPlaneAtTheHertzDepth) {
  const double m = 1.0, r = 0.1, K = 1e7;
  BallWorld w(m, 0.4 * m * r * r);
  CompliantContact contact(w.forces);
  contact.addShapeOnPlane(w.ball, sphere(r), Vector3d::Zero(), Vector3d::UnitZ(),
                          hertzLaws(K, NormalLaw::HuntCrossley, 5.0, 0.0));
  SimTK::State state = w.start();
  w.ball.setQToFitTranslation(state, SimTK::Vec3(0, 0, r + 0.002));
  Simulation run(w.system, state, 1e-9);
  const double depth = r - w.ball.getBodyOriginLocation(run.stepTo(3.0))[2];
  const double hertz = std::pow(m * kGravity / K, 2.0 / 3.0);
  EXPECT_NEAR(depth, hertz, 1e-6 * hertz);
  EXPECT_GT(contact.counters().in_contact, 0);
}

TEST(Dynamics, AnElasticBounceKeepsItsEnergy) {
  const double m = 0.5, r = 0.05, K = 1e6;
  BallWorld w(m, 0.4 * m * r * r);
  CompliantContact contact(w.forces);
  contact.addShapeOnPlane(w.ball, sphere(r), Vector3d::Zero(), Vector3d::UnitZ(),
                          hertzLaws(K, NormalLaw::Hertz, 0.0, 0.0));
  SimTK::State state = w.start();
  w.ball.setQToFitTranslation(state, SimTK::Vec3(0, 0, r + 0.2));
  w.ball.setUToFitLinearVelocity(state, SimTK::Vec3(0.3, 0, 0));
  w.system.realize(state, SimTK::Stage::Dynamics);
  const double e0 = w.system.calcEnergy(state);
  Simulation run(w.system, state, 1e-10);
  double worst = 0;
  for (int i = 1; i <= 100; ++i) {
    const SimTK::State& s = run.stepTo(0.1 * i);
    w.system.realize(s, SimTK::Stage::Dynamics);
    worst = std::max(worst, std::fabs(w.system.calcEnergy(s) - e0) / std::fabs(e0));
  }
  EXPECT_LT(worst, 1e-6);
  EXPECT_GT(contact.counters().in_contact, 100);  // it did bounce, several times
}

// Pairs of convex shapes through the common-normal / dual solver, warm
// started per pair: a ball resting on a ball fixed in ground settles at the
// Hertz depth; two free ellipsoids colliding in zero gravity keep their
// total momentum (the pair's forces are equal and opposite).
TEST(Dynamics, ShapePairsSettleAndConserveMomentum) {
  {
    const double m = 1.0, r = 0.05, R = 0.5, K = 1e7;
    BallWorld w(m, 0.4 * m * r * r);
    CompliantContact contact(w.forces);
    const auto big = articula::contact::makeConvexShape(Vector3d(0, 0, -R), Eigen::Matrix3d::Identity(), Vector3d::Constant(R));
    contact.addShapePair(w.ball, sphere(r), w.matter.Ground(), big, hertzLaws(K, NormalLaw::HuntCrossley, 5.0, 0.0));
    SimTK::State state = w.start();
    w.ball.setQToFitTranslation(state, SimTK::Vec3(0, 0, r + 0.002));
    Simulation run(w.system, state, 1e-9);
    const double depth = r - w.ball.getBodyOriginLocation(run.stepTo(3.0))[2];
    const double hertz = std::pow(m * kGravity / K, 2.0 / 3.0);
    EXPECT_NEAR(depth, hertz, 1e-6 * hertz);
    EXPECT_GT(contact.counters().warm_starts, contact.counters().evaluations / 2);
  }
  {
    SimTK::MultibodySystem system;
    SimTK::SimbodyMatterSubsystem matter(system);
    SimTK::GeneralForceSubsystem forces(system);
    const auto free = [&](double mass) {
      return SimTK::MobilizedBody::Free(matter.Ground(), SimTK::Transform(),
                                        SimTK::Body::Rigid(SimTK::MassProperties(mass, SimTK::Vec3(0), SimTK::UnitInertia(1e-3))),
                                        SimTK::Transform());
    };
    SimTK::MobilizedBody::Free a = free(1.0), b = free(3.0);
    CompliantContact contact(forces);
    const Eigen::Matrix3d turned = Eigen::AngleAxisd(0.4, Vector3d(1, 2, 3).normalized()).toRotationMatrix();
    contact.addShapePair(a, articula::contact::makeConvexShape(Vector3d::Zero(), turned, Vector3d(0.05, 0.03, 0.04)), b,
                         articula::contact::makeConvexShape(Vector3d::Zero(), Eigen::Matrix3d::Identity(), Vector3d(0.06, 0.04, 0.05)),
                         hertzLaws(1e6, NormalLaw::HuntCrossley, 0.2, 0.3));
    system.realizeTopology();
    SimTK::State state = system.getDefaultState();
    a.setQToFitTranslation(state, SimTK::Vec3(-0.2, 0.01, 0));
    a.setUToFitLinearVelocity(state, SimTK::Vec3(1.0, 0, 0.05));
    b.setQToFitTranslation(state, SimTK::Vec3(0, 0, 0));
    Simulation run(system, state, 1e-9);
    const SimTK::State& end = run.stepTo(0.5);
    const SimTK::Vec3 momentum = 1.0 * a.getBodyOriginVelocity(end) + 3.0 * b.getBodyOriginVelocity(end);
    EXPECT_LT((momentum - SimTK::Vec3(1.0, 0, 0.05)).norm(), 1e-9);
    EXPECT_GT(b.getBodyOriginVelocity(end)[0], 0.1);  // they did collide
    EXPECT_GT(contact.counters().in_contact, 10);
  }
}

// A solid ball (I = 2/5 m r^2) rolling without slip at the bottom of a bowl
// of radius R: small oscillations of period 2 pi sqrt(7 (R - r) / (5 g)).
TEST(Dynamics, ABallRollingInABowlOscillatesWithTheRollingPeriod) {
  const double m = 1.0, r = 0.1, R = 1.0, K = 1e7;
  BallWorld w(m, 0.4 * m * r * r);
  CompliantContact contact(w.forces);
  ContactLaws laws = hertzLaws(K, NormalLaw::HuntCrossley, 0.1, 0.5);
  laws.friction.transition_speed = 1e-3;
  contact.addSphereInCavity(w.ball, r, Vector3d(0, 0, R), R, laws);
  SimTK::State state = w.start();
  const double angle = 0.05;  // from the bottom, about the y axis
  const double sag = std::pow(m * kGravity / K, 2.0 / 3.0);
  const double arm = R - r + sag;
  w.ball.setQToFitTranslation(state, SimTK::Vec3(arm * std::sin(angle), 0, R - arm * std::cos(angle)));
  Simulation run(w.system, state, 1e-8);
  std::vector<double> t, x;
  sampleX(w, run, 3.0, t, x);
  const double period = periodFromZeroCrossings(t, x, 3);
  const double rolling = 2 * M_PI * std::sqrt(7.0 * (R - r) / (5.0 * kGravity));
  EXPECT_NEAR(period, rolling, 0.005 * rolling) << "sliding: " << 2 * M_PI * std::sqrt((R - r) / kGravity) << " s";
}

// Simbody's HuntCrossleyForce with the same law: f = K d^1.5 (1 + 3/2 c d'),
// K = 4/3 sqrt(R) E with E = (E1^(2/3) / 2)^(3/2) for two surfaces of plane
// strain modulus E1, and its friction; a sphere dropped with spin and
// forward speed rolls and slides.
TEST(Dynamics, ASphereOnAPlaneFollowsSimbodysHuntCrossley) {
  const double m = 1.0, r = 0.05, k_surface = 1e8, c = 0.5, mu_s = 0.6, mu_d = 0.4, vt = 0.01;
  const auto simulate = [&](bool ours) {
    BallWorld w(m, 0.4 * m * r * r);
    SimTK::GeneralContactSubsystem contacts(w.system);
    std::unique_ptr<CompliantContact> element;
    if (ours) {
      const double modulus = k_surface / std::pow(2.0, 1.5);
      ContactLaws laws = hertzLaws(4.0 / 3.0 * std::sqrt(r) * modulus, NormalLaw::HuntCrossley, c, mu_d);
      laws.friction.static_peak = mu_s;
      laws.friction.transition_speed = vt;
      element = std::make_unique<CompliantContact>(w.forces);
      element->addShapeOnPlane(w.ball, sphere(r), Vector3d::Zero(), Vector3d::UnitZ(), laws);
    } else {
      const SimTK::ContactSetIndex set = contacts.createContactSet();
      contacts.addBody(set, w.ball, SimTK::ContactGeometry::Sphere(r), SimTK::Transform());
      contacts.addBody(set, w.matter.updGround(), SimTK::ContactGeometry::HalfSpace(),
                       SimTK::Transform(SimTK::Rotation(0.5 * SimTK::Pi, SimTK::YAxis), SimTK::Vec3(0)));
      SimTK::HuntCrossleyForce hc(w.forces, contacts, set);
      hc.setBodyParameters(SimTK::ContactSurfaceIndex(0), k_surface, c, mu_s, mu_d, 0);
      hc.setBodyParameters(SimTK::ContactSurfaceIndex(1), k_surface, c, mu_s, mu_d, 0);
      hc.setTransitionVelocity(vt);
    }
    SimTK::State state = w.start();
    w.ball.setQToFitTranslation(state, SimTK::Vec3(0, 0, r + 0.01));
    w.ball.setUToFitVelocity(state, SimTK::SpatialVec(SimTK::Vec3(0, 20, 3), SimTK::Vec3(1.0, 0.2, 0)));
    Simulation run(w.system, state, 1e-10);
    std::vector<SimTK::Vec3> path;
    for (int i = 1; i <= 50; ++i) path.push_back(w.ball.getBodyOriginLocation(run.stepTo(0.01 * i)));
    return path;
  };
  const std::vector<SimTK::Vec3> ours = simulate(true), simbody = simulate(false);
  double worst = 0, travelled = 0;
  for (size_t i = 0; i < ours.size(); ++i) {
    worst = std::max(worst, (ours[i] - simbody[i]).norm());
    travelled = std::max(travelled, (simbody[i] - simbody[0]).norm());
  }
  EXPECT_LT(worst, 1e-6) << "travelled " << travelled << " m";
  EXPECT_GT(travelled, 0.05);  // it rolled and slid, not just sat
}

// Simbody's CompliantContactSubsystem answers an ellipsoid on a half-space
// with its elliptical Hertz generator; articula's element takes one
// stiffness, here hertzStiffness at the pole's curvatures (Greenwood's
// equivalent radius). Both drop an ellipsoid on the pole of its shortest
// axis and let it settle: the depths agree to within the two Hertz
// approximations' difference (0.2 % here).
TEST(Dynamics, AnEllipsoidRestsWhereSimbodysEllipticalHertzPutsIt) {
  const double m = 1.0, a = 0.06, b = 0.05, c = 0.04, e_surface = 1e7, dissipation = 5.0;  // on its shortest axis: stable
  const SimTK::Vec3 moments(0.2 * m * (b * b + c * c), 0.2 * m * (a * a + c * c), 0.2 * m * (a * a + b * b));
  const auto restingDepth = [&](bool ours) {
    BallWorld w(m, moments);
    SimTK::ContactTrackerSubsystem tracker(w.system);
    SimTK::CompliantContactSubsystem compliant(w.system, tracker);
    std::unique_ptr<CompliantContact> element;
    if (ours) {
      const double modulus = e_surface / std::pow(2.0, 1.5);  // Simbody's combination of two equal surfaces
      const double stiffness = articula::contact::hertzStiffness(c / (a * a), c / (b * b), modulus);
      element = std::make_unique<CompliantContact>(w.forces);
      element->addShapeOnPlane(w.ball,
                               articula::contact::makeConvexShape(Vector3d::Zero(), Eigen::Matrix3d::Identity(),
                                                                  Vector3d(a, b, c)),
                               Vector3d::Zero(), Vector3d::UnitZ(),
                               hertzLaws(stiffness, NormalLaw::HuntCrossley, dissipation, 0.0));
    } else {
      const SimTK::ContactMaterial material(e_surface, dissipation, 0, 0, 0);
      w.ball.updBody().addContactSurface(SimTK::Transform(),
                                         SimTK::ContactSurface(SimTK::ContactGeometry::Ellipsoid(SimTK::Vec3(a, b, c)), material));
      // Simbody's half-space fills x > 0 of its frame: turned so that it fills z < 0.
      w.matter.updGround().updBody().addContactSurface(
          SimTK::Transform(SimTK::Rotation(0.5 * SimTK::Pi, SimTK::YAxis), SimTK::Vec3(0)),
          SimTK::ContactSurface(SimTK::ContactGeometry::HalfSpace(), material));
    }
    SimTK::State state = w.start();
    w.ball.setQToFitTranslation(state, SimTK::Vec3(0, 0, c + 0.001));
    Simulation run(w.system, state, 1e-9);
    return c - w.ball.getBodyOriginLocation(run.stepTo(2.0))[2];
  };
  const double ours = restingDepth(true), simbody = restingDepth(false);
  EXPECT_GT(ours, 0);
  EXPECT_NEAR(ours, simbody, 0.01 * simbody) << "ours " << ours << " m, Simbody's " << simbody << " m";
}

/// The columns of a CSV file with a header, by name.
std::map<std::string, std::vector<double>> readColumns(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  std::vector<std::string> names;
  for (std::stringstream header(line); std::getline(header, line, ',');) names.push_back(line);
  std::map<std::string, std::vector<double>> columns;
  while (std::getline(in, line)) {
    std::stringstream row(line);
    for (const std::string& name : names) {
      std::string cell;
      std::getline(row, cell, ',');
      columns[name].push_back(std::stod(cell));
    }
  }
  return columns;
}

std::filesystem::path simulateInto(const std::string& scene_json, const std::string& name) {
  const std::filesystem::path folder = std::filesystem::path(::testing::TempDir()) / name;
  std::filesystem::create_directories(folder);
  articula::dynamics::simulateScene(articula::dynamics::sceneFromJson(nlohmann::json::parse(scene_json), name), folder);
  return folder;
}

// No gravity; an arm hinged to a base a billion times heavier by an oblique
// revolute joint with a torsion spring: theta'' = -k / (I + m L^2) theta,
// exactly, so its centre swings with period 2 pi sqrt((I + m L^2) / k) in the
// plane across the axis, and the energy (the spring's included) stays.
TEST(Dynamics, AHingedArmSwingsWithTheTorsionPendulumsPeriod) {
  const double m = 2, inertia = 0.01, arm = 0.2, k = 5;
  const std::string scene = R"({
    "gravity": [0, 0, 0], "duration": 3, "output_interval": 0.001,
    "integrator": {"type": "runge-kutta-merson", "accuracy": 1e-9},
    "bodies": [
      {"name": "base", "mass": 1e9, "inertia": [1e9, 1e9, 1e9]},
      {"name": "arm", "mass": 2, "inertia": [0.01, 0.01, 0.01],
       "joint": {"type": "revolute", "parent": "base", "point_in_parent": [0, 0, 0], "point_in_child": [-0.2, 0, 0],
                 "axis": [0, 1, 1], "stiffness": 5, "angle_deg": 10}}]})";
  const auto columns = readColumns(simulateInto(scene, "hinged_arm") / "trajectory.csv");
  // The arm's centre along the swing's tangent at rest, (axis x x) / |...|: proportional to sin(theta).
  const Vector3d tangent = Vector3d(0, 1, 1).normalized().cross(Vector3d::UnitX());
  const auto& t = columns.at("time_s");
  std::vector<double> along(t.size());
  for (size_t i = 0; i < t.size(); ++i)
    along[i] = tangent.dot(Vector3d(columns.at("arm_x_m")[i], columns.at("arm_y_m")[i], columns.at("arm_z_m")[i]));
  const double period = periodFromZeroCrossings(t, along, 6);
  const double expected = 2 * M_PI * std::sqrt((inertia + m * arm * arm) / k);
  EXPECT_NEAR(period, expected, 1e-4 * expected);
  const auto& energy = columns.at("total_j");
  EXPECT_GT(energy.front(), 0);  // the spring's, at 10 degrees
  EXPECT_NEAR(energy.back(), energy.front(), 1e-6 * energy.front());
}

// A box on four contact points at its bottom corners: each carries a quarter
// of the weight, K d^1.5 = m g / 4.
TEST(Dynamics, ABoxOnFourContactPointsRestsAtTheirHertzDepth) {
  const double m = 2, K = 1e5, half_height = 0.05;
  std::string contacts;
  for (const char* corner : {"[0.1, 0.05, -0.05]", "[0.1, -0.05, -0.05]", "[-0.1, 0.05, -0.05]", "[-0.1, -0.05, -0.05]"})
    contacts += std::string(contacts.empty() ? "" : ",") + R"({"body": "box", "point": )" + corner +
                R"(, "against": {"plane": {"normal": [0, 0, 1]}},
                "normal_law": {"law": "hunt-crossley", "stiffness": 1e5, "dissipation": 20},
                "friction": {"dynamic": 0.5}})";
  const std::string scene = R"({"duration": 3, "output_interval": 0.5,
    "integrator": {"type": "runge-kutta-merson", "accuracy": 1e-10},
    "bodies": [{"name": "box", "mass": 2, "inertia": [0.004, 0.008, 0.01], "position": [0, 0, 0.051]}],
    "contacts": [)" + contacts + "]}";
  const auto columns = readColumns(simulateInto(scene, "box_on_points") / "trajectory.csv");
  const double depth = half_height - columns.at("box_z_m").back();
  const double hertz = std::pow(m * kGravity / (4 * K), 2.0 / 3.0);
  EXPECT_NEAR(depth, hertz, 1e-6 * hertz);
  EXPECT_NEAR(columns.at("box_x_m").back(), 0, 1e-9);  // symmetric: no drift
}

// An ellipsoidal cavity of equal radii is the spherical one: the closest
// point's geometry gives the same contact as the closed form, to rounding.
TEST(Dynamics, AnEllipsoidalCavityOfEqualRadiiIsTheSphericalOne) {
  const double m = 1.0, r = 0.1, R = 1.0;
  const auto path = [&](bool ellipsoidal) {
    BallWorld w(m, 0.4 * m * r * r);
    CompliantContact contact(w.forces);
    const ContactLaws laws = hertzLaws(1e7, NormalLaw::HuntCrossley, 0.5, 0.3);
    if (ellipsoidal)
      contact.addSphereInEllipsoidalCavity(
          w.ball, r, articula::contact::makeConvexShape(Vector3d(0, 0, R), Eigen::Matrix3d::Identity(), Vector3d::Constant(R)),
          laws);
    else
      contact.addSphereInCavity(w.ball, r, Vector3d(0, 0, R), R, laws);
    SimTK::State state = w.start();
    w.ball.setQToFitTranslation(state, SimTK::Vec3(0.5, 0.2, 0.3));
    w.ball.setUToFitVelocity(state, SimTK::SpatialVec(SimTK::Vec3(0, 3, 1), SimTK::Vec3(0.5, -1, 0)));
    Simulation run(w.system, state, 1e-8);
    std::vector<SimTK::Vec3> out;
    for (int i = 1; i <= 20; ++i) out.push_back(w.ball.getBodyOriginLocation(run.stepTo(0.05 * i)));
    return out;
  };
  const std::vector<SimTK::Vec3> sphere = path(false), ellipsoid = path(true);
  for (size_t i = 0; i < sphere.size(); ++i) EXPECT_LT((sphere[i] - ellipsoid[i]).norm(), 1e-7) << i;
}

// A ball rolling without slip at the bottom of an ellipsoidal bowl (semi-axes
// A, B, C, the bottom at the end of C) along A: the bottom's radius of
// curvature in that plane is rho = A^2 / C, and small oscillations have the
// period 2 pi sqrt(7 (rho - r) / (5 g)).
TEST(Dynamics, ABallRollingInAnEllipsoidalBowlOscillatesWithItsCurvature) {
  const double m = 1.0, r = 0.1, A = 1.2, B = 1.0, C = 1.0, K = 1e7;
  BallWorld w(m, 0.4 * m * r * r);
  CompliantContact contact(w.forces);
  ContactLaws laws = hertzLaws(K, NormalLaw::HuntCrossley, 0.1, 0.5);
  contact.addSphereInEllipsoidalCavity(
      w.ball, r, articula::contact::makeConvexShape(Vector3d(0, 0, C), Eigen::Matrix3d::Identity(), Vector3d(A, B, C)),
      laws);
  SimTK::State state = w.start();
  // Touching the wall (at the Hertz sag) at x = 0.06 on the bowl's x-z section.
  const double x0 = 0.06, z0 = C - C * std::sqrt(1 - x0 * x0 / (A * A));
  const Vector3d inward = -Vector3d(x0 / (A * A), 0, (z0 - C) / (C * C)).normalized();
  const Vector3d start = Vector3d(x0, 0, z0) + (r - std::pow(m * kGravity / K, 2.0 / 3.0)) * inward;
  w.ball.setQToFitTranslation(state, SimTK::Vec3(start.x(), start.y(), start.z()));
  Simulation run(w.system, state, 1e-8);
  std::vector<double> t, x;
  sampleX(w, run, 3.6, t, x);
  const double period = periodFromZeroCrossings(t, x, 3);
  const double rho = A * A / C, rolling = 2 * M_PI * std::sqrt(7.0 * (rho - r) / (5.0 * kGravity));
  EXPECT_NEAR(period, rolling, 0.005 * rolling) << "the sphere of radius C would give "
                                                << 2 * M_PI * std::sqrt(7.0 * (C - r) / (5.0 * kGravity)) << " s";
  EXPECT_THROW(contact.addSphereInEllipsoidalCavity(
                   w.ball, 0.9, articula::contact::makeConvexShape(Vector3d::Zero(), Eigen::Matrix3d::Identity(), Vector3d(A, B, C)),
                   laws),
               articula::InvalidParameter);  // tighter than the ball at the ends of A
}

// No gravity, no friction: a ball meeting a plane at v0 leaves it at e v0,
// e the exact restitution of Hunt-Crossley damping (force_laws.hpp).
TEST(Dynamics, ADroppedBallReboundsWithTheLawsRestitution) {
  const double v0 = 1.0, c = 0.4;
  const std::string scene = R"({"gravity": [0, 0, 0], "duration": 0.05, "output_interval": 0.05,
    "integrator": {"type": "runge-kutta-merson", "accuracy": 1e-11},
    "bodies": [{"name": "ball", "mass": 0.5, "inertia": [5e-4, 5e-4, 5e-4], "position": [0, 0, 0.0501], "velocity": [0, 0, -1]}],
    "contacts": [{"body": "ball", "shape": {"model": "sphere", "radii": [0.05, 0.05, 0.05]},
                  "against": {"plane": {"normal": [0, 0, 1]}},
                  "normal_law": {"law": "hunt-crossley", "stiffness": 1e7, "dissipation": 0.4}}]})";
  const auto columns = readColumns(simulateInto(scene, "rebound") / "trajectory.csv");
  const double e = columns.at("ball_vz_m_s").back() / v0;
  const double expected = articula::contact::restitutionOfLinearDamping(1.5 * c * v0);
  EXPECT_LT(expected, 0.9);  // a real loss
  EXPECT_NEAR(e, expected, 1e-6);
}

// A contact surface taken from a fits.json (millimetres, as the fit writes
// them): the fitted sphere of 25 mm, centred on its body, rests on a plane
// at the Hertz depth of a 0.025 m ball; a model the file lacks is refused.
TEST(Dynamics, AFittedHeadFromFitsJsonIsAContactSurfaceInMetres) {
  const std::filesystem::path folder = std::filesystem::path(::testing::TempDir()) / "fitted_head";
  std::filesystem::create_directories(folder);
  std::ofstream(folder / "fits.json") << R"({"models": [{"model": "sphere", "center_mm": [10, 20, 30],
    "radii_mm": [25, 25, 25], "rotation_deg": [0, 0, 0], "exponents": [2, 2, 2], "cx": [1, 0, 0, 0], "cy": [1, 0, 0, 0]}]})";
  const double m = 1, K = 1e6, r = 0.025;
  const auto scene = [&](const std::string& model) {
    return nlohmann::json::parse(R"({"duration": 2, "output_interval": 0.5,
      "integrator": {"type": "runge-kutta-merson", "accuracy": 1e-10},
      "bodies": [{"name": "head", "mass": 1, "inertia": [2.5e-4, 2.5e-4, 2.5e-4], "position": [0, 0, 0.026]}],
      "contacts": [{"body": "head", "shape": {"model": ")" + model + R"(", "fits": "fits.json", "center": [0, 0, 0]},
                    "against": {"plane": {"normal": [0, 0, 1]}},
                    "normal_law": {"law": "hunt-crossley", "stiffness": 1e6, "dissipation": 20}}]})");
  };
  const articula::dynamics::Scene read = articula::dynamics::sceneFromJson(scene("sphere"), "scene", folder);
  ASSERT_EQ(read.contacts.size(), 1u);
  EXPECT_DOUBLE_EQ(read.contacts[0].shape.radii[0], r);
  articula::dynamics::simulateScene(read, folder);
  const auto columns = readColumns(folder / "trajectory.csv");
  const double depth = r - columns.at("head_z_m").back();
  const double hertz = std::pow(m * kGravity / K, 2.0 / 3.0);
  EXPECT_NEAR(depth, hertz, 1e-6 * hertz);
  EXPECT_THROW(articula::dynamics::sceneFromJson(scene("ellipsoid"), "scene", folder), articula::InputError);
}

// A misspelt or stray key is refused with its place in the scene: left
// alone, "disipation" would have meant no damping at all.
TEST(Dynamics, UnknownSceneKeysAreRefusedByTheirPlace) {
  const nlohmann::json ball = nlohmann::json::parse(R"({
    "description": "a ball in a bowl", "gravity": [0, 0, -9.81], "duration": 1,
    "bodies": [{"name": "ball", "mass": 1.0, "inertia": [0.01, 0.01, 0.01], "position": [0.9, 0, 1.0]}],
    "contacts": [{"body": "ball", "shape": {"model": "sphere", "radii": [0.1, 0.1, 0.1]},
                  "against": {"cavity": {"center": [0, 0, 1.0], "radius": 1.0}},
                  "normal_law": {"law": "hunt-crossley", "stiffness": 1e8, "dissipation": 0.1},
                  "friction": {"dynamic": 0.01}}]})");
  EXPECT_NO_THROW(articula::dynamics::sceneFromJson(ball, "scene"));
  const std::vector<std::pair<std::string, std::string>> strays = {
      {"/gravty", "scene: unknown key \"gravty\""},
      {"/output_intervall", "scene: unknown key \"output_intervall\""},
      {"/bodies/0/velocty", "scene bodies[0]: unknown key \"velocty\""},
      {"/bodies/0/colour", "scene bodies[0]: unknown key \"colour\""},
      {"/contacts/0/normal_law/disipation", "normal_law (hunt-crossley): unknown key \"disipation\""},
      {"/contacts/0/normal_law/restitution", "normal_law (hunt-crossley): unknown key \"restitution\""},
      {"/contacts/0/friction/statc", "friction: unknown key \"statc\""},
      {"/contacts/0/shape/radius", "shape: unknown key \"radius\""},
      {"/contacts/0/against/cavity/radii_mm", "against cavity: unknown key \"radii_mm\""}};
  for (const auto& [pointer, message] : strays) {
    nlohmann::json scene = ball;
    scene[nlohmann::json::json_pointer(pointer)] = 1;
    try {
      articula::dynamics::sceneFromJson(scene, "scene");
      ADD_FAILURE() << pointer << " was accepted";
    } catch (const articula::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
    }
  }
  nlohmann::json described = ball;
  described["description"] = nlohmann::json::array({1, 2});
  EXPECT_THROW(articula::dynamics::sceneFromJson(described, "scene"), articula::InputError);
}

}  // namespace
