#pragma once
// The fits.json contract (docs/formats.md): one entry of `models` per fitted model
// with "model", "center_mm", "radii_mm", "rotation_deg" [phi, theta, psi],
// "rotation_matrix", "exponents", "cx", "cy", objective values and the
// optimiser's report; plus top-level "least_rms_model" (files before it: "best_model").
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "articula/fit/fit_hierarchy.hpp"

namespace articula::fit {

/// One entry of fits.json "models".
nlohmann::json modelFitJson(const ModelFit& fit);

/// The whole fits.json document of a fitted hierarchy: LPS mm, the points'
/// file and count, the objective, the least-RMS model, every model's entry
/// and `provenance` (core/provenance.hpp's JSON).
nlohmann::json fitsDocument(const Summary& summary, const std::string& input, const std::string& objective,
                            const nlohmann::json& provenance);

/// The shape of one fits.json "models" entry; throws InputError naming the
/// missing or malformed key and `where` (e.g. the file name and index).
geometry::ShapeParameters shapeFromJson(const nlohmann::json& entry, const std::string& where);

/// A "models" entry's edge_offset_absorbed_terms_mm2 (a square matrix), else
/// empty: an older or foreign fits.json, whose selection then takes the
/// field's sum as carried by one term (statistics/model_selection.hpp).
Eigen::MatrixXd absorbedTermsFromJson(const nlohmann::json& entry);

/// Every shape of a fits.json document, in file order.
std::vector<geometry::ShapeParameters> shapesFromFitsJson(const nlohmann::json& document, const std::string& where);

}  // namespace articula::fit
