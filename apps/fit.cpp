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
#include "articula/pipeline/stage_options_cli.hpp"
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
    pipeline::addStageOptions(app, name(), settings_);
  }

  int run(const cli::CommonOptions& common) override {
    const pipeline::FitSettings& given = settings_.fit();
    fit::Options o;
    o.models.clear();
    for (const auto& m : given.models) o.models.push_back(geometry::modelFromName(m));
    o.objective = fit::objectiveFromName(given.objective);
    o.strategy = fit::strategyFromName(given.strategy);
    o.local_algorithm = given.local_algorithm;
    o.max_evaluations = given.max_evaluations;
    o.sample_points = given.sample_points;
    o.seed = static_cast<unsigned>(common.seed);
    if (!given.bounds.empty()) o.bounds = readBounds(given.bounds);
    o.validate();
    if (output_.extension() != ".json") throw UsageError("--output: expected a .json file, found '" + output_.string() + "'");
    const std::filesystem::path csv = std::filesystem::path(output_).replace_extension(".csv");
    refuseOutputsOverInputs({output_, csv}, {input_, given.bounds});
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
    nlohmann::json params = {{"models", given.models},           {"objective", given.objective},
                             {"strategy", given.strategy},       {"local_algorithm", given.local_algorithm},
                             {"max_evaluations", given.max_evaluations}, {"sample_points", given.sample_points}, {"bounds", nlohmann::json(o.bounds)}};
    nlohmann::json doc = {{"coordinate_system", "LPS"},
                          {"units", "mm"},
                          {"input", input_.string()},
                          {"n_points", cloud.positions.rows()},
                          {"objective", given.objective},
                          {"least_rms_model", summary.best_model},
                          {"seconds", summary.seconds},
                          {"models", models},
                          {"provenance", provenanceJson({params, {input_}, common.seed})}};
    if (!given.bounds.empty()) doc["provenance"] = provenanceJson({params, {input_, given.bounds}, common.seed});
    writeFileAtomically(output_, doc.dump(2) + "\n", common.force);
    writeFileAtomically(csv, fitsCsv(summary), common.force);
    if (common.json)
      cli::printJson({{"output", output_.string()}, {"csv", csv.string()}, {"least_rms_model", summary.best_model},
                      {"seconds", summary.seconds}});
    return 0;
  }

 private:
  std::filesystem::path input_, output_;
  pipeline::StageSettings settings_;
};

ARTICULA_REGISTER_COMMAND(FitCommand)

}  // namespace
}  // namespace articula::apps
