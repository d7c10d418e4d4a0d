#include "articula/subject/subject_report.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <memory>
#include <optional>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "articula/core/json_file.hpp"
#include "articula/core/log.hpp"
#include "articula/core/atomic_file.hpp"
#include "articula/core/error.hpp"
#include "articula/core/number_text.hpp"
#include "articula/core/provenance.hpp"
#include "articula/fit/fits_json.hpp"
#include "articula/fit/residual_correlation.hpp"
#include "articula/geometry/pose.hpp"
#include "articula/geometry/shape.hpp"
#include "articula/core/csv.hpp"
#include "articula/checks/cap_departures.hpp"
#include "articula/subject/markups.hpp"
#include "articula/imaging/edges.hpp"
#include "articula/imaging/io.hpp"
#include "articula/subject/head_slices.hpp"
#include "articula/subject/head_view.hpp"
#include "articula/subject/slicer_scene.hpp"
#include "articula/statistics/model_selection.hpp"
#include "articula/subject/subject_html.hpp"
#include "articula/points/mesh_file.hpp"
#include "articula/sampling/select.hpp"
#include "articula/fit/fit_hierarchy.hpp"
#include "articula/points/point_io.hpp"
#include "articula/report/error_map_svg.hpp"
#include "articula/report/markup_text.hpp"

