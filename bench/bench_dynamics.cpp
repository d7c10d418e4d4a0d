// bench-dynamics: wall time of simulations with articula's compliant contact
// on Simbody, against Simbody's own HuntCrossleyForce on the same scene in
// the same run (a sphere dropped with spin on a plane: it rolls and slides,
// 1 s simulated), and the thesis's ball in a bowl (section 5.2.7: m = 1 kg,
// r = 0.1 m, I = 0.01 kg m^2, R = 1 m, K = 140e6 N/m^1.5, restitution 0.9,
// Coulomb friction 0.01), 10 s simulated; an ellipsoid dropped with spin on
// a plane against Simbody's CompliantContactSubsystem (its elliptical Hertz
// generator); the three-segment foot of scenes/ with 6 surface elements
// against 31 point elements (the thesis's table 6.1), read and run as
// `articula simulate` does. Runge-Kutta-Merson at accuracy 1e-6 (the foot:
// the argument's 1e-4 or 1e-5). Counters: integrator steps, mean (and
// minimum) step (s), contact evaluations.
#include <cmath>
#include <filesystem>
#include <memory>
#include <string>

#include <benchmark/benchmark.h>
#include <Simbody.h>

#include "articula/contact/convex_shape.hpp"
#include "articula/dynamics/compliant_contact.hpp"
#include "articula/dynamics/scene.hpp"
#include "articula/dynamics/simulate.hpp"
#include "articula/testsupport/ball_world.hpp"

namespace {

using articula::dynamics::CompliantContact;
using articula::dynamics::ContactLaws;
using Eigen::Vector3d;

using articula::testsupport::BallWorld;
using articula::testsupport::Simulation;

struct Run {
  int steps = 0;
  double simulated = 0;
  long long contact_evaluations = 0;
};

struct Scene : BallWorld {
  using BallWorld::BallWorld;
  std::unique_ptr<CompliantContact> contact;

  // articula's element: an axis-aligned ellipsoid of `radii` at the body's origin on the plane z = 0.
  void addOnGround(const Vector3d& radii, const ContactLaws& laws) {
    contact = std::make_unique<CompliantContact>(forces);
    contact->addShapeOnPlane(ball, articula::contact::makeConvexShape(Vector3d::Zero(), Eigen::Matrix3d::Identity(), radii),
                             Vector3d::Zero(), Vector3d::UnitZ(), laws);
  }

