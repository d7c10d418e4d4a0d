#pragma once
// A free rigid ball under gravity (-z, 9.81 m/s^2) in a Simbody system, and
// a Runge-Kutta-Merson run over it: the scene the dynamics tests and
// benchmarks share (SI units).
#include <Simbody.h>

namespace articula::testsupport {

constexpr double kGravity = 9.81;

struct BallWorld {
  SimTK::MultibodySystem system;
  SimTK::SimbodyMatterSubsystem matter{system};
  SimTK::GeneralForceSubsystem forces{system};
  SimTK::Force::Gravity gravity{forces, matter, -SimTK::ZAxis, kGravity};
  SimTK::MobilizedBody::Free ball;

  BallWorld(double mass, double inertia) : BallWorld(mass, SimTK::Vec3(inertia)) {}

  /// A body of any principal moments (an ellipsoid's, say) about its body axes.
  BallWorld(double mass, const SimTK::Vec3& principal_moments)
      : ball(matter.Ground(), SimTK::Transform(),
             SimTK::Body::Rigid(SimTK::MassProperties(mass, SimTK::Vec3(0), SimTK::Inertia(principal_moments))),
             SimTK::Transform()) {}

  /// The default state once every force is added.
  SimTK::State start() {
    system.realizeTopology();
    return system.getDefaultState();
  }
};

/// Runge-Kutta-Merson at `accuracy` from `state`; the caller steps it.
struct Simulation {
  SimTK::RungeKuttaMersonIntegrator integrator;
  SimTK::TimeStepper stepper;
  Simulation(const SimTK::MultibodySystem& system, const SimTK::State& state, double accuracy)
      : integrator(system), stepper(system, integrator) {
    integrator.setAccuracy(accuracy);
    stepper.initialize(state);
  }
  const SimTK::State& stepTo(double time) {
    stepper.stepTo(time);
    return integrator.getState();
  }
};

}  // namespace articula::testsupport
