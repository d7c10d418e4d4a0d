// `articula run -i INPUT -o OUTDIR`: segment -> mesh -> sample -> fit ->
// errors -> report for one subject, in this process. Each stage is the
// registered stage command itself, run with the arguments its executable
// would get, so OUTDIR holds exactly the files the stage apps write. A stage
// whose outputs exist and whose inputs (SHA-256) and arguments are unchanged
// is skipped (stamps in OUTDIR/.articula/).
#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "articula/cli/command.hpp"
#include "articula/core/atomic_file.hpp"
#include "articula/core/error.hpp"
#include "articula/core/log.hpp"
#include "articula/core/provenance.hpp"
#include "articula/fit/fits_json.hpp"
#include "articula/geometry/pose.hpp"
#include "articula/geometry/shape.hpp"
#include "articula/pipeline/csv.hpp"
#include "articula/pipeline/markups.hpp"
#include "articula/pipeline/qc.hpp"
#include "articula/points/point_io.hpp"
#include "articula/pipeline/statistics.hpp"

namespace articula::apps {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

const std::vector<std::string> kStages = {"segment", "mesh", "sample", "fit", "errors", "report"};

// Options of `run` forwarded to the stage that declares them (the same table
// as pipelines/Snakefile's STAGE_OPTIONS).
struct Forwarded {
  const char* option;
  const char* stage;
};
const Forwarded kForwarded[] = {{"seed-point", "segment"},    {"series-uid", "segment"}, {"hu-min", "segment"},
                                {"hu-max", "segment"},        {"roi", "segment"},        {"level-set", "segment"},
                                {"smoothing", "mesh"},
                                {"smooth-iterations", "mesh"}, {"relaxation", "mesh"},   {"decimate", "mesh"},
                                {"select", "sample"},         {"ball-radius", "sample"}, {"ratio", "sample"},
                                {"models", "fit"},            {"objective", "fit"}};

// Default of --selection-tolerance: models whose RMS is within 10 % of the
// least are not told apart; on phantoms of known shape
// (tests/apps/batch_killed.sh) the voxelised surface leaves the true model
// 4-9 % above the most flexible one.
constexpr double kDefaultSelectionTolerance = 0.10;
// Default of --selection-floor (see pipeline::selectParsimonious).
constexpr double kDefaultSelectionFloorMm = 0.03;

// SHA-256 of a file, or of every file of a folder (a DICOM series) in name order.
std::string hashInput(const fs::path& path) {
  if (!fs::is_directory(path)) return sha256File(path);
  std::vector<fs::path> files;
  for (const auto& e : fs::recursive_directory_iterator(path))
    if (e.is_regular_file()) files.push_back(e.path());
  std::sort(files.begin(), files.end());
  std::string all;
  for (const auto& f : files) all += fs::relative(f, path).string() + ":" + sha256File(f) + "\n";
  return sha256String(all);
}

std::string number(double v) {
  std::ostringstream s;
  s.precision(10);
  s << v;
  return s.str();
}

// Parameter names with units, for results and study tables (angles in degrees).
std::string withUnit(const std::string& name, geometry::ParameterKind kind) {
  if (kind == geometry::ParameterKind::Angle) return name + "_deg";
  const std::string unit = geometry::parameterUnit(kind);
  return unit.empty() ? name : name + "_" + unit;
}

class RunCommand : public cli::Command {
 public:
  std::string name() const override { return "run"; }
  std::string description() const override {
    return "Run segment -> mesh -> sample -> fit -> errors -> report on one CT, skipping stages that are up to date";
  }
  std::string example() const override {
    return "articula run -i ct/ -o out/subject01 --joint hip --side right";
  }
  void declare(CLI::App& app) override {
    app.add_option("-i,--input", input_, "DICOM folder or .nii/.nii.gz/.nrrd/.mha CT")->required();
    app.add_option("-o,--output", output_, "Output folder, one file per stage output")->required();
    app.add_option("--joint", joint_, "hip or shoulder")->check(CLI::IsMember({"hip", "shoulder"}))->capture_default_str();
    app.add_option("--side", side_, "right or left")->check(CLI::IsMember({"right", "left"}))->capture_default_str();
    app.add_option("--from", from_, "First stage to run (earlier outputs must exist): " + stageList())
        ->check(CLI::IsMember(kStages));
    app.add_option("--until", until_, "Last stage to run")->check(CLI::IsMember(kStages));
    app.add_option("--selection-floor", selection_floor_mm_,
                   "Report: RMS differences up to this many mm never tell models apart (systematic error of the CT surface)")
        ->check(CLI::Range(0.0, 1.0))
        ->capture_default_str();
    app.add_option("--selection-tolerance", selection_tolerance_,
                   "Report: the selected model is the simplest whose RMS is within this fraction of the least RMS")
        ->check(CLI::Range(0.0, 10.0))
        ->capture_default_str();
    for (const auto& f : kForwarded)
      app.add_option(std::string("--") + f.option, forwarded_[f.option],
                     std::string("Passed to the ") + f.stage + " stage (see articula " + f.stage + " --help)");
  }

