#pragma once
// Runs a scene (scene.hpp) on Simbody with articula's compliant contact and
// writes, into a folder: trajectory.csv (every body's position, orientation
// quaternion, velocities, and the system's energies, at each output time),
// contacts.csv (each contact's depth, normal and friction forces and point)
// and steps.csv (every internal integrator step); the summary, and the
// series a caller draws (each body's height, each contact's force, the step
// sizes), are returned for the caller to write with its provenance.
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "articula/dynamics/scene.hpp"

namespace articula::dynamics {

struct SimulationSummary {
  double simulated_seconds = 0;
  double wall_seconds = 0;
  long long steps = 0;
  double mean_step = 0, min_step = 0, max_step = 0;  // s
  long long contact_evaluations = 0;
  long long output_rows = 0;
  double energy_start = 0, energy_end = 0;  // kinetic + gravitational + elastic contact, J
  nlohmann::json toJson() const;
};

/// One quantity over time; NaN where it is undefined (a contact apart).
struct TimeSeries {
  std::string label;
  std::vector<double> t, value;
};

/// What a simulation's figures show: each body's height along -gravity at
/// every output time, each contact's normal force, every step's size.
struct SimulationSeries {
  std::vector<TimeSeries> heights, normal_forces;
  TimeSeries step_sizes{"step", {}, {}};
};

/// The tables simulateScene writes into its folder, in this order.
const std::vector<std::string>& simulationOutputs();

/// Simulates `scene` and writes the tables into `folder` (which must exist);
/// `progress(t)` is called at every output time; `series`, when given,
/// receives what the figures show.
SimulationSummary simulateScene(const Scene& scene, const std::filesystem::path& folder,
                                const std::function<void(double)>& progress = {}, SimulationSeries* series = nullptr);

}  // namespace articula::dynamics