namespace articula::subject {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

std::string number(double v) {
  std::string text;
  appendNumber(text, v, 10);
  return text;
}

// Parameter names with units, for results and study tables (angles in degrees).
std::string withUnit(const std::string& name, geometry::ParameterKind kind) {
  if (kind == geometry::ParameterKind::Angle) return name + "_deg";
  const std::string unit = geometry::parameterUnit(kind);
  return unit.empty() ? name : name + "_" + unit;
}

json stepJson(const statistics::NestedStep& s) {
  const auto finite = [](double v) { return std::isfinite(v) ? json(v) : json(nullptr); };
  return {{"simpler", s.simpler},
          {"richer", s.richer},
          {"f", finite(s.f)},
          {"df1", s.df1},
          {"df1_effective", finite(s.df1_effective)},
          {"df2", s.df2},
          {"n_eff", finite(s.n_eff)},
          {"p_value", finite(s.p_value)},
          {"alpha", finite(s.alpha)},
          {"richer_needed", s.richer_needed}};
}

json readStageJson(const fs::path& path) {
  if (!fs::exists(path))
    throw InputError("the report needs '" + path.string() + "', which is missing: run the earlier stages first");
  return readJsonFile(path, "report");
}

// The checks of a head (checks/qc.hpp) on the articular points, their
// fitted sphere and the segmentation's own head, where it searched.
checks::QcReport checkSubjectHead(const fs::path& folder, const points::PointCloud& cloud, const std::string& joint,
                          const std::vector<geometry::ShapeParameters>& shapes, const imaging::Volume* ct,
                          const std::optional<checks::CapDepartures>& departures) {
  checks::HeadQcInput in;
  if (departures) in.cap_departure_mm2 = departures->largestFindingMm2();
  if (departures) in.cap_bone_beyond_mm2 = departures->largestBoneBeyondMm2();
  in.points = cloud.positions;
  in.normals = cloud.normals;
  if (ct && in.normals.rows() == in.points.rows()) {
    in.ct_edges = checks::pointsOnCtEdge(*ct, in.points, in.normals);
    in.ct_voxel_mm = ct->geometry.spacing.maxCoeff();
    in.cortex_contrast_across_slices = checks::cortexContrastAcrossSlices(*ct, in.points, in.normals);
    // A humeral head's glenoid is small and shallow: most of its cap faces none.
    if (joint == "hip")
      if (const auto socket = checks::socketFacing(*ct, in.points, in.normals)) {
        in.socket_facing_share = socket->share;
        in.joint_space_mm = socket->joint_space_mm;
      }
  }
  const auto sphere =
      std::find_if(shapes.begin(), shapes.end(), [](const auto& s) { return s.model == geometry::ShapeModel::Sphere; });
  if (sphere == shapes.end()) throw InputError("fits.json holds no sphere: the head checks need one (fit --models with sphere)");
  in.sphere_center = sphere->center;
  in.sphere_radius_mm = sphere->radii[0];
  in.joint = joint;
  if (ct) {
    in.head_outside_volume_share = checks::headOutsideVolumeShare(ct->geometry, in.points, in.sphere_center, in.sphere_radius_mm);
    in.metal_near_head_mm3 = checks::metalNearHead(*ct, in.sphere_center, in.sphere_radius_mm);
    in.head_beyond_fov_mm = checks::headBeyondFieldOfView(ct->geometry, in.sphere_center, in.sphere_radius_mm);
  }
  const fs::path mesh_summary = folder / "bone.vtp.json";
  if (fs::exists(mesh_summary)) {
    const json mesh = readStageJson(mesh_summary);
    const json edges = mesh.contains("ct_edges") && mesh.at("ct_edges").is_object() ? mesh.at("ct_edges") : json::object();
    if (edges.contains("moved") && edges.at("moved").is_boolean()) in.surface_on_ct_edges = edges.at("moved").get<bool>();
    // The edges' model fallen back to the steepest falls (no point-spread
    // estimated): a named check, not the mesh stage's terminal line only.
    if (edges.contains("cortex_model_note") && edges.at("cortex_model_note").is_string())
      in.stage_warnings.push_back("mesh: " + edges.at("cortex_model_note").get<std::string>());
  }
  const fs::path sample_summary = folder / "points.ply.json";
  if (fs::exists(sample_summary)) {
    const json sample = readStageJson(sample_summary);
    for (const auto& w : sample.value("warnings", json::array()))
      if (w.is_string()) in.stage_warnings.push_back("sample: " + w.get<std::string>());
    const json kept = sample.value("cut_through_bone_kept", json());
    const double selected = sample.value("selected_points", 0.0);
    if (kept.is_number() && selected > 0) in.points_on_cut_share = kept.get<double>() / selected;
  }
  const fs::path segment_summary = folder / "label.nii.gz.json";
  if (fs::exists(segment_summary)) {
    const json seg = readStageJson(segment_summary);
    try {
      for (const auto& w : seg.value("warnings", json::array()))
        if (w.is_string()) in.stage_warnings.push_back(w.get<std::string>());
      if (seg.contains("head_depth_mm")) in.label_depth_mm = seg.at("head_depth_mm").get<double>();
      if (const double noise_hu = seg.value("noise_hu", 0.0); noise_hu > 0) in.ct_noise_hu = noise_hu;
      // The head radii the user allowed the search (--min-radius,
      // --max-radius): a head found beyond the defaults with a widened range
      // is held to that range.
      const json parameters = seg.contains("provenance") ? seg.at("provenance").value("parameters", json::object()) : json::object();
      if (parameters.contains("min_radius_mm")) in.min_radius_mm = parameters.at("min_radius_mm").get<double>();
      if (parameters.contains("max_radius_mm")) in.max_radius_mm = parameters.at("max_radius_mm").get<double>();
      if (seg.value("seed_source", "").rfind("automatic", 0) == 0) {
        const auto& sc = seg.at("head_center_mm");
        in.search_center = Eigen::Vector3d(sc.at(0).get<double>(), sc.at(1).get<double>(), sc.at(2).get<double>());
        in.search_radius_mm = seg.value("search_radius_mm", 0.0);
        if (seg.contains("side_check")) in.side_verified = seg.value("side_check", "") != "not verified";
        if (seg.contains("head_found_by")) in.found_by_edges = seg.value("head_found_by", "") == "edges";
        if (seg.contains("body_middle_x_mm") && seg.at("body_middle_x_mm").is_number())
          in.body_middle_x_mm = seg.at("body_middle_x_mm").get<double>();
      }
    } catch (const json::exception& e) {
      throw InputError("cannot read the segmentation summary '" + segment_summary.string() + "': " + e.what());
    }
  }
  return checks::checkHead(in);
}

// The subject's CT, read once for the checks against it and the slices; null
// with the reason when none is given or it cannot be read without options
// the report does not take (then both are left out, with a warning).
std::shared_ptr<const imaging::Volume> readSubjectCt(const SubjectReportOptions& o, std::string& why_not) {
  if (o.ct.empty()) {
    why_not = "No CT given (--ct).";
    return nullptr;
  }
  try {
    imaging::ReadOptions read;
    read.series_uid = o.series_uid;
    return imaging::readSharedVolume(o.ct, read, nullptr, o.memory);
  } catch (const Error& e) {
    why_not = std::string("No CT slices: ") + e.what();
    log::warn(std::string("report: the head checks against the CT are left out: ") + e.what());
    return nullptr;
  }
}

// The report's CT slices through the selected model, or a note why there
// are none (no CT, a model that cannot be drawn): they show, they decide nothing.
std::string slicesThroughHead(const SubjectReportOptions& o, const imaging::Volume* ct, const std::string& why_not,
                              const std::vector<geometry::ShapeParameters>& shapes, const std::string& selected) {
  if (!ct) return "<p class=\"note\">" + report::escapeMarkup(why_not) + "</p>";
  try {
    geometry::ShapeParameters model;
    for (const auto& shape : shapes)
      if (geometry::modelName(shape.model) == selected) model = shape;
    std::optional<imaging::Label> label;
    if (fs::exists(o.folder / "label.nii.gz")) label = imaging::readLabel(o.folder / "label.nii.gz", false, o.memory);
    return headSlicesHtml(*ct, label ? &*label : nullptr, model, 1.6 * model.radii.maxCoeff(),
                          std::min(0.5, ct->geometry.spacing.minCoeff()));
  } catch (const Error& e) {
    return "<p class=\"note\">No CT slices: " + report::escapeMarkup(e.what()) + "</p>";
  }
}

// Where the bone's mesh departs from the selected model over the cap
// (checks/cap_departures.hpp); none without the mesh.
std::optional<checks::CapDepartures> departuresFromModel(const Eigen::MatrixX3d& points, const std::optional<points::MeshFile>& bone,
                                                 const geometry::ShapeParameters& model, const imaging::Volume* ct,
                                                 const std::string& joint, const std::string& side) {
  if (!bone) return std::nullopt;
  const points::MeshFile& mesh = *bone;
  checks::CapDepartureInput in;
  in.vertices = mesh.vertices;
  in.triangles = mesh.triangles;
  in.model = model;
  in.points = points;
  if (ct) in.voxel_mm = ct->geometry.spacing.maxCoeff();
  in.ct = ct;
  in.seek_junction_lip = joint == "hip";
  // LPS: +x is the patient's left, so a right hip's medial side is +x.
  if (joint == "hip" && (side == "right" || side == "left")) in.medial = Eigen::Vector3d(side == "right" ? 1 : -1, 0, 0);
  return checks::capDepartures(in);
}

// The bone's triangles whose corners all lie in one departing region (a
// fovea aside), for the 3-D view.
report::ViewSurface departingSurface(const points::MeshFile& bone, const checks::CapDepartures& departures) {
  const auto region = [&departures](int v) { return departures.region_of_vertex[static_cast<size_t>(v)]; };
  return meshPart(bone, "departing from the model", [&](Eigen::Index f) {
    const int r = region(bone.triangles(f, 0));
    return r >= 0 && region(bone.triangles(f, 1)) == r && region(bone.triangles(f, 2)) == r &&
           departures.regions[static_cast<size_t>(r)].kind != "fovea";
  });
}

}  // namespace

