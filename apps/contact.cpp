// `articula contact`: minimum signed distance between smooth convex surfaces
// (thesis ch. 5). Three inputs:
//   --pairs FILE.csv   one query per row (ellipsoid/superellipsoid pairs, or a plane for b)
//   --scenario NAME    the prescribed motions of thesis tables 5.3 / 5.4, 200 warm-started steps
//   --fits-a/--fits-b  two fitted surfaces (fits.json from articula-fit), each with an optional pose
// The pairs file is read by lib/contact (pairs_csv.hpp).
// Output: a CSV (LPS mm) and FILE.json with the summary and provenance;
// --json prints the summary (with the median solver time per query).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <iomanip>

#include <Eigen/Geometry>

#include "articula/cli/command.hpp"
#include "articula/contact/common_normal.hpp"
#include "articula/contact/pairs_csv.hpp"
#include "articula/contact/plane_contact.hpp"
#include "articula/contact/scenario.hpp"
#include "articula/core/json_file.hpp"
#include "articula/core/atomic_file.hpp"
#include "articula/core/error.hpp"
#include "articula/core/log.hpp"
#include "articula/core/parallel.hpp"
#include "articula/core/provenance.hpp"
#include "articula/geometry/pose.hpp"

namespace articula::apps {
namespace {

using contact::ContactResult;
using contact::ConvexShape;
using Eigen::Vector3d;

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

// Solver time of one query: the fastest of `repeats` identical calls (the
// first pays for cold caches), without any file I/O.
template <class F>
double timeNs(F&& f, int repeats = 5) {
  double best = INFINITY;
  for (int i = 0; i < repeats; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    f();
    best = std::min(best, std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - t0).count());
  }
  return best;
}

// One fitted model of a fits.json (docs/formats.md) as a contact shape, with an
// extra rigid pose x' = R_pose x + t_pose applied on top of the fit.
ConvexShape shapeFromFits(const std::filesystem::path& path, const std::string& model_name,
                          const Eigen::Matrix3d& R_pose, const Vector3d& t_pose) {
  const nlohmann::json j = readJsonFile(path, "fits");
  try {
    // The least-RMS model by default (written as "best_model" before "least_rms_model").
    const std::string wanted = !model_name.empty()            ? model_name
                               : j.contains("least_rms_model") ? j.at("least_rms_model").get<std::string>()
                                                               : j.at("best_model").get<std::string>();
    for (const auto& m : j.at("models")) {
      if (m.at("model").get<std::string>() != wanted) continue;
      geometry::ShapeParameters p;
      p.model = geometry::modelFromName(wanted);
      const auto v3 = [&](const char* key) {
        const auto a = m.at(key).get<std::vector<double>>();
        if (a.size() != 3) throw InputError(path.string() + ": '" + key + "' of model " + wanted + " needs 3 values");
        return Vector3d(a[0], a[1], a[2]);
      };
      p.center = v3("center_mm");
      p.radii = v3("radii_mm");
      p.angles = v3("rotation_deg") * (M_PI / 180.0);
      if (m.contains("exponents")) p.exponents = v3("exponents");
      ConvexShape s = contact::shapeFromParameters(p);
      s.center = R_pose * s.center + t_pose;
      s.rotation = R_pose * s.rotation;
      return s;
    }
    throw InputError(path.string() + ": no model '" + wanted + "' in 'models'");
  } catch (const nlohmann::json::exception& e) {
    throw InputError(path.string() + ": unexpected fits.json layout (" + e.what() + ")");
  }
}

class ContactCommand : public cli::Command {
 public:
  std::string name() const override { return "contact"; }
  std::string description() const override {
    return "Minimum signed distance between smooth convex surfaces (common-normal Newton solver, thesis ch. 5)";
  }
  std::string example() const override {
    return "articula contact --pairs pairs.csv -o contacts.csv --json\n"
           "  articula contact --scenario table5.3-1 -o motion.csv\n"
           "  articula contact --fits-a femur/fits.json --fits-b pelvis/fits.json --model-b sphere -o hip.csv";
  }
  void declare(CLI::App& app) override {
    auto* pairs = app.add_option("--pairs", pairs_,
                                 "CSV, one query per row: cx_a,cy_a,cz_a,qw_a,qx_a,qy_a,qz_a,ra_a,rb_a,rc_a,g1_a,g2_a,"
                                 "g3_a and the same with _b (quaternion w,x,y,z; exponents 2 = ellipsoid); optional "
                                 "column shape_b: 'plane' takes b as the plane through cx_b,cy_b,cz_b with normal "
                                 "nx_b,ny_b,nz_b; 'sphere' or 'ellipsoid' may leave g1_b,g2_b,g3_b empty");
    auto* scenario = app.add_option("--scenario", scenario_, "Prescribed motion: table5.3-1..4, table5.4-1..3");
    auto* fits_a = app.add_option("--fits-a", fits_a_, "fits.json of surface A (articula-fit)");
    app.add_option("--fits-b", fits_b_, "fits.json of surface B")->needs(fits_a);
    fits_a->needs(app.get_option("--fits-b"));
    app.add_option("--model-a", model_a_, "Model of A in its fits.json (default: its least_rms_model)");
    app.add_option("--model-b", model_b_, "Model of B in its fits.json (default: its least_rms_model)");
    app.add_option("--pose-a", pose_a_, "Extra pose of A: tx,ty,tz (mm),phi,theta,psi (deg), R = Rx Ry Rz")
        ->delimiter(',')->expected(6);
    app.add_option("--pose-b", pose_b_, "Extra pose of B, as --pose-a")->delimiter(',')->expected(6);
    pairs->excludes(scenario)->excludes(fits_a);
    scenario->excludes(fits_a);
    app.add_option("--steps", steps_, "Steps of a --scenario")->check(CLI::Range(1, 1000000))->capture_default_str();
    app.add_option("--frame", frame_, "Tangent frame: householder or square-plate")
        ->check(CLI::IsMember({"householder", "square-plate"}))->capture_default_str();
    app.add_option("--solver", solver_,
                   "Ellipsoid pairs: auto (Newton on the support-function dual) or common-normal (eq. 5.23, "
                   "the thesis solver; other pairs always use it)")
        ->check(CLI::IsMember({"auto", "common-normal"}))->capture_default_str();
    app.add_option("-o,--output", output_, "Output CSV")->required();
  }