  int run(const cli::CommonOptions& common) override {
    const auto start = std::chrono::steady_clock::now();
    const int first = from_.empty() ? 0 : index(from_), last = until_.empty() ? 5 : index(until_);
    if (first > last) throw UsageError("--from " + from_ + " comes after --until " + until_);
    if (!fs::exists(input_)) throw InputError("input '" + input_.string() + "' does not exist: expected a DICOM folder or a CT image file");
    fs::create_directories(output_ / ".articula");
    if (const int stale = removeStaleTemporaries(output_))
      log::info("removed " + std::to_string(stale) + " unfinished file(s) of an interrupted earlier run");
    for (int i = first; i <= last; ++i) {
      const std::string& stage = kStages[i];
      const auto plan = stagePlan(stage, common);
      for (const auto& in : plan.inputs)
        if (!fs::exists(in))
          throw InputError("stage " + stage + " needs '" + in.string() + "', which is missing: run the earlier stages first");
      json stamp = {{"args", plan.args}, {"inputs", json::object()}};
      for (const auto& in : plan.inputs) stamp["inputs"][in.string()] = hashInput(in);
      const fs::path stamp_path = output_ / ".articula" / (stage + ".json");
      const bool forced = common.force || (!from_.empty() && i == first);
      if (!forced && upToDate(plan, stamp, stamp_path)) {
        log::info("run: " + stage + " is up to date");
        continue;
      }
      fs::remove(stamp_path);
      log::info("run: " + stage + " ...");
      const auto t0 = std::chrono::steady_clock::now();
      if (stage == "report") {
        report(common);
      } else {
        const int rc = cli::runCommandInProcess(stage, plan.args);
        if (rc != 0) return rc;  // the stage has said why on stderr
      }
      stamp["seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      stamp["outputs"] = json::object();  // a damaged or replaced output reruns the stage
      for (const auto& out : plan.outputs) stamp["outputs"][out.string()] = hashInput(out);
      writeFileAtomically(stamp_path, stamp.dump(2) + "\n");
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    log::info("run: done in " + number(seconds) + " s: " + (output_ / "results.json").string());
    if (common.json && fs::exists(output_ / "results.json")) {
      std::ifstream in(output_ / "results.json");
      cli::printJson(json::parse(in));
    }
    return 0;
  }

 private:
  struct Plan {
    std::vector<std::string> args;
    std::vector<fs::path> inputs, outputs;
  };

  static std::string stageList() {
    std::string s;
    for (const auto& st : kStages) s += (s.empty() ? "" : ", ") + st;
    return s;
  }
  static int index(const std::string& stage) {
    return static_cast<int>(std::find(kStages.begin(), kStages.end(), stage) - kStages.begin());
  }

  Plan stagePlan(const std::string& stage, const cli::CommonOptions& common) const {
    const fs::path label = output_ / "label.nii.gz", bone = output_ / "bone.vtp", points = output_ / "points.ply",
                   fits = output_ / "fits.json", errors = output_ / "errors";
    Plan p;
    if (stage == "segment") {
      p = {{"-i", input_.string(), "-o", label.string(), "--joint", joint_, "--side", side_}, {input_}, {label}};
    } else if (stage == "mesh") {
      // The CT too: the surface moves onto its bone edge (sub-voxel).
      p = {{"-i", label.string(), "-o", bone.string(), "--ct", input_.string()}, {label, input_}, {bone}};
      if (auto uid = forwarded_.find("series-uid"); uid != forwarded_.end() && !uid->second.empty())
        p.args.insert(p.args.end(), {"--series-uid", uid->second});
    } else if (stage == "sample") {
      p = {{"-i", bone.string(), "-o", points.string()}, {bone}, {points}};
    } else if (stage == "fit") {
      p = {{"-i", points.string(), "-o", fits.string()}, {points}, {fits, output_ / "fits.csv"}};
    } else if (stage == "errors") {
      p = {{"-i", points.string(), "--fits", fits.string(), "-o", errors.string()}, {points, fits},
           {errors / "summary.json", errors / "histogram.svg", errors / "error_map.svg"}};
    } else {
      // (The report runs in-process: its arguments only stamp it, so that a new tolerance reruns it.)
      p = {{"--selection-tolerance", number(selection_tolerance_), "--selection-floor", number(selection_floor_mm_)},
           {fits, errors / "summary.json", points},
           {output_ / "results.json", output_ / "results.csv", output_ / "head.mrk.json"}};
      return p;
    }
    for (const auto& f : kForwarded) {
      auto it = forwarded_.find(f.option);
      if (f.stage == stage && it != forwarded_.end() && !it->second.empty())
        p.args.insert(p.args.end(), {std::string("--") + f.option, it->second});
    }
    p.args.insert(p.args.end(), {"--seed", std::to_string(common.seed), "--threads", std::to_string(common.threadCount()),
                                 "--force"});
    if (common.verbosity == 0) p.args.push_back("--quiet");
    if (common.verbosity == 2) p.args.push_back("--verbose");
    return p;
  }

  static bool upToDate(const Plan& plan, const json& stamp, const fs::path& stamp_path) {
    for (const auto& out : plan.outputs)
      if (!fs::exists(out)) return false;
    std::ifstream in(stamp_path);
    if (!in) return false;
    try {
      const json old = json::parse(in);
      if (!(old.at("args") == stamp.at("args") && old.at("inputs") == stamp.at("inputs"))) return false;
      for (const auto& out : plan.outputs)
        if (old.at("outputs").value(out.string(), "") != hashInput(out)) return false;
      return true;
    } catch (const json::exception&) {
      return false;
    }
  }

  // results.json / results.csv / head.mrk.json from fits.json and errors/summary.json.
  void report(const cli::CommonOptions& common) const {
    const fs::path fits_path = output_ / "fits.json", summary_path = output_ / "errors" / "summary.json";
    json fits, summary;
    try {
      std::ifstream f(fits_path), s(summary_path);
      fits = json::parse(f);
      summary = json::parse(s);
    } catch (const json::exception& e) {
      throw InputError("cannot read the fit or error summary in '" + output_.string() + "': " + e.what());
    }
    std::map<std::string, json> errors_by_model;
    for (const auto& row : summary.at("models")) errors_by_model[row.at("model").get<std::string>()] = row;
    const auto shapes = fit::shapesFromFitsJson(fits, fits_path.string());
    const std::string best = fits.value("best_model", "");
    json models = json::array();
    std::vector<std::string> csv_header = {"model", "n_parameters", "aic", "bic", "best_by_rms"};
    std::string csv_rows;
    geometry::ShapeParameters best_shape = shapes.front();
    for (size_t model_index = 0; model_index < shapes.size(); ++model_index) {
      const geometry::ShapeParameters& shape = shapes[model_index];
      const json& fit_entry = fits.at("models")[model_index];
      const std::string name = geometry::modelName(shape.model);
      if (name == best) best_shape = shape;
      const auto names = geometry::parameterNames(shape.model);
      const auto kinds = geometry::parameterKinds(shape.model);
      const Eigen::VectorXd lambda = geometry::toVector(shape);
      json parameters = json::object();
      for (size_t i = 0; i < names.size(); ++i) {
        double v = lambda[static_cast<Eigen::Index>(i)];
        if (kinds[i] == geometry::ParameterKind::Angle) v *= 180.0 / M_PI;
        parameters[withUnit(names[i], kinds[i])] = v;
      }
      json errors = errors_by_model.count(name) ? errors_by_model[name] : json::object();
      errors.erase("model");
      const int k = geometry::parameterCount(shape.model);
      const int n = errors.value("n_points", 0);
      const double sse = errors.value("sse_mm2", 0.0);
      json entry = {{"model", name}, {"n_parameters", k}, {"parameters", parameters}, {"errors", errors}};
      // Standard errors in the parameters' units (angles in degrees); null:
      // not identifiable from these points (fits.json, fit/uncertainty.hpp).
      if (fit_entry.contains("standard_errors_table_3_2")) {
        json standard_errors = json::object();
        const json& se = fit_entry.at("standard_errors_table_3_2");
        for (size_t i = 0; i < names.size(); ++i) {
          json v = se.value(names[i], json(nullptr));
          if (v.is_number() && kinds[i] == geometry::ParameterKind::Angle) v = v.get<double>() * 180.0 / M_PI;
          standard_errors[withUnit(names[i], kinds[i])] = v;
        }
        entry["standard_errors"] = standard_errors;
        entry["not_identifiable"] = fit_entry.value("not_identifiable", json::array());
      }
      if (n > k && sse > 0) {
        entry["aic"] = pipeline::aic(sse, n, k);
        entry["bic"] = pipeline::bic(sse, n, k);
      }
      models.push_back(entry);
    }
    // The model these points support (see pipeline::selectParsimonious).
    std::vector<pipeline::ModelScore> scores;
    for (const auto& m : models)
      scores.push_back({m.at("model"), m.at("n_parameters"), m.at("errors").value("rms_mm", NAN)});
    const pipeline::ModelSelection selection = pipeline::selectParsimonious(scores, selection_tolerance_, selection_floor_mm_);
    csv_header.push_back("selected");
    // results.csv: one row per model, units in the column names.
    std::vector<std::string> error_columns, parameter_columns;
    for (const auto& m : models) {
      for (const auto& [key, v] : m.at("errors").items())
        if (std::find(error_columns.begin(), error_columns.end(), key) == error_columns.end()) error_columns.push_back(key);
      for (const auto& [key, v] : m.at("parameters").items())
        if (std::find(parameter_columns.begin(), parameter_columns.end(), key) == parameter_columns.end())
          parameter_columns.push_back(key);
    }
    csv_header.insert(csv_header.end(), error_columns.begin(), error_columns.end());
    csv_header.insert(csv_header.end(), parameter_columns.begin(), parameter_columns.end());
    for (const auto& m : models) {
      std::vector<std::string> f = {m.at("model"), std::to_string(m.at("n_parameters").get<int>()),
                                    m.contains("aic") ? number(m.at("aic")) : "", m.contains("bic") ? number(m.at("bic")) : "",
                                    m.at("model") == best ? "1" : "0", m.at("model") == selection.selected ? "1" : "0"};
      for (const auto& c : error_columns) f.push_back(m.at("errors").contains(c) ? number(m.at("errors").at(c).get<double>()) : "");
      for (const auto& c : parameter_columns)
        f.push_back(m.at("parameters").contains(c) ? number(m.at("parameters").at(c).get<double>()) : "");
      csv_rows += pipeline::csvLine(f) + "\n";
    }
    // The head centre and axes of the best model, for 3D Slicer.
    const Eigen::Matrix3d R = geometry::rotationFromAngles(best_shape.angles);
    const Eigen::Vector3d c = best_shape.center;
    std::vector<pipeline::LandmarkLine> axes;
    const char* axis_names[3] = {"axis_a", "axis_b", "axis_c"};
    for (int i = 0; i < 3; ++i)
      axes.push_back({axis_names[i], c - best_shape.radii[i] * R.col(i), c + best_shape.radii[i] * R.col(i)});
    pipeline::writeSlicerMarkups(output_ / "head.mrk.json", best + " head (articula)", {{"head_center", c}}, axes);

    const pipeline::QcReport qc = checkHead(shapes);

    Provenance provenance;
    provenance.inputs = {input_.has_filename() && fs::is_regular_file(input_) ? input_ : fs::path(), fits_path, summary_path};
    provenance.inputs.erase(std::remove(provenance.inputs.begin(), provenance.inputs.end(), fs::path()), provenance.inputs.end());
    provenance.seed = common.seed;
    provenance.parameters = {
        {"joint", joint_}, {"side", side_}, {"input", input_.string()}, {"selection_tolerance", selection_tolerance_},
        {"selection_floor_mm", selection_floor_mm_}};
    const json results = {{"input", input_.string()},
                          {"joint", joint_},
                          {"side", side_},
                          {"best_model", best},
                          {"selected_model", selection.selected},
                          {"selection", {{"rule", "the simplest model whose RMS exceeds the least RMS by at most the larger of relative_tolerance x the least RMS and absolute_tolerance_mm"},
                                         {"relative_tolerance", selection_tolerance_},
                                         {"absolute_tolerance_mm", selection_floor_mm_},
                                         {"indistinguishable", selection.indistinguishable}}},
                          {"head_center_mm", {c[0], c[1], c[2]}},
                          {"qc", qc.toJson()},
                          {"models", models},
                          {"coordinate_system", "LPS"},
                          {"units", "mm"},
                          {"provenance", provenanceJson(provenance)}};
    writeFileAtomically(output_ / "results.csv", pipeline::csvLine(csv_header) + "\n" + csv_rows);
    writeFileAtomically(output_ / "results.json", results.dump(2) + "\n");
    for (const std::string& reason : qc.reasons()) log::warn("qc " + reason);
    if (qc.status == "fail")
      throw ProcessingError("the result is not a plausible joint head (results.json, \"qc\"): " + qc.reasons().front());
  }

  // The checks of a head (pipeline/qc.hpp) on the articular points, their
  // fitted sphere and the segmentation's own head, where it searched.
  pipeline::QcReport checkHead(const std::vector<geometry::ShapeParameters>& shapes) const {
    pipeline::HeadQcInput in;
    const points::PointCloud cloud = points::readPoints(output_ / "points.ply");
    in.points = cloud.positions;
    in.normals = cloud.normals;
    const auto sphere = std::find_if(shapes.begin(), shapes.end(),
                                     [](const auto& s) { return s.model == geometry::ShapeModel::Sphere; });
    if (sphere == shapes.end()) throw InputError("fits.json holds no sphere: the head checks need one (fit --models with sphere)");
    in.sphere_center = sphere->center;
    in.sphere_radius_mm = sphere->radii[0];
    const fs::path segment_summary = output_ / "label.nii.gz.json";
    if (fs::exists(segment_summary)) {
      try {
        std::ifstream f(segment_summary);
        const json seg = json::parse(f);
        if (seg.value("seed_source", "").rfind("automatic", 0) == 0) {
          const auto& sc = seg.at("head_center_mm");
          in.search_center = Eigen::Vector3d(sc.at(0).get<double>(), sc.at(1).get<double>(), sc.at(2).get<double>());
          in.search_radius_mm = seg.value("search_radius_mm", 0.0);
        }
      } catch (const json::exception& e) {
        throw InputError("cannot read the segmentation summary '" + segment_summary.string() + "': " + e.what());
      }
    }
    return pipeline::checkHead(in);
  }

  fs::path input_, output_;
  std::string joint_ = "hip", side_ = "right", from_, until_;
  double selection_tolerance_ = kDefaultSelectionTolerance;
  double selection_floor_mm_ = kDefaultSelectionFloorMm;
  std::map<std::string, std::string> forwarded_;
};

ARTICULA_REGISTER_COMMAND(RunCommand)

}  // namespace
}  // namespace articula::apps
