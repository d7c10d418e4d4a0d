// `articula fit` / articula-fit: fits the hierarchy sphere -> ellipsoid ->
// {superellipsoid, ovoid} -> superovoid to a point file and writes fits.json
// (the contract read by errors and contact) and fits.csv beside it.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <sstream>

#include "articula/cli/command.hpp"
#include "articula/core/json_file.hpp"
#include "articula/core/atomic_file.hpp"
#include "articula/core/error.hpp"
#include "articula/core/excerpt.hpp"
#include "articula/core/output_paths.hpp"
#include "articula/core/log.hpp"
#include "articula/core/provenance.hpp"
#include "articula/fit/fit_hierarchy.hpp"
#include "articula/fit/fits_json.hpp"
#include "articula/points/point_io.hpp"

namespace articula::apps {
namespace {

using geometry::ShapeModel;

// --bounds FILE: {"a": [lo, hi], "gamma1": [2, 3], ...} (names of thesis table 3.2).
std::map<std::string, std::pair<double, double>> readBounds(const std::filesystem::path& path) {
  const nlohmann::json j = readJsonFile(path, "--bounds");
  if (!j.is_object()) throw InputError("--bounds: '" + path.string() + "': expected an object of name: [lower, upper]");
  std::map<std::string, std::pair<double, double>> bounds;
  for (const auto& [name, v] : j.items()) {
    if (!v.is_array() || v.size() != 2 || !v[0].is_number() || !v[1].is_number())
      throw InputError("--bounds: '" + path.string() + "': \"" + name + "\" expected [lower, upper], found " + describeJson(v));
    bounds[name] = {v[0].get<double>(), v[1].get<double>()};
  }
  return bounds;
}

std::string fitsCsv(const fit::Summary& s) {
  // Standard errors after the values, one per parameter of the superovoid
  // (the widest model), in the values' units; empty where a model lacks the
  // parameter or the points cannot identify it.
  const auto all_names = geometry::parameterNames(ShapeModel::Superovoid);
  const auto all_kinds = geometry::parameterKinds(ShapeModel::Superovoid);
  std::ostringstream out;
  out << "model,a_mm,b_mm,c_mm,gamma1,gamma2,gamma3,c0x,c1x,c2x,c3x,c0y,c1y,c2y,c3y,t1_mm,t2_mm,t3_mm,"
         "phi_deg,theta_deg,psi_deg,rms_mm,sse_mm2,algebraic_objective,evaluations,seconds,converged";
  for (size_t k = 0; k < all_names.size(); ++k) {
    const std::string unit = all_kinds[k] == geometry::ParameterKind::Angle ? "deg" : geometry::parameterUnit(all_kinds[k]);
    out << ',' << all_names[k] << "_se" << (unit.empty() ? "" : "_" + unit);
  }
  out << "\n" << std::setprecision(12);
  for (const auto& f : s.fits) {
    const auto& p = f.parameters;
    const Eigen::Vector3d r = p.model == ShapeModel::Sphere ? Eigen::Vector3d::Constant(p.radii[0]) : p.radii;
    const Eigen::Vector3d deg = p.angles * (180.0 / M_PI);
    out << geometry::modelName(p.model);
    for (double v : {r[0], r[1], r[2], p.exponents[0], p.exponents[1], p.exponents[2], p.cx[0], p.cx[1], p.cx[2],
                     p.cx[3], p.cy[0], p.cy[1], p.cy[2], p.cy[3], p.center[0], p.center[1], p.center[2], deg[0],
                     deg[1], deg[2], f.rms_mm, f.sse_mm2, f.algebraic_objective})
      out << ',' << v;
    out << ',' << f.evaluations << ',' << f.seconds << ',' << (f.converged ? "true" : "false");
    const auto names = geometry::parameterNames(p.model);
    for (size_t k = 0; k < all_names.size(); ++k) {
      out << ',';
      const auto at = std::find(names.begin(), names.end(), all_names[k]);
      if (at == names.end() || f.uncertainty.standard_error.size() != static_cast<Eigen::Index>(names.size())) continue;
      const double se = f.uncertainty.standard_error[at - names.begin()];
      if (std::isfinite(se)) out << (all_kinds[k] == geometry::ParameterKind::Angle ? se * 180.0 / M_PI : se);
    }
    out << "\n";
  }
  return out.str();
}

class FitCommand : public cli::Command {
 public:
  std::string name() const override { return "fit"; }
  std::string description() const override {
    return "Fit sphere, ellipsoid, superellipsoid, ovoid and superovoid to points (fits.json + fits.csv)";
  }
  std::string example() const override { return "articula-fit -i head.ply -o fits.json --seed 42"; }
  void declare(CLI::App& app) override {
    app.add_option("-i,--input", input_, "Points (.ply, .csv/.xyz/.txt, or the vertices of .stl/.obj/.vtp), LPS mm")
        ->required();
    app.add_option("-o,--output", output_, "fits.json (fits.csv is written beside it)")->required();
    app.add_option("--models", models_, "Comma-separated models to report")->delimiter(',')->capture_default_str();
    app.add_option("--objective", objective_, "geometric (orthogonal distances) or algebraic (thesis eq. 3.1)")
        ->capture_default_str();
    app.add_option("--strategy", strategy_, "local (from the hierarchical start) or global-local (GN_CRS2_LM first)")
        ->capture_default_str();
    app.add_option("--local-algorithm", local_algorithm_, "Local method: LM (Levenberg-Marquardt on the residuals) or NLopt's LD_SLSQP, LN_BOBYQA, LD_LBFGS, LD_MMA")
        ->capture_default_str();
    app.add_option("--max-evaluations", max_evaluations_, "Evaluation cap per local run")->capture_default_str();
    app.add_option("--sample-points", sample_points_,
                   "More points than this: fit on a seeded random sample of this many, then finish on all (0 = always all)")
        ->check(CLI::Range(0, 100000000))
        ->capture_default_str();
    app.add_option("--bounds", bounds_file_, "JSON of parameter bounds overrides, e.g. {\"gamma1\": [2, 3]}");
  }