  int run(const cli::CommonOptions& common) override {
    options_.frame = frame_ == "householder" ? geometry::FrameMethod::Householder : geometry::FrameMethod::SquarePlate;
    options_.solver = solver_ == "auto" ? contact::ContactSolver::Auto : contact::ContactSolver::CommonNormal;
    options_.validate();
    if (pairs_.empty() && scenario_.empty() && fits_a_.empty())
      throw UsageError("expected one of --pairs, --scenario or --fits-a/--fits-b");
    cli::refuseExistingOutputs({output_, output_.string() + ".json"}, common.force);
    if (!pairs_.empty()) return runPairs(common);
    if (!scenario_.empty()) return runScenario(common);
    return runFits(common);
  }

 private:
  int runPairs(const cli::CommonOptions& common) {
    const std::vector<contact::PairRow> pairs = contact::readPairsCsv(pairs_);

    AtomicFile file(output_, common.force);
    std::ostream& out = file.stream();
    out << contact::kResultsCsvHeader << '\n' << std::setprecision(17);
    // The rows are independent: solved over --threads, written in order
    // (the same file for any thread count).
    std::vector<ContactResult> results(pairs.size());
    std::vector<double> row_ns(pairs.size(), 0.0);
    parallelFor(static_cast<std::ptrdiff_t>(pairs.size()), 16, common.threadCount(), [&](std::ptrdiff_t begin, std::ptrdiff_t end) {
      for (std::ptrdiff_t i = begin; i < end; ++i) {
        const contact::PairRow& pair = pairs[static_cast<size_t>(i)];
        if (!pair.valid) continue;
        ContactResult& r = results[static_cast<size_t>(i)];
        if (pair.plane)
          row_ns[static_cast<size_t>(i)] =
              timeNs([&] { r = contact::shapePlaneContact(pair.a, pair.plane_point, pair.plane_normal); });
        else
          row_ns[static_cast<size_t>(i)] = timeNs([&] { r = contact::computeContact(pair.a, pair.b, options_); });
      }
    });
    std::vector<double> ns;
    nlohmann::json invalid = nlohmann::json::array();
    int rows = 0, converged = 0, certified = 0, planes = 0;
    long long iterations = 0;
    for (size_t i = 0; i < pairs.size(); ++i) {
      const contact::PairRow& pair = pairs[i];
      ++rows;
      for (const std::string& warning : pair.warnings) log::warn(warning);
      if (!pair.valid) {
        log::warn(pairs_.string() + ":" + std::to_string(pair.line) + ": " + pair.reason + "; row marked invalid");
        invalid.push_back({{"line", pair.line}, {"reason", pair.reason}});
        out << "nan,nan,nan,nan,nan,nan,nan,nan,nan,nan,0,invalid\n";
        continue;
      }
      const ContactResult& r = results[i];
      ns.push_back(row_ns[i]);
      planes += pair.plane;
      contact::writeResultRow(out, r);
      iterations += r.summary.iterations;
      converged += r.summary.status == contact::ContactStatus::Converged;
      certified += r.summary.certified;
    }
    const int valid = rows - static_cast<int>(invalid.size());
    if (valid == 0)
      throw InputError(pairs_.string() + ": no valid row among " + std::to_string(rows) +
                       " (see the messages above); nothing written");
    file.commit();
    nlohmann::json summary = {{"output", output_.string()},
                              {"rows", rows},
                              {"valid_rows", valid},
                              {"invalid_rows", invalid},
                              {"plane_rows", planes},
                              {"converged", converged},
                              {"certified_global", certified},
                              {"mean_iterations", static_cast<double>(iterations) / valid},
                              {"ns_per_query", median(ns)},
                              {"ns_per_query_note", "median over valid rows of the fastest of 5 identical calls; solver only, no file I/O"},
                              {"threads", common.threadCount()}};
    finish(summary, common, {pairs_});
    return 0;
  }

