// `articula contact`: minimum signed distance between smooth convex surfaces
// (thesis ch. 5). Three inputs:
//   --pairs FILE.csv   one query per row (ellipsoid/superellipsoid pairs, or a plane for b)
//   --scenario NAME    the prescribed motions of thesis tables 5.3 / 5.4, 200 warm-started steps
//   --fits-a/--fits-b  two fitted surfaces (fits.json from articula-fit), each with an optional pose
// Output: a CSV (LPS mm) and FILE.json with the summary and provenance;
// --json prints the summary (with the median solver time per query).
#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <map>
#include <sstream>

#include <Eigen/Geometry>

#include "articula/cli/command.hpp"
#include "articula/contact/common_normal.hpp"
#include "articula/contact/plane_contact.hpp"
#include "articula/contact/scenario.hpp"
#include "articula/core/atomic_file.hpp"
#include "articula/core/error.hpp"
#include "articula/core/log.hpp"
#include "articula/core/provenance.hpp"
#include "articula/geometry/pose.hpp"

namespace articula::apps {
namespace {

using contact::ContactResult;
using contact::ConvexShape;
using Eigen::Vector3d;

const char* kOutputHeader = "distance,pax,pay,paz,pbx,pby,pbz,nx,ny,nz,iterations,status";

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r"), e = s.find_last_not_of(" \t\r");
  return b == std::string::npos ? "" : s.substr(b, e - b + 1);
}

std::vector<std::string> splitCsv(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream ss(line);
  std::string cell;
  while (std::getline(ss, cell, ',')) out.push_back(trim(cell));
  if (!line.empty() && line.back() == ',') out.emplace_back();
  return out;
}

// A row that cannot be used: the reason goes to stderr and the JSON summary.
struct BadRow : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct Row {
  const std::map<std::string, size_t>& columns;
  const std::vector<std::string>& cells;
  const std::string& text(const std::string& name) const {
    const auto it = columns.find(name);
    if (it == columns.end()) throw BadRow("column '" + name + "' is missing from the header");
    return cells[it->second];
  }
  bool empty(const std::string& name) const { return columns.count(name) == 0 || cells[columns.at(name)].empty(); }
  double number(const std::string& name) const {
    const std::string& text = this->text(name);
    char* end = nullptr;
    const double v = std::strtod(text.c_str(), &end);
    if (text.empty() || end != text.c_str() + text.size()) throw BadRow(name + ": expected a number, found '" + text + "'");
    if (!std::isfinite(v)) throw BadRow(name + ": expected a finite number, found '" + text + "'");
    return v;
  }
  Vector3d vec(const std::string& x, const std::string& y, const std::string& z) const {
    return {number(x), number(y), number(z)};
  }
};

// Shape "a" or "b" of a row; warns when the quaternion had to be normalised.
// `kind` (shape_b): "sphere" and "ellipsoid" take empty exponent cells as 2
// and reject others; "sphere" also needs three equal radii.
ConvexShape rowShape(const Row& r, const std::string& s, int line, const std::string& kind = "") {
  const Eigen::Vector4d q(r.number("qw_" + s), r.number("qx_" + s), r.number("qy_" + s), r.number("qz_" + s));
  const double len = q.norm();
  if (!(len > 1e-12)) throw BadRow("quaternion " + s + " is zero");
  if (std::fabs(len - 1.0) > 1e-9)
    log::warn("line " + std::to_string(line) + ": quaternion " + s + " has length " + std::to_string(len) +
              "; normalised");
  const Eigen::Matrix3d R = Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized().toRotationMatrix();
  const Vector3d radii = r.vec("ra_" + s, "rb_" + s, "rc_" + s);
  Vector3d exponents(2.0, 2.0, 2.0);
  const bool quadric = kind == "sphere" || kind == "ellipsoid";
  for (int i = 0; i < 3; ++i) {
    const std::string column = "g" + std::to_string(i + 1) + "_" + s;
    if (quadric && r.empty(column)) continue;
    exponents[i] = r.number(column);
    if (quadric && exponents[i] != 2.0)
      throw BadRow(column + ": expected 2 or an empty cell (shape_" + s + " is " + kind + "), found " + r.text(column));
  }
  if (kind == "sphere" && !(radii.maxCoeff() - radii.minCoeff() <= 1e-12 * radii.maxCoeff()))
    throw BadRow("shape_" + s + " is sphere: expected ra_" + s + " = rb_" + s + " = rc_" + s + ", found " +
                 r.text("ra_" + s) + ", " + r.text("rb_" + s) + ", " + r.text("rc_" + s));
  try {
    return contact::makeConvexShape(r.vec("cx_" + s, "cy_" + s, "cz_" + s), R, radii, exponents);
  } catch (const InvalidParameter& e) {
    throw BadRow("shape " + s + ": " + e.what());
  }
}

// One output row; `suffix` (e.g. ",123.4") goes before the newline.
void writeRow(std::ostream& out, const ContactResult& r, const std::string& suffix = "") {
  out << r.distance;
  for (const Vector3d* v : {&r.point_a, &r.point_b, &r.normal}) out << ',' << (*v)[0] << ',' << (*v)[1] << ',' << (*v)[2];
  out << ',' << r.summary.iterations << ',' << contact::statusName(r.summary.status) << suffix << '\n';
}

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
  std::ifstream in(path);
  if (!in) throw InputError("cannot read fits file '" + path.string() + "'");
  nlohmann::json j;
  try {
    in >> j;
  } catch (const std::exception& e) {
    throw InputError(path.string() + ": not valid JSON (" + e.what() + ")");
  }
  try {
    const std::string wanted = model_name.empty() ? j.at("best_model").get<std::string>() : model_name;
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
    app.add_option("--model-a", model_a_, "Model of A in its fits.json (default: its best_model)");
    app.add_option("--model-b", model_b_, "Model of B in its fits.json (default: its best_model)");
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
    if (!pairs_.empty()) return runPairs(common);
    if (!scenario_.empty()) return runScenario(common);
    return runFits(common);
  }