  int run(const cli::CommonOptions& common) override {
    fit::Options o;
    o.models.clear();
    for (const auto& m : models_) o.models.push_back(geometry::modelFromName(m));
    o.objective = fit::objectiveFromName(objective_);
    o.strategy = fit::strategyFromName(strategy_);
    o.local_algorithm = local_algorithm_;
    o.max_evaluations = max_evaluations_;
    o.sample_points = sample_points_;
    o.seed = static_cast<unsigned>(common.seed);
    if (!bounds_file_.empty()) o.bounds = readBounds(bounds_file_);
    o.validate();
    if (output_.extension() != ".json") throw UsageError("--output: expected a .json file, found '" + output_.string() + "'");
    const std::filesystem::path csv = std::filesystem::path(output_).replace_extension(".csv");
    refuseOutputsOverInputs({output_, csv}, {input_, bounds_file_});
    checkOutputTarget(output_);
    cli::refuseExistingOutputs({output_, csv}, common.force);

    const points::PointCloud cloud = points::readPoints(input_);
    points::checkFittable(cloud, geometry::parameterCount(ShapeModel::Superovoid), input_.string());
    log::info("fitting " + std::to_string(cloud.positions.rows()) + " points from " + input_.string());
    const fit::Summary summary = fit::fitHierarchy(cloud.positions, o);
    // One line by default; each model's start and termination with -v.
    log::info(summary.briefReport());
    log::debug(summary.fullReport());

    nlohmann::json models = nlohmann::json::array();
    for (const auto& f : summary.fits) models.push_back(fit::modelFitJson(f));
    nlohmann::json params = {{"models", models_},           {"objective", objective_},
                             {"strategy", strategy_},       {"local_algorithm", local_algorithm_},
                             {"max_evaluations", max_evaluations_}, {"sample_points", sample_points_}, {"bounds", nlohmann::json(o.bounds)}};
    nlohmann::json doc = {{"coordinate_system", "LPS"},
                          {"units", "mm"},
                          {"input", input_.string()},
                          {"n_points", cloud.positions.rows()},
                          {"objective", objective_},
                          {"least_rms_model", summary.best_model},
                          {"seconds", summary.seconds},
                          {"models", models},
                          {"provenance", provenanceJson({params, {input_}, common.seed})}};
    if (!bounds_file_.empty()) doc["provenance"] = provenanceJson({params, {input_, bounds_file_}, common.seed});
    writeFileAtomically(output_, doc.dump(2) + "\n", common.force);
    writeFileAtomically(csv, fitsCsv(summary), common.force);
    if (common.json)
      cli::printJson({{"output", output_.string()}, {"csv", csv.string()}, {"least_rms_model", summary.best_model},
                      {"seconds", summary.seconds}});
    return 0;
  }

 private:
  std::filesystem::path input_, output_, bounds_file_;
  std::vector<std::string> models_ = {"sphere", "ellipsoid", "superellipsoid", "ovoid", "superovoid"};
  std::string objective_ = "geometric", strategy_ = "local", local_algorithm_ = fit::Options{}.local_algorithm;
  int max_evaluations_ = fit::Options{}.max_evaluations;
  int sample_points_ = fit::Options{}.sample_points;
};

ARTICULA_REGISTER_COMMAND(FitCommand)

}  // namespace
}  // namespace articula::apps
