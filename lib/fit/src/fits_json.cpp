#include "articula/fit/fits_json.hpp"

#include <cmath>
#include <fstream>

#include "articula/core/error.hpp"
#include "articula/core/excerpt.hpp"
#include "articula/geometry/pose.hpp"

namespace articula::fit {

using geometry::ShapeModel;

namespace {
template <typename Vec>
std::vector<double> list(const Vec& v) {
  return std::vector<double>(v.data(), v.data() + v.size());
}

template <int N>
Eigen::Matrix<double, N, 1> vectorAt(const nlohmann::json& entry, const char* key, const std::string& where) {
  if (!entry.contains(key)) throw InputError(where + ": missing key \"" + key + "\"");
  const nlohmann::json& v = entry.at(key);
  if (!v.is_array() || v.size() != N)
    throw InputError(where + ": \"" + key + "\" expected an array of " + std::to_string(N) + " numbers, found " +
                     describeJson(v));
  Eigen::Matrix<double, N, 1> out;
  for (int i = 0; i < N; ++i) {
    if (!v[static_cast<size_t>(i)].is_number())
      throw InputError(where + ": \"" + key + "\" expected numbers, found " + describeJson(v[static_cast<size_t>(i)]));
    out[i] = v[static_cast<size_t>(i)].get<double>();
  }
  return out;
}
}  // namespace

nlohmann::json modelFitJson(const ModelFit& f) {
  const geometry::ShapeParameters& p = f.parameters;
  const Eigen::Vector3d radii = p.model == ShapeModel::Sphere ? Eigen::Vector3d::Constant(p.radii[0]) : p.radii;
  const Eigen::Matrix3d R = geometry::rotationFromAngles(p.angles);
  nlohmann::json parameters = nlohmann::json::object();
  const auto names = geometry::parameterNames(p.model);
  const Eigen::VectorXd lambda = geometry::toVector(p);
  for (size_t i = 0; i < names.size(); ++i) parameters[names[i]] = lambda[static_cast<Eigen::Index>(i)];
  // Standard errors and 95 % intervals (null: not identifiable from these points).
  const ParameterUncertainty& u = f.uncertainty;
  nlohmann::json errors = nlohmann::json::object(), intervals = nlohmann::json::object(),
                 systematic = nlohmann::json::object();
  const auto finite = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); };
  nlohmann::json absorbed_terms = nlohmann::json::array();
  for (Eigen::Index r = 0; r < u.edge_offset_absorbed_terms_mm2.rows(); ++r)
    absorbed_terms.push_back(list(Eigen::VectorXd(u.edge_offset_absorbed_terms_mm2.row(r).transpose())));
  if (u.standard_error.size() == static_cast<Eigen::Index>(names.size()))
    for (size_t i = 0; i < names.size(); ++i) {
      const auto k = static_cast<Eigen::Index>(i);
      errors[names[i]] = finite(u.standard_error[k]);
      if (u.systematic_standard_error.size() == u.standard_error.size())
        systematic[names[i]] = std::isfinite(u.standard_error[k]) ? nlohmann::json(u.systematic_standard_error[k]) : nlohmann::json(nullptr);
      intervals[names[i]] = std::isfinite(u.standard_error[k]) ? nlohmann::json{u.ci95_lower[k], u.ci95_upper[k]} : nlohmann::json(nullptr);
    }
  return {{"model", geometry::modelName(p.model)},
          {"center_mm", list(p.center)},
          {"radii_mm", list(radii)},
          {"rotation_deg", list(Eigen::Vector3d(p.angles * (180.0 / M_PI)))},
          {"rotation_matrix", {list(Eigen::Vector3d(R.row(0))), list(Eigen::Vector3d(R.row(1))),
                               list(Eigen::Vector3d(R.row(2)))}},
          {"exponents", list(p.exponents)},
          {"cx", list(p.cx)},
          {"cy", list(p.cy)},
          {"parameters_table_3_2", parameters},
          {"standard_errors_table_3_2", errors},
          {"ci95_table_3_2", intervals},
          {"edge_offset_standard_errors_table_3_2", systematic},
          {"edge_offset_absorbed_mm2", u.edge_offset_absorbed_mm2},
          {"edge_offset_absorbed_terms_mm2", absorbed_terms},
          {"not_identifiable", u.not_identifiable},
          {"gauge", u.gauge},
          {"uncertainty_method", u.method},
          {"residual_correlation",
           {{"nugget_mm2", u.correlation.nugget_mm2},
            {"sill_mm2", list(u.correlation.sill_mm2)},
            {"length_mm", list(u.correlation.length_mm)},
            {"correlated_share", u.correlation.correlatedShare()},
            {"n_eff", u.correlation.n_eff},
            {"n_points", u.correlation.n}}},
          {"condition_number", finite(u.condition_number)},
          {"other_optima_spanned", u.other_optima},
          {"other_optima_bound_mm2", u.other_optima_bound_mm2},
          {"rms_mm", f.rms_mm},
          {"geometric_objective_mm2", f.sse_mm2},
          {"algebraic_objective", f.algebraic_objective},
          {"evaluations", f.evaluations},
          {"seconds", f.seconds},
          {"started_from", f.started_from},
          {"termination", f.termination},
          {"termination_type", terminationName(f.termination_type)},
          {"converged", f.converged}};
}

