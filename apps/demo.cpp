// `articula demo -o OUTDIR`: the embedded default. Makes a synthetic hip CT
// whose femoral head has a known shape (articula phantom), runs the whole
// pipeline on its DICOM series (articula run), and prints the five models
// against the truth.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "articula/cli/command.hpp"
#include "articula/core/json_file.hpp"
#include "articula/core/atomic_file.hpp"
#include "articula/core/error.hpp"
#include "articula/core/log.hpp"

namespace articula::apps {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

json readJson(const fs::path& path) {
  if (!fs::exists(path)) throw ProcessingError("expected '" + path.string() + "' to exist after the previous step");
  return readJsonFile(path, "demo");
}

Eigen::Vector3d vec(const json& j) { return {j.at(0).get<double>(), j.at(1).get<double>(), j.at(2).get<double>()}; }

class DemoCommand : public cli::Command {
 public:
  std::string name() const override { return "demo"; }
  bool holdsVolumes() const override { return true; }
  std::string description() const override {
    return "Make a synthetic hip CT with a femoral head of known shape, run the pipeline on it, compare with the truth";
  }
  std::string example() const override { return "articula demo -o out/demo --model superellipsoid --seed 7"; }
  void declare(CLI::App& app) override {
    app.add_option("-o,--output", output_, "Output folder: phantom/, run/, demo.json")->required();
    app.add_option("--model", model_, "True head shape (default: chosen by the seed)");
  }

  int run(const cli::CommonOptions& common) override {
    const std::string seed = std::to_string(common.seed), threads = std::to_string(common.threadCount());
    const fs::path phantom = output_ / "phantom", run_dir = output_ / "run";
    std::vector<std::string> phantom_args = {"-o", phantom.string(), "--seed", seed, "--force"};
    if (!model_.empty()) phantom_args.insert(phantom_args.end(), {"--model", model_});
    if (common.verbosity == 0) phantom_args.push_back("--quiet");
    if (int rc = cli::runCommandInProcess("phantom", phantom_args)) return rc;
    const json truth = readJson(phantom / "truth.json");
    std::vector<std::string> run_args = {"-i", (phantom / "dicom").string(), "-o", run_dir.string(), "--joint", "hip",
                                         "--side", truth.value("side", "right"), "--seed", seed, "--threads", threads};
    if (common.force) run_args.push_back("--force");
    if (common.verbosity == 0) run_args.push_back("--quiet");
    if (int rc = cli::runCommandInProcess("run", run_args)) return rc;
    const json results = readJson(run_dir / "results.json");

    const Eigen::Vector3d true_center = vec(truth.at("head_center_mm"));
    std::ostringstream table;
    char line[256];
    std::snprintf(line, sizeof line, "true head: %s, radii %.2f %.2f %.2f mm, centre (%.2f, %.2f, %.2f) mm LPS\n",
                  truth.at("model").get<std::string>().c_str(), truth.at("radii_mm")[0].get<double>(),
                  truth.at("radii_mm")[1].get<double>(), truth.at("radii_mm")[2].get<double>(), true_center[0],
                  true_center[1], true_center[2]);
    table << line;
    std::snprintf(line, sizeof line, "%-15s %9s %9s %9s %9s %7s %12s\n", "model", "rms_mm", "a_mm", "b_mm", "c_mm",
                  "n_eff", "centre_err_mm");
    table << line;
    json rows = json::array();
    const std::string selected = results.value("selected_model", ""), least = results.value("least_rms_model", "");
    for (const auto& m : results.at("models")) {
      const auto& p = m.at("parameters");
      const double a = p.at("a_mm"), b = p.value("b_mm", a), c = p.value("c_mm", a);
      const Eigen::Vector3d center(p.at("t1_mm"), p.at("t2_mm"), p.at("t3_mm"));
      const double centre_error = (center - true_center).norm();
      const double rms = m.at("errors").value("rms_mm", NAN);
      const std::string name = m.at("model").get<std::string>();
      const double n_eff = m.contains("residual_correlation") ? m.at("residual_correlation").value("n_eff", NAN) : NAN;
      // The one model results.json selects; the least RMS named only where it is another.
      const std::string mark = name == selected ? "  <- selected" : name == least ? "  (least RMS, not selected)" : "";
      std::snprintf(line, sizeof line, "%-15s %9.4f %9.3f %9.3f %9.3f %7.0f %12.3f%s\n", name.c_str(), rms, a, b, c,
                    n_eff, centre_error, mark.c_str());
      table << line;
      rows.push_back({{"model", m.at("model")}, {"rms_mm", rms}, {"radii_mm", {a, b, c}}, {"center_error_mm", centre_error}});
    }
    if (common.verbosity > 0) std::fputs(table.str().c_str(), stderr);
    const json demo = {{"truth", truth}, {"selected_model", selected}, {"least_rms_model", least}, {"models", rows},
                       {"coordinate_system", "LPS"}, {"units", "mm"}};
    writeFileAtomically(output_ / "demo.json", demo.dump(2) + "\n");
    if (common.json) cli::printJson(demo);
    return 0;
  }

 private:
  fs::path output_;
  std::string model_;
};

ARTICULA_REGISTER_COMMAND(DemoCommand)

}  // namespace
}  // namespace articula::apps
