// `articula fit` / articula-fit: fits the hierarchy sphere -> ellipsoid ->
// {superellipsoid, ovoid} -> superovoid to a point file and writes fits.json
// (the contract read by errors and contact) and fits.csv beside it, both
// written by lib/fit (fits_json.hpp, fits_csv.hpp).

#include "articula/cli/command.hpp"
#include "articula/core/json_file.hpp"
#include "articula/core/atomic_file.hpp"
#include "articula/core/error.hpp"
#include "articula/core/excerpt.hpp"
#include "articula/core/output_paths.hpp"
#include "articula/core/log.hpp"
#include "articula/core/provenance.hpp"
#include "articula/fit/fit_hierarchy.hpp"
#include "articula/fit/fits_csv.hpp"
#include "articula/fit/fits_json.hpp"
#include "articula/imaging/io.hpp"
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
    app.add_option("--grid", grid_,
                   "The image the points were found in (the CT or its label, .nii.gz/.nrrd/.mha): its voxels size the "
                   "edge offset over the surface that the intervals add (without: the residuals' part alone)");
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
    o.threads = common.threadCount();
    if (!given.bounds.empty()) o.bounds = readBounds(given.bounds);
    if (!grid_.empty()) {
      const imaging::ImageGeometry grid = imaging::readImageGeometry(grid_);
      o.edge_offset = fit::edgeOffsetField(grid.spacing, grid.direction.col(2));
    }
    o.validate();
    if (output_.extension() != ".json") throw UsageError("--output: expected a .json file, found '" + output_.string() + "'");
    const std::filesystem::path csv = std::filesystem::path(output_).replace_extension(".csv");
    refuseOutputsOverInputs({output_, csv}, {input_, given.bounds, grid_});
    checkOutputTarget(output_);
    cli::refuseExistingOutputs({output_, csv}, common.force);

    const points::PointCloud cloud = points::readPoints(input_);
    points::checkFittable(cloud, geometry::parameterCount(ShapeModel::Superovoid), input_.string());
    log::info("fitting " + std::to_string(cloud.positions.rows()) + " points from " + input_.string());
    const fit::Summary summary = fit::fitHierarchy(cloud.positions, o);
    // One line by default; each model's start and termination with -v.
    log::info(summary.briefReport());
    log::debug(summary.fullReport());

    nlohmann::json params = {{"models", given.models},           {"objective", given.objective},
                             {"strategy", given.strategy},       {"local_algorithm", given.local_algorithm},
                             {"max_evaluations", given.max_evaluations}, {"sample_points", given.sample_points}, {"bounds", nlohmann::json(o.bounds)}};
    std::vector<std::filesystem::path> inputs = {input_};
    if (!given.bounds.empty()) inputs.push_back(given.bounds);
    if (!grid_.empty()) inputs.push_back(grid_);
    const nlohmann::json doc = fit::fitsDocument(summary, input_.string(), given.objective,
                                                 provenanceJson({params, inputs, common.seed, o.threads}));
    writeFileAtomically(output_, doc.dump(2) + "\n", common.force);
    writeFileAtomically(csv, fit::fitsCsv(summary), common.force);
    if (common.json)
      cli::printJson({{"output", output_.string()}, {"csv", csv.string()}, {"least_rms_model", summary.best_model},
                      {"seconds", summary.seconds}});
    return 0;
  }

 private:
  std::filesystem::path input_, output_, grid_;
  pipeline::StageSettings settings_;
};

ARTICULA_REGISTER_COMMAND(FitCommand)

}  // namespace
}  // namespace articula::apps