  Run simulate(const SimTK::State& state, double duration) {
    Simulation run(system, state, 1e-6);
    run.stepTo(duration);
    return {run.integrator.getNumStepsTaken(), duration, contact ? contact->counters().evaluations : 0};
  }
};

// The sphere-on-plane scene of the dynamics test (E = 1e8 per surface).
constexpr double kMass = 1.0, kRadius = 0.05, kSurfaceModulus = 1e8, kDissipation = 0.5, kStatic = 0.6, kDynamic = 0.4,
                 kTransition = 0.01;

SimTK::State sphereOnPlaneStart(Scene& scene) {
  SimTK::State state = scene.start();
  scene.ball.setQToFitTranslation(state, SimTK::Vec3(0, 0, kRadius + 0.01));
  scene.ball.setUToFitVelocity(state, SimTK::SpatialVec(SimTK::Vec3(0, 20, 3), SimTK::Vec3(1.0, 0.2, 0)));
  return state;
}

// The material of the plane scenes with a Hertz stiffness K (Simbody's peers take the modulus).
ContactLaws planeLaws(double stiffness) {
  ContactLaws laws;
  laws.normal.law = articula::contact::NormalLaw::HuntCrossley;
  laws.normal.stiffness = stiffness;
  laws.normal.dissipation = kDissipation;
  laws.friction.dynamic = kDynamic;
  laws.friction.static_peak = kStatic;
  laws.friction.transition_speed = kTransition;
  return laws;
}

void report(benchmark::State& state, const Run& run) {
  state.counters["steps"] = run.steps;
  state.counters["mean_step_s"] = run.simulated / run.steps;
  state.counters["contact_evaluations"] = static_cast<double>(run.contact_evaluations);
}

void BM_SphereOnPlane_Articula(benchmark::State& state) {
  Run run;
  for (auto _ : state) {
    Scene scene(kMass, 0.4 * kMass * kRadius * kRadius);
    scene.addOnGround(Vector3d::Constant(kRadius),
                      planeLaws(4.0 / 3.0 * std::sqrt(kRadius) * kSurfaceModulus / std::pow(2.0, 1.5)));
    run = scene.simulate(sphereOnPlaneStart(scene), 1.0);
  }
  report(state, run);
}
BENCHMARK(BM_SphereOnPlane_Articula)->Unit(benchmark::kMillisecond);

void BM_SphereOnPlane_SimbodyHuntCrossley(benchmark::State& state) {
  Run run;
  for (auto _ : state) {
    Scene scene(kMass, 0.4 * kMass * kRadius * kRadius);
    SimTK::GeneralContactSubsystem contacts(scene.system);
    const SimTK::ContactSetIndex set = contacts.createContactSet();
    contacts.addBody(set, scene.ball, SimTK::ContactGeometry::Sphere(kRadius), SimTK::Transform());
    contacts.addBody(set, scene.matter.updGround(), SimTK::ContactGeometry::HalfSpace(),
                     SimTK::Transform(SimTK::Rotation(0.5 * SimTK::Pi, SimTK::YAxis), SimTK::Vec3(0)));
    SimTK::HuntCrossleyForce hc(scene.forces, contacts, set);
    for (int i = 0; i < 2; ++i)
      hc.setBodyParameters(SimTK::ContactSurfaceIndex(i), kSurfaceModulus, kDissipation, kStatic, kDynamic, 0);
    hc.setTransitionVelocity(kTransition);
    run = scene.simulate(sphereOnPlaneStart(scene), 1.0);
  }
  report(state, run);
}
BENCHMARK(BM_SphereOnPlane_SimbodyHuntCrossley)->Unit(benchmark::kMillisecond);

// The thesis's ball, released touching the bowl's wall at the height of the
// bowl's centre, spinning at 9 rad/s about y. Hunt-Crossley dissipation for
// restitution 0.9 at 1 m/s; friction regularised over 1 mm/s.
void BM_BallInBowl_Thesis(benchmark::State& state) {
  Run run;
  for (auto _ : state) {
    const double m = 1.0, r = 0.1, R = 1.0;
    Scene scene(m, 0.01);
    ContactLaws laws;
    laws.normal.law = articula::contact::NormalLaw::HuntCrossley;
    laws.normal.stiffness = 140e6;
    laws.normal.dissipation = articula::contact::huntCrossleyDissipation(0.9, 1.0);
    laws.friction.dynamic = 0.01;
    laws.friction.transition_speed = 1e-3;
    scene.contact = std::make_unique<CompliantContact>(scene.forces);
    scene.contact->addSphereInCavity(scene.ball, r, Vector3d(0, 0, R), R, laws);
    SimTK::State start = scene.start();
    scene.ball.setQToFitTranslation(start, SimTK::Vec3(R - r, 0, R));
    scene.ball.setUToFitAngularVelocity(start, SimTK::Vec3(0, 9.0, 0));
    run = scene.simulate(start, 10.0);
  }
  report(state, run);
}
BENCHMARK(BM_BallInBowl_Thesis)->Unit(benchmark::kMillisecond);

// An ellipsoid (semi-axes 6, 5 and 4 cm) dropped on its shortest axis with
// spin and forward speed: it bounces, rolls and slides. articula's element
// takes the Hertz stiffness of the pole's curvatures; Simbody's generator
// recomputes it from the curvatures at each contact.
constexpr double kEggMass = 1.0, kEggA = 0.06, kEggB = 0.05, kEggC = 0.04;

SimTK::Vec3 eggMoments() {
  return {0.2 * kEggMass * (kEggB * kEggB + kEggC * kEggC), 0.2 * kEggMass * (kEggA * kEggA + kEggC * kEggC),
          0.2 * kEggMass * (kEggA * kEggA + kEggB * kEggB)};
}

SimTK::State eggStart(Scene& scene) {
  SimTK::State state = scene.start();
  scene.ball.setQToFitTranslation(state, SimTK::Vec3(0, 0, kEggC + 0.01));
  scene.ball.setUToFitVelocity(state, SimTK::SpatialVec(SimTK::Vec3(2, 5, 10), SimTK::Vec3(1.0, 0.2, 0)));
  return state;
}

void BM_EllipsoidOnPlane_Articula(benchmark::State& state) {
  Run run;
  for (auto _ : state) {
    Scene scene(kEggMass, eggMoments());
    scene.addOnGround(Vector3d(kEggA, kEggB, kEggC),
                      planeLaws(articula::contact::hertzStiffness(kEggC / (kEggA * kEggA), kEggC / (kEggB * kEggB),
                                                                  kSurfaceModulus / std::pow(2.0, 1.5))));
    run = scene.simulate(eggStart(scene), 1.0);
  }
  report(state, run);
}
BENCHMARK(BM_EllipsoidOnPlane_Articula)->Unit(benchmark::kMillisecond);

void BM_EllipsoidOnPlane_SimbodyCompliant(benchmark::State& state) {
  Run run;
  for (auto _ : state) {
    Scene scene(kEggMass, eggMoments());
    SimTK::ContactTrackerSubsystem tracker(scene.system);
    SimTK::CompliantContactSubsystem compliant(scene.system, tracker);
    compliant.setTransitionVelocity(kTransition);
    const SimTK::ContactMaterial material(kSurfaceModulus, kDissipation, kStatic, kDynamic, 0);
    scene.ball.updBody().addContactSurface(
        SimTK::Transform(),
        SimTK::ContactSurface(SimTK::ContactGeometry::Ellipsoid(SimTK::Vec3(kEggA, kEggB, kEggC)), material));
    scene.matter.updGround().updBody().addContactSurface(
        SimTK::Transform(SimTK::Rotation(0.5 * SimTK::Pi, SimTK::YAxis), SimTK::Vec3(0)),
        SimTK::ContactSurface(SimTK::ContactGeometry::HalfSpace(), material));
    run = scene.simulate(eggStart(scene), 1.0);
  }
  report(state, run);
}
BENCHMARK(BM_EllipsoidOnPlane_SimbodyCompliant)->Unit(benchmark::kMillisecond);

// The foot scenes as shipped (1 s simulated), at accuracy 10^-range(0); the
// files go to a scratch folder.
void footScene(benchmark::State& state, const char* sole) {
  articula::dynamics::Scene scene =
      articula::dynamics::readScene(std::filesystem::path(ARTICULA_SCENES_DIR) / (std::string("foot_") + sole + ".json"));
  scene.accuracy = std::pow(10.0, -static_cast<double>(state.range(0)));
  const std::filesystem::path folder = std::filesystem::temp_directory_path() / (std::string("bench-foot-") + sole);
  std::filesystem::create_directories(folder);
  articula::dynamics::SimulationSummary summary;
  for (auto _ : state) summary = articula::dynamics::simulateScene(scene, folder);
  state.counters["steps"] = static_cast<double>(summary.steps);
  state.counters["mean_step_s"] = summary.mean_step;
  state.counters["min_step_s"] = summary.min_step;
  state.counters["contact_evaluations"] = static_cast<double>(summary.contact_evaluations);
  std::filesystem::remove_all(folder);
}
void BM_Foot_Surfaces(benchmark::State& state) { footScene(state, "surfaces"); }
void BM_Foot_Points(benchmark::State& state) { footScene(state, "points"); }
BENCHMARK(BM_Foot_Surfaces)->Arg(4)->Arg(5)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Foot_Points)->Arg(4)->Arg(5)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