checks::QcReport writeSubjectReport(const SubjectReportOptions& o) {
  const fs::path fits_path = o.folder / "fits.json", summary_path = o.folder / "errors" / "summary.json";
  const json fits = readStageJson(fits_path), summary = readStageJson(summary_path);
  std::map<std::string, json> errors_by_model;
  try {
    for (const auto& row : summary.at("models")) errors_by_model[row.at("model").get<std::string>()] = row;
  } catch (const json::exception& e) {
    throw InputError("cannot read the error summary '" + summary_path.string() + "': " + e.what());
  }
  const auto shapes = fit::shapesFromFitsJson(fits, fits_path.string());
  const std::string best = fits.value("least_rms_model", fits.value("best_model", ""));
  json models = json::array();
  std::vector<std::string> csv_header = {"model", "n_parameters", "aic", "bic", "least_rms"};
  std::string csv_rows;
  for (size_t model_index = 0; model_index < shapes.size(); ++model_index) {
    const geometry::ShapeParameters& shape = shapes[model_index];
    const json& fit_entry = fits.at("models")[model_index];
    const std::string name = geometry::modelName(shape.model);
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
    // The parameters the surface pins down (an ovoid's scales c0x, c0y are its gauge): the
    // nested tests' degrees of freedom and AIC / BIC count these.
    const int k = geometry::freeParameterCount(shape.model);
    const int n = errors.value("n_points", 0);
    const double sse = errors.value("sse_mm2", 0.0);
    json entry = {{"model", name}, {"n_parameters", k}, {"parameters", parameters}, {"errors", errors}};
    const Eigen::Vector3d semi = geometry::semiAxes(shape);
    entry["semi_axes_mm"] = {semi[0], semi[1], semi[2]};
    // Standard errors in the parameters' units (angles in degrees); null:
    // not identifiable from these points (fits.json, fit/uncertainty.hpp).
    const auto inUnits = [&](const json& se) {
      json out = json::object();
      for (size_t i = 0; i < names.size(); ++i) {
        json v = se.value(names[i], json(nullptr));
        if (v.is_number() && kinds[i] == geometry::ParameterKind::Angle) v = v.get<double>() * 180.0 / M_PI;
        out[withUnit(names[i], kinds[i])] = v;
      }
      return out;
    };
    if (fit_entry.contains("standard_errors_table_3_2")) {
      const json& se = fit_entry.at("standard_errors_table_3_2");
      entry["standard_errors"] = inUnits(se);
      // Their part from the edge offset over the surface (fits.json's edge_offset_field).
      if (fit_entry.contains("edge_offset_standard_errors_table_3_2"))
        entry["edge_offset_standard_errors"] = inUnits(fit_entry.at("edge_offset_standard_errors_table_3_2"));
      entry["not_identifiable"] = fit_entry.value("not_identifiable", json::array());
      entry["gauge"] = fit_entry.value("gauge", json::array());
      // The semi-axes' standard errors: an ovoid's a c0x and b c0y with c0 held.
      const json sa = se.value("a", json(nullptr)), sb = se.value("b", sa), sc = se.value("c", sa);
      const auto scaled = [](const json& v, double f) { return v.is_number() ? json(v.get<double>() * f) : json(nullptr); };
      const bool ovoid = shape.model == geometry::ShapeModel::Ovoid || shape.model == geometry::ShapeModel::Superovoid;
      entry["semi_axes_se_mm"] = {scaled(sa, ovoid ? shape.cx[0] : 1.0), scaled(sb, ovoid ? shape.cy[0] : 1.0), scaled(sc, 1.0)};
    }
    if (fit_entry.contains("residual_correlation")) entry["residual_correlation"] = fit_entry.at("residual_correlation");
    if (fit_entry.contains("other_optima_spanned")) entry["other_optima_spanned"] = fit_entry.at("other_optima_spanned");
    if (n > k && sse > 0) {
      entry["aic"] = statistics::aic(sse, n, k);
      entry["bic"] = statistics::bic(sse, n, k);
    }
    models.push_back(entry);
  }
  // The model these points support (see statistics::selectNested), the points counted as
  // the cap's effective number at the surface's correlation length.
  const points::PointCloud cloud = points::readPoints(o.folder / "points.ply");
  const double selection_n_eff =
      o.selection_length_mm > 0 ? fit::nEffectiveAtLength(cloud.positions, o.selection_length_mm) : NAN;
  std::vector<statistics::ModelEvidence> evidence;
  for (size_t i = 0; i < models.size(); ++i) {
    const json& m = models[i];
    const json& fit_entry = fits.at("models")[i];
    statistics::ModelEvidence e;
    e.model = m.at("model");
    e.n_parameters = m.at("n_parameters");
    e.n_points = m.at("errors").value("n_points", fits.value("n_points", 0));
    e.sse_mm2 = m.at("errors").value("sse_mm2", fit_entry.value("geometric_objective_mm2", NAN));
    if (std::isfinite(selection_n_eff))
      e.n_eff = selection_n_eff;
    else if (fit_entry.contains("residual_correlation") && fit_entry.at("residual_correlation").is_object())
      e.n_eff = fit_entry.at("residual_correlation").value("n_eff", NAN);
    // An ovoid's c0x and c0y are its gauge (fits.json "gauge"), never listed as not identifiable.
    e.determined = statistics::determinedByPoints(shapes[i].model, m.value("not_identifiable", std::vector<std::string>{}));
    e.edge_offset_absorbed_mm2 = fit_entry.value("edge_offset_absorbed_mm2", 0.0);
    e.edge_offset_absorbed_terms_mm2 = fit::absorbedTermsFromJson(fit_entry);
    evidence.push_back(e);
  }
  const statistics::ModelSelection selection = statistics::selectNested(evidence, o.selection_alpha);
  // Per model, the hierarchy's step into it (the superovoid's from its
  // parent of the lower SSE, as the fit started it).
  std::map<std::string, statistics::NestedStep> step_into;
  for (const statistics::NestedStep& st : selection.steps) {
    const auto sse = [&evidence](const std::string& name) {
      for (const auto& e : evidence)
        if (e.model == name) return e.sse_mm2;
      return static_cast<double>(NAN);
    };
    if (!step_into.count(st.richer) || sse(st.simpler) < sse(step_into[st.richer].simpler)) step_into[st.richer] = st;
  }
  csv_header.insert(csv_header.end(), {"selected", "n_eff", "step_from", "step_f", "step_p_value", "richer_needed"});
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
    const json& rc = m.contains("residual_correlation") ? m.at("residual_correlation") : json::object();
    f.push_back(rc.contains("n_eff") && rc.at("n_eff").is_number() ? number(rc.at("n_eff").get<double>()) : "");
    const auto st = step_into.find(m.at("model").get<std::string>());
    const bool stepped = st != step_into.end();
    f.push_back(stepped ? st->second.simpler : "");
    f.push_back(stepped && std::isfinite(st->second.f) ? number(st->second.f) : "");
    f.push_back(stepped && std::isfinite(st->second.p_value) ? number(st->second.p_value) : "");
    f.push_back(stepped ? (st->second.richer_needed ? "1" : "0") : "");
    for (const auto& c : error_columns) f.push_back(m.at("errors").contains(c) ? number(m.at("errors").at(c).get<double>()) : "");
    for (const auto& c : parameter_columns)
      f.push_back(m.at("parameters").contains(c) ? number(m.at("parameters").at(c).get<double>()) : "");
    csv_rows += csvLine(f) + "\n";
  }
  // The head centre and axes of the selected model (one the points
  // determine, unlike the least-RMS model at times), for 3D Slicer and
  // results.json.
  geometry::ShapeParameters selected_shape = shapes.front();  // the selection names one of them
  for (const auto& shape : shapes)
    if (geometry::modelName(shape.model) == selection.selected) selected_shape = shape;
  const Eigen::Matrix3d R = geometry::rotationFromAngles(selected_shape.angles);
  const Eigen::Vector3d c = selected_shape.center;
  std::vector<LandmarkLine> axes;
  const char* axis_names[3] = {"axis_a", "axis_b", "axis_c"};
  for (int i = 0; i < 3; ++i)
    axes.push_back({axis_names[i], c - geometry::semiAxes(selected_shape)[i] * R.col(i), c + geometry::semiAxes(selected_shape)[i] * R.col(i)});

  json steps_json = json::array(), path_json = json::array();
  for (const statistics::NestedStep& st : selection.steps) steps_json.push_back(stepJson(st));
  for (const statistics::NestedStep& st : selection.path) path_json.push_back(stepJson(st));

  std::string no_ct;
  const std::shared_ptr<const imaging::Volume> ct = readSubjectCt(o, no_ct);
  std::optional<points::MeshFile> bone;
  if (fs::exists(o.folder / "bone.vtp")) bone = points::readMeshFile(o.folder / "bone.vtp");
  const std::optional<checks::CapDepartures> departures =
      departuresFromModel(cloud.positions, bone, selected_shape, ct.get(), o.joint, o.side);
  const checks::QcReport qc = checkSubjectHead(o.folder, cloud, o.joint, shapes, ct.get(), departures);
  // The head centre, and where the bone departs from the selected model.
  std::vector<Landmark> landmarks = {{"head_center", c}};
  if (departures)
    for (size_t k = 0; k < departures->regions.size(); ++k) {
      const checks::DepartingRegion& region = departures->regions[k];
      landmarks.push_back({"departure_" + std::to_string(k + 1) + " (" + region.kind + ", " + number(std::round(region.area_mm2)) +
                               " mm2, " + number(std::round(10 * region.depth_mm) / 10) + " mm)",
                           region.centre});
    }
  writeSlicerMarkups(o.folder / "head.mrk.json", selection.selected + " head (articula)", landmarks, axes);
  SlicerSceneContent scene;
  scene.markups = writeSlicerMarkupsPerNode(o.folder / "slicer", selection.selected + " head (articula)", landmarks, axes);

  Provenance provenance;
  provenance.inputs = {o.ct.has_filename() && fs::is_regular_file(o.ct) ? o.ct : fs::path(), fits_path, summary_path};
  provenance.inputs.erase(std::remove(provenance.inputs.begin(), provenance.inputs.end(), fs::path()), provenance.inputs.end());
  provenance.seed = o.seed;
  provenance.parameters = {{"joint", o.joint},
                           {"side", o.side},
                           {"input", o.ct.string()},
                           {"selection_alpha", o.selection_alpha},
                           {"selection_length_mm", o.selection_length_mm}};
  const json results = {
      {"input", o.ct.string()},
      {"joint", o.joint},
      {"side", o.side},
      {"selected_model", selection.selected},
      {"least_rms_model", best},
      {"edge_offset_field", fits.value("edge_offset_field", json(nullptr))},
      {"selection",
       {{"rule",
         "each model the points determine (not undetermined) is tested against every determined model containing it "
         "(F = (SSE_simpler - SSE_richer) / (s2 x df1 + mu) on (df1_effective, df2) degrees of freedom, "
         "s2 = SSE_richer / df2 x n / n_eff, df1 the extra free parameters, df2 = n - the richer model's, mu the edge "
         "offset field's expected part of the fall; df1_effective matches the variance of the noise's and the field's "
         "parts (Satterthwaite; df1 without a field); n_eff the points' effective number of independent points for "
         "errors correlated over length_mm; with length_mm 0, the geometric mean of the two models' from their "
         "residuals) at alpha / their number; a model "
         "is supported when it is the simplest or needed over every supported model it contains; the selected model "
         "is the simplest supported one that no model containing it beats"},
        {"alpha", o.selection_alpha},
        {"length_mm", o.selection_length_mm},
        {"n_eff", std::isfinite(selection_n_eff) ? json(selection_n_eff) : json(nullptr)},
        {"steps", steps_json},
        {"path", path_json},
        {"undetermined", selection.undetermined}}},
      {"head_center_mm", {c[0], c[1], c[2]}},
      {"qc", qc.toJson()},
      {"cap_departures", departures ? departures->toJson() : json(nullptr)},
      {"libraries",
       {{"ITK", imaging::itkVersion()},
        {"VTK", points::vtkLibraryVersion()},
        {"CGAL", sampling::cgalVersion()},
        {"NLopt", fit::nloptVersion()},
        {"Eigen", fit::eigenVersion()}}},
      {"models", models},
      {"coordinate_system", "LPS"},
      {"units", "mm"},
      {"provenance", provenanceJson(provenance)}};
  writeFileAtomically(o.folder / "results.csv", csvLine(csv_header) + "\n" + csv_rows);
  writeFileAtomically(o.folder / "results.json", results.dump(2) + "\n");
  // The 3-D view and the Slicer scene show the same colourings.
  std::string view_html;
  scene.selected_model = selection.selected;
  scene.bone = fs::exists(o.folder / "bone.vtp");
  for (const auto& shape : shapes)
    if (fs::exists(o.folder / "errors" / ("points_" + geometry::modelName(shape.model) + ".vtp")))
      scene.models.push_back(geometry::modelName(shape.model));
  try {
    report::View3d view = loadHeadView(o.folder, shapes, selection.selected);
    if (bone && departures) view.departures = departingSurface(*bone, *departures);
    // One colour, one distance: the error maps' scale on the view and in Slicer.
    std::vector<report::ErrorMapPanel> panels;
    for (const auto& d : view.distances) panels.push_back({d.model, d.signed_distance_mm});
    if (!panels.empty()) view.colour_range_mm = report::sharedColourLimit(panels);
    for (const auto& d : view.distances) scene.colour_range_mm[d.model] = view.colour_range_mm;
    view_html = report::web3dViewHtml(view);
  } catch (const Error& e) {
    view_html = "<section id=\"view3d\"><h2>3-D view</h2><p class=\"note\">No 3-D view: " + report::escapeMarkup(e.what()) +
                "</p></section>\n";
  }
  writeFileAtomically(o.folder / "scene.mrml", slicerSceneXml(scene));
  writeFileAtomically(o.folder / "report.html",
                      subjectReportHtml(results, o.folder, slicesThroughHead(o, ct.get(), no_ct, shapes, selection.selected), view_html));
  return qc;
}

}  // namespace articula::subject