geometry::ShapeParameters shapeFromJson(const nlohmann::json& entry, const std::string& where) {
  if (!entry.is_object()) throw InputError(where + ": expected an object, found " + describeJson(entry));
  if (!entry.contains("model") || !entry.at("model").is_string())
    throw InputError(where + ": missing string key \"model\"");
  geometry::ShapeParameters p;
  try {
    p.model = geometry::modelFromName(entry.at("model").get<std::string>());
  } catch (const UsageError& e) {
    throw InputError(where + ": " + e.what());
  }
  p.center = vectorAt<3>(entry, "center_mm", where);
  p.radii = vectorAt<3>(entry, "radii_mm", where);
  p.angles = vectorAt<3>(entry, "rotation_deg", where) * (M_PI / 180.0);
  p.exponents = vectorAt<3>(entry, "exponents", where);
  p.cx = vectorAt<4>(entry, "cx", where);
  p.cy = vectorAt<4>(entry, "cy", where);
  // What a model does not use must hold its neutral value: an ellipsoid with
  // exponents of 1.5 is not an ellipsoid, and silently dropping them would
  // report another surface than the file describes.
  const std::string model = entry.at("model").get<std::string>();
  const bool exponents_used = p.model == ShapeModel::Superellipsoid || p.model == ShapeModel::Superovoid;
  const bool coefficients_used = p.model == ShapeModel::Ovoid || p.model == ShapeModel::Superovoid;
  if (!exponents_used && p.exponents != Eigen::Vector3d::Constant(2.0))
    throw InputError(where + ": exponents " + describeJson(entry.at("exponents")) + " given for the model '" + model +
                     "', which has none: expected [2, 2, 2]");
  if (!coefficients_used && (p.cx != Eigen::Vector4d(1, 0, 0, 0) || p.cy != Eigen::Vector4d(1, 0, 0, 0)))
    throw InputError(where + ": ovoid coefficients cx " + describeJson(entry.at("cx")) + " and cy " +
                     describeJson(entry.at("cy")) + " given for the model '" + model + "', which has none: expected [1, 0, 0, 0]");
  if (p.model == ShapeModel::Sphere && !(p.radii.maxCoeff() == p.radii.minCoeff()))
    throw InputError(where + ": a sphere has three equal radii, found " + describeJson(entry.at("radii_mm")));
  // Joint heads and bodies measured in millimetres: beyond these, distances
  // lose their precision and the numbers reported would be noise.
  constexpr double kMaxLengthMm = 1e5;
  if (!(p.radii.maxCoeff() <= kMaxLengthMm) || !(p.center.cwiseAbs().maxCoeff() <= kMaxLengthMm))
    throw InputError(where + ": expected radii and centre coordinates within 1e5 mm, found radii " +
                     describeJson(entry.at("radii_mm")) + " and centre " + describeJson(entry.at("center_mm")));
  try {
    geometry::validate(p);
  } catch (const InvalidParameter& e) {
    throw InputError(where + ": " + e.what());
  }
  return p;
}

Eigen::MatrixXd absorbedTermsFromJson(const nlohmann::json& entry) {
  const nlohmann::json terms = entry.value("edge_offset_absorbed_terms_mm2", nlohmann::json::array());
  const auto n = static_cast<Eigen::Index>(terms.is_array() ? terms.size() : 0);
  Eigen::MatrixXd out(n, n);
  for (Eigen::Index r = 0; r < n; ++r) {
    const nlohmann::json& row = terms[static_cast<size_t>(r)];
    if (!row.is_array() || static_cast<Eigen::Index>(row.size()) != n) return {};
    for (Eigen::Index c = 0; c < n; ++c) {
      if (!row[static_cast<size_t>(c)].is_number()) return {};
      out(r, c) = row[static_cast<size_t>(c)].get<double>();
    }
  }
  return out;
}

std::vector<geometry::ShapeParameters> shapesFromFitsJson(const nlohmann::json& document, const std::string& where) {
  if (!document.is_object() || !document.contains("models") || !document.at("models").is_array() ||
      document.at("models").empty())
    throw InputError(where + ": expected a fits.json object with a non-empty array \"models\"");
  std::vector<geometry::ShapeParameters> shapes;
  for (size_t i = 0; i < document.at("models").size(); ++i)
    shapes.push_back(shapeFromJson(document.at("models")[i], where + ": models[" + std::to_string(i) + "]"));
  return shapes;
}

nlohmann::json fitsDocument(const Summary& summary, const std::string& input, const std::string& objective,
                            const nlohmann::json& provenance) {
  nlohmann::json models = nlohmann::json::array();
  for (const auto& f : summary.fits) models.push_back(modelFitJson(f));
  // The edge offset field in every model's intervals (the same for all).
  nlohmann::json field = nullptr;
  if (!summary.fits.empty() && summary.fits.front().uncertainty.edge_offset.active()) {
    const EdgeOffsetField& e = summary.fits.front().uncertainty.edge_offset;
    field = {{"voxel_spacing_mm", list(e.spacing_mm)},
             {"slice_axis_lps", list(e.slice_axis)},
             {"linear_sd_mm", e.linear_sd_mm},
             {"across_slices_sd_mm", e.across_slices_sd_mm},
             {"odd_across_slices_sd_mm", e.odd_across_slices_sd_mm}};
  }
  return {{"coordinate_system", "LPS"},
          {"units", "mm"},
          {"input", input},
          {"n_points", summary.points},
          {"objective", objective},
          {"least_rms_model", summary.best_model},
          {"edge_offset_field", field},
          {"seconds", summary.seconds},
          {"models", models},
          {"provenance", provenance}};
}

}  // namespace articula::fit
