// `articula simulate -i SCENE.json -o DIR`: forward dynamics of rigid bodies
// with articula's compliant contact on Simbody (lib/dynamics). Writes
// trajectory.csv, contacts.csv, steps.csv, their figures and, last,
// summary.json (wall
// time, integrator steps, contact evaluations, energies, provenance): a
// folder without summary.json is unfinished.
#include <cmath>
#include <filesystem>

#include "articula/cli/command.hpp"
#include "articula/core/atomic_file.hpp"
#include "articula/core/error.hpp"
#include "articula/core/log.hpp"
#include "articula/core/output_paths.hpp"
#include "articula/core/provenance.hpp"
#include "articula/dynamics/scene.hpp"
#include "articula/dynamics/simulate.hpp"
#include "articula/report/line_chart_svg.hpp"

namespace articula::apps {
namespace {

namespace fs = std::filesystem;

// The simulation's figures, beside its tables.
const std::vector<std::string> kFigures = {"trajectory.svg", "contact_forces.svg", "steps.svg"};

std::vector<report::LineSeries> lines(const std::vector<dynamics::TimeSeries>& series) {
  std::vector<report::LineSeries> out;
  for (const auto& s : series) out.push_back({s.label, s.t, s.value});
  return out;
}

void writeFigures(const fs::path& folder, const dynamics::SimulationSeries& series) {
  const std::string contents[] = {
      report::lineChartSvg(lines(series.heights), {"Height of each body along -gravity", "time (s)", "height (m)"}),
      report::lineChartSvg(lines(series.normal_forces), {"Normal contact force", "time (s)", "force (N)"}),
      report::lineChartSvg(lines({series.step_sizes}), {"Integrator step sizes", "time (s)", "step (s)", true})};
  for (size_t i = 0; i < kFigures.size(); ++i) writeFileAtomically(folder / kFigures[i], contents[i]);
}

class SimulateCommand : public cli::Command {
 public:
  std::string name() const override { return "simulate"; }
  std::string description() const override {
    return "Simulate rigid bodies with compliant contact (a scene in JSON) on Simbody";
  }
  std::string example() const override { return "articula simulate -i scenes/ball_in_bowl.json -o out/bowl"; }
  void declare(CLI::App& app) override {
    app.add_option("-i,--input", scene_path_, "Scene (.json, docs/formats.md)")->required();
    app.add_option("-o,--output", output_, "Output folder")->required();
  }
  int run(const cli::CommonOptions& common) override {
    const fs::path summary_path = output_ / "summary.json";
    std::vector<fs::path> outputs = {summary_path};
    std::vector<std::string> written = dynamics::simulationOutputs();
    written.insert(written.end(), kFigures.begin(), kFigures.end());
    for (const std::string& name : written) outputs.push_back(output_ / name);
    refuseOutputsOverInputs(outputs, {scene_path_});
    if (!common.force && fs::exists(summary_path))
      throw UsageError("refusing to overwrite " + summary_path.string() + " (use --force)");
    const dynamics::Scene scene = dynamics::readScene(scene_path_);
    checkOutputTarget(summary_path);
    fs::remove(summary_path);  // until the new one is written, the folder is unfinished
    log::info("simulating " + std::to_string(scene.bodies.size()) + " bodies, " + std::to_string(scene.contacts.size()) +
              " contacts, " + std::to_string(scene.duration) + " s");
    dynamics::SimulationSeries series;
    const dynamics::SimulationSummary s = dynamics::simulateScene(
        scene, output_, [&](double t) { log::progress("simulate", t / scene.duration); }, &series);
    writeFigures(output_, series);
    nlohmann::json summary = s.toJson();
    summary["scene"] = scene_path_.string();
    summary["outputs"] = written;
    // The scene by its path and SHA-256 (provenance's inputs), not a copy.
    summary["provenance"] = provenanceJson({{}, {scene_path_}, -1});
    summary["provenance"]["coordinate_system"] = "the scene's (z up when gravity is -z)";
    summary["provenance"]["units"] = "SI: m, kg, s, N";
    writeFileAtomically(summary_path, summary.dump(2) + "\n");
    log::info("simulated " + std::to_string(s.simulated_seconds) + " s in " + std::to_string(s.wall_seconds) + " s wall, " +
              std::to_string(s.steps) + " steps");
    if (common.json) cli::printJson(summary);
    return 0;
  }

 private:
  fs::path scene_path_, output_;
};

ARTICULA_REGISTER_COMMAND(SimulateCommand)

}  // namespace
}  // namespace articula::apps