  int runScenario(const cli::CommonOptions& common) {
    AtomicFile file(output_, common.force);
    std::ostream& out = file.stream();
    out << "step," << contact::kResultsCsvHeader << ",ns\n" << std::setprecision(17);
    std::vector<double> ns;
    long long iterations = 0;
    int converged = 0, max_iterations = 0;
    ContactResult previous;
    for (int k = 0; k < steps_; ++k) {
      const contact::ScenarioPair p = contact::scenarioPair(scenario_, k, steps_);
      ContactResult r;
      const double t = timeNs([&] { r = contact::computeContact(p.i, p.j, options_, k ? &previous : nullptr); }, 1);
      ns.push_back(t);
      out << k << ',';
      contact::writeResultRow(out, r, "," + std::to_string(t));
      if (k) iterations += r.summary.iterations;
      max_iterations = std::max(max_iterations, r.summary.iterations);
      converged += r.summary.status == contact::ContactStatus::Converged;
      previous = r;
    }
    file.commit();
    nlohmann::json summary = {{"output", output_.string()},
                              {"scenario", scenario_},
                              {"steps", steps_},
                              {"frame", frame_}, {"solver", solver_},
                              {"converged_steps", converged},
                              {"iterations_per_warm_step", steps_ > 1 ? static_cast<double>(iterations) / (steps_ - 1) : 0.0},
                              {"max_iterations_per_step", max_iterations},
                              {"ns_per_query", median(ns)},
                              {"placement_note", "the thesis gives shapes and kinds of motion, not placements or speeds: "
                                                 "see lib/contact/include/articula/contact/scenario.hpp"}};
    finish(summary, common, {});
    return 0;
  }

  static void poseFrom(const std::vector<double>& v, Eigen::Matrix3d& R, Vector3d& t) {
    R.setIdentity();
    t.setZero();
    if (v.empty()) return;
    t = Vector3d(v[0], v[1], v[2]);
    R = geometry::rotationFromAngles(Vector3d(v[3], v[4], v[5]) * (M_PI / 180.0));
  }

  int runFits(const cli::CommonOptions& common) {
    Eigen::Matrix3d Ra, Rb;
    Vector3d ta, tb;
    poseFrom(pose_a_, Ra, ta);
    poseFrom(pose_b_, Rb, tb);
    const ConvexShape a = shapeFromFits(fits_a_, model_a_, Ra, ta), b = shapeFromFits(fits_b_, model_b_, Rb, tb);
    ContactResult r;
    const double t = timeNs([&] { r = contact::computeContact(a, b, options_); });
    AtomicFile file(output_, common.force);
    file.stream() << contact::kResultsCsvHeader << '\n' << std::setprecision(17);
    contact::writeResultRow(file.stream(), r);
    file.commit();
    nlohmann::json summary = {{"output", output_.string()},
                              {"distance_mm", r.distance},
                              {"status", contact::statusName(r.summary.status)},
                              {"summary", r.summary.briefReport()},
                              {"ns_per_query", t}};
    finish(summary, common, {fits_a_, fits_b_});
    return r.summary.status == contact::ContactStatus::Converged ? 0 : 1;
  }

  void finish(nlohmann::json& summary, const cli::CommonOptions& common, std::vector<std::filesystem::path> inputs) {
    summary["coordinate_system"] = "LPS";
    summary["units"] = "mm";
    const nlohmann::json params = {{"frame", frame_}, {"solver", solver_},
                                   {"max_iterations", options_.max_iterations},
                                   {"step_tolerance", options_.step_tolerance},
                                   {"sample_directions", options_.sample_directions},
                                   {"global_starts", options_.global_starts}};
    summary["provenance"] = provenanceJson({params, std::move(inputs), -1, common.threadCount()});
    writeFileAtomically(output_.string() + ".json", summary.dump(2) + "\n", true);
    log::info("wrote " + output_.string());
    if (common.json) cli::printJson(summary);
  }

  std::filesystem::path pairs_, output_, fits_a_, fits_b_;
  std::string scenario_, model_a_, model_b_, frame_ = "householder", solver_ = "auto";
  std::vector<double> pose_a_, pose_b_;
  int steps_ = 200;
  contact::ContactOptions options_;
};

ARTICULA_REGISTER_COMMAND(ContactCommand)

}  // namespace
}  // namespace articula::apps