 private:
  int runPairs(const cli::CommonOptions& common) {
    std::ifstream in(pairs_);
    if (!in) throw InputError("cannot read --pairs file '" + pairs_.string() + "'");
    std::string line;
    if (!std::getline(in, line)) throw InputError(pairs_.string() + ": empty file (expected a header row)");
    std::map<std::string, size_t> columns;
    const auto header = splitCsv(line);
    for (size_t i = 0; i < header.size(); ++i) columns[header[i]] = i;
    std::vector<std::string> missing;
    for (const char* s : {"a", "b"})
      for (const char* c : {"cx", "cy", "cz"})
        if (!columns.count(std::string(c) + "_" + s)) missing.push_back(std::string(c) + "_" + s);
    for (const char* c : {"qw", "qx", "qy", "qz", "ra", "rb", "rc", "g1", "g2", "g3"})
      if (!columns.count(std::string(c) + "_a")) missing.push_back(std::string(c) + "_a");
    if (!missing.empty()) {
      std::string list;
      for (const auto& m : missing) list += (list.empty() ? "" : ", ") + m;
      throw InputError(pairs_.string() + ":1: header lacks column(s) " + list);
    }

    AtomicFile file(output_, common.force);
    std::ostream& out = file.stream();
    out << kOutputHeader << '\n' << std::setprecision(17);
    std::vector<double> ns;
    nlohmann::json invalid = nlohmann::json::array();
    int rows = 0, converged = 0, certified = 0, planes = 0;
    long long iterations = 0;
    for (int line_no = 2; std::getline(in, line); ++line_no) {
      if (trim(line).empty()) continue;
      ++rows;
      const auto cells = splitCsv(line);
      try {
        if (cells.size() != header.size())
          throw BadRow("expected " + std::to_string(header.size()) + " cells, found " + std::to_string(cells.size()));
        const Row row{columns, cells};
        const ConvexShape a = rowShape(row, "a", line_no);
        std::string kind = row.empty("shape_b") ? "" : row.text("shape_b");
        std::transform(kind.begin(), kind.end(), kind.begin(), [](unsigned char c) { return std::tolower(c); });
        if (kind != "" && kind != "plane" && kind != "sphere" && kind != "ellipsoid" && kind != "superellipsoid")
          throw BadRow("shape_b: expected plane, sphere, ellipsoid, superellipsoid or empty, found '" +
                       row.text("shape_b") + "'");
        const bool plane = kind == "plane";
        ContactResult r;
        if (plane) {
          const Vector3d p = row.vec("cx_b", "cy_b", "cz_b"), n = row.vec("nx_b", "ny_b", "nz_b");
          if (!(n.norm() > 0.0)) throw BadRow("plane normal nx_b,ny_b,nz_b is zero");
          ns.push_back(timeNs([&] { r = contact::shapePlaneContact(a, p, n); }));
          ++planes;
        } else {
          const ConvexShape b = rowShape(row, "b", line_no, kind);
          ns.push_back(timeNs([&] { r = contact::computeContact(a, b, options_); }));
        }
        writeRow(out, r);
        iterations += r.summary.iterations;
        converged += r.summary.status == contact::ContactStatus::Converged;
        certified += r.summary.certified;
      } catch (const BadRow& e) {
        log::warn(pairs_.string() + ":" + std::to_string(line_no) + ": " + e.what() + "; row marked invalid");
        invalid.push_back({{"line", line_no}, {"reason", e.what()}});
        out << "nan,nan,nan,nan,nan,nan,nan,nan,nan,nan,0,invalid\n";
      }
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
                              {"ns_per_query_note", "median over valid rows of the fastest of 5 identical calls; solver only, no file I/O"}};
    finish(summary, common, {pairs_});
    return 0;
  }

  int runScenario(const cli::CommonOptions& common) {
    AtomicFile file(output_, common.force);
    std::ostream& out = file.stream();
    out << "step," << kOutputHeader << ",ns\n" << std::setprecision(17);
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
      writeRow(out, r, "," + std::to_string(t));
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
    file.stream() << kOutputHeader << '\n' << std::setprecision(17);
    writeRow(file.stream(), r);
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
    summary["provenance"] = provenanceJson({params, std::move(inputs), -1});
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
