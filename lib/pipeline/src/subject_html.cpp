#include "articula/pipeline/subject_html.hpp"

#include <cmath>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <sstream>
#include <vector>

#include "articula/core/json_file.hpp"
#include "articula/report/html_page.hpp"
#include "articula/report/markup_text.hpp"
#include "results_json.hpp"

namespace articula::pipeline {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using namespace detail;  // the results.json readers

std::string fixed(double v, int digits) {
  if (!std::isfinite(v)) return "-";
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*f", digits, v);
  return buffer;
}

// "22.72 ± 0.19" (the 95 % interval's half width), the value alone, or the
// value marked as one the points do not determine (in the model's
// not_identifiable: its name is the key without its unit).
std::string withInterval(const json& model, const std::string& key, int digits) {
  const double v = numberAt(member(model, "parameters"), key);
  const std::string name = key.substr(0, key.find('_'));
  for (const auto& open : member(model, "not_identifiable"))
    if (open.is_string() && open.get<std::string>() == name)
      return fixed(v, digits) + " <span class=\"note\">(not determined)</span>";
  const double se = numberAt(member(model, "standard_errors"), key);
  return fixed(v, digits) + (std::isfinite(se) ? " &plusmn; " + fixed(1.96 * se, digits) : "");
}

// An errors-stage figure, inlined; a note when it is missing.
std::string inlineSvg(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream content;
  content << in.rdbuf();
  std::string svg = content.str();
  const size_t start = svg.find("<svg");
  if (!in || start == std::string::npos) return "<p class=\"missing\">" + report::escapeMarkup(path.filename().string()) + " not found</p>";
  return "<figure>" + svg.substr(start) + "</figure>";
}

json optionalJson(const fs::path& path) { return readJsonFileIfValid(path).value_or(json::object()); }

std::string utcNow() {
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  char buffer[32];
  std::strftime(buffer, sizeof buffer, "%Y-%m-%d %H:%M UTC", &utc);
  return buffer;
}

std::string verdictSection(const json& results) {
  const json& qc = member(results, "qc");
  const std::string status = qc.is_object() ? qc.value("status", "unknown") : "unknown", selected = results.value("selected_model", "");
  std::string html = "<section id=\"verdict\"><h2>Verdict</h2>\n<p class=\"status " + report::escapeMarkup(status) +
                     "\">Checks: <strong>" + report::escapeMarkup(status) + "</strong></p>\n";
  const json& reasons = member(qc, "reasons");
  if (reasons.is_array() && !reasons.empty()) {
    html += "<ul class=\"reasons\">";
    for (const auto& r : reasons) html += "<li>" + report::escapeMarkup(r.is_string() ? r.get<std::string>() : r.dump()) + "</li>";
    html += "</ul>\n";
  }
  html += "<table><tr><th>selected model</th><td id=\"selected-model\">" + report::escapeMarkup(selected) +
          "</td></tr>\n<tr><th>least RMS</th><td>" + report::escapeMarkup(results.value("best_model", "")) + "</td></tr>\n";
  std::string open_models;
  for (const auto& m : member(member(results, "selection"), "undetermined"))
    open_models += (open_models.empty() ? "" : ", ") + report::escapeMarkup(m.is_string() ? m.get<std::string>() : "");
  if (!open_models.empty())
    html += "<tr><th>not determined by the points (not selectable)</th><td id=\"undetermined\">" + open_models + "</td></tr>\n";
  if (const json* m = modelNamed(results, selected)) {
    html += "<tr><th>head centre (mm, LPS)</th><td id=\"head-centre\">" + withInterval(*m, "t1_mm", 2) + ", " +
            withInterval(*m, "t2_mm", 2) + ", " + withInterval(*m, "t3_mm", 2) + "</td></tr>\n";
    const json& parameters = member(*m, "parameters");
    std::string radii;
    for (const char* key : {"a_mm", "b_mm", "c_mm"})
      if (parameters.contains(key)) radii += (radii.empty() ? "" : ", ") + withInterval(*m, key, 2);
    html += "<tr><th>radii (mm)</th><td id=\"radii\">" + radii + "</td></tr>\n";
    const json& semi_axes = member(*m, "semi_axes_mm");
    if (semi_axes.is_array() && semi_axes.size() == 3 && parameters.contains("c0x"))
      html += "<tr><th>semi-axes through the centre (mm): a&middot;c0x, b&middot;c0y, c</th><td id=\"semi-axes\">" +
              fixed(semi_axes[0].is_number() ? semi_axes[0].get<double>() : NAN, 2) + ", " +
              fixed(semi_axes[1].is_number() ? semi_axes[1].get<double>() : NAN, 2) + ", " +
              fixed(semi_axes[2].is_number() ? semi_axes[2].get<double>() : NAN, 2) +
              " <span class=\"note\">(an ovoid's a and b share their scale with c0x and c0y; these products are its "
              "shape)</span></td></tr>\n";
    html += "<tr><th>RMS error (mm)</th><td id=\"rms\">" +
            fixed(numberAt(member(*m, "errors"), "rms_mm"), 3) + "</td></tr>\n";
  }
  return html + "</table>\n<p class=\"note\">&plusmn;: half the 95 % interval (1.96 standard errors of the fit).</p></section>\n";
}

std::string checksSection(const json& results) {
  std::string html = "<section id=\"checks\"><h2>Checks of the head</h2>\n<table><tr><th>check</th><th>value</th>"
                     "<th>rule</th><th>status</th><th>reason</th></tr>\n";
  for (const auto& c : member(member(results, "qc"), "checks"))
    html += "<tr class=\"" + report::escapeMarkup(text(c, "status")) + "\"><td>" + report::escapeMarkup(text(c, "name")) + "</td><td>" +
            fixed(numberAt(c, "value"), 3) + "</td><td>" + report::escapeMarkup(text(c, "rule")) + "</td><td>" +
            report::escapeMarkup(text(c, "status")) + "</td><td>" + report::escapeMarkup(text(c, "reason")) + "</td></tr>\n";
  return html + "</table></section>\n";
}

// What the articular selection left out: where the bone departs from the
// selected model over its cap (results.json's cap_departures).
std::string departuresSection(const json& results) {
  const json& d = member(results, "cap_departures");
  if (!d.is_object()) return "";
  std::string html = "<section id=\"departures\"><h2>Where the bone departs from the model</h2>\n<p class=\"note\">The bone's "
                     "surface over the articular cap and its rim, measured against the selected model: regions beyond " +
                     fixed(numberAt(d, "threshold_mm"), 2) + " mm (the largest of 0.75 mm, three times the points' scatter and 0.3 voxel) and of " +
                     fixed(numberAt(d, "min_region_mm2"), 0) + " mm&sup2; or more. The points leave them out, so the model "
                     "describes the rest of the cap. Landmarks departure_1, ... in head.mrk.json; red in the 3-D view.</p>\n";
  const json& regions = member(d, "regions");
  if (!regions.is_array() || regions.empty()) return html + "<p>None: the bone follows the model over the cap.</p></section>\n";
  html += "<table><tr><th>region</th><th>kind</th><th>area (mm&sup2;)</th><th>depth (mm)</th><th>where</th>"
          "<th>centre (LPS mm)</th></tr>\n";
  int k = 0;
  for (const auto& r : regions) {
    const json& centre = member(r, "centre_mm");
    std::string at;
    for (int i = 0; i < 3 && centre.is_array() && centre.size() == 3; ++i)
      at += (i ? ", " : "") + fixed(centre[static_cast<size_t>(i)].is_number() ? centre[static_cast<size_t>(i)].get<double>() : NAN, 1);
    const std::string kind = text(r, "kind");
    html += "<tr><td>departure_" + std::to_string(++k) + "</td><td>" +
            report::escapeMarkup(kind == "fovea" ? "fovea (a pit at the medial pole: anatomy)" : kind) + "</td><td>" +
            fixed(numberAt(r, "area_mm2"), 0) + "</td><td>" + fixed(numberAt(r, "depth_mm"), 1) + "</td><td>" +
            report::escapeMarkup(text(r, "where")) + "</td><td>" + at + "</td></tr>\n";
  }
  return html + "</table></section>\n";
}

std::string modelsSection(const json& results) {
  const std::string selected = results.value("selected_model", ""), best = results.value("best_model", "");
  std::string html = "<section id=\"models\"><h2>Models</h2>\n<table><tr><th>model</th><th>parameters</th>"
                     "<th>RMS (mm)</th><th>mean |d| (mm)</th><th>max |d| (mm)</th><th>AIC</th><th>BIC</th><th></th></tr>\n";
  for (const auto& m : member(results, "models")) {
    const json& errors = member(m, "errors");
    const std::string name = m.value("model", "");
    const double max_abs = std::max(std::fabs(numberAt(errors, "min_mm")), std::fabs(numberAt(errors, "max_mm")));
    std::string marks = name == selected ? "selected" : "";
    if (name == best) marks += marks.empty() ? "least RMS" : ", least RMS";
    html += "<tr data-model=\"" + report::escapeMarkup(name) + "\"><td>" + report::escapeMarkup(name) + "</td><td>" +
            std::to_string(m.value("n_parameters", 0)) + "</td><td class=\"rms\">" + fixed(numberAt(errors, "rms_mm"), 3) +
            "</td><td>" + fixed(numberAt(errors, "mean_abs_mm"), 3) + "</td><td>" + fixed(max_abs, 3) + "</td><td>" +
            fixed(numberAt(m, "aic"), 1) + "</td><td>" + fixed(numberAt(m, "bic"), 1) + "</td><td>" + marks + "</td></tr>\n";
  }
  html += "</table>\n";
  for (const auto& m : member(results, "models")) {
    html += "<details><summary>" + report::escapeMarkup(m.value("model", "")) + ": parameters</summary><table>";
    for (const auto& [key, value] : member(m, "parameters").items())
      html += "<tr><th>" + report::escapeMarkup(key) + "</th><td>" + withInterval(m, key, 4) + "</td></tr>";
    html += "</table></details>\n";
  }
  return html + "</section>\n";
}

std::string methodsParagraph(const json& results, const fs::path& folder) {
  const json& provenance = member(results, "provenance");
  const json segment = optionalJson(folder / "label.nii.gz.json"), sample = optionalJson(folder / "points.ply.json"),
             mesh = optionalJson(folder / "bone.vtp.json");
  const std::string selected = results.value("selected_model", "");
  const json& selection = member(results, "selection");
  std::ostringstream p;
  p << "The " << results.value("side", "") << " " << (results.value("joint", "") == "shoulder" ? "humeral" : "femoral")
    << " head was analysed with articula " << text(provenance, "articula_version") << " (commit "
    << text(provenance, "git_commit") << "). ";
  const std::string seed_source = text(segment, "seed_source");
  p << "It was segmented from the CT " << (seed_source.rfind("automatic", 0) == 0 ? "automatically (a search for the "
                                                                                     "joint head, then a marker watershed)"
                                                                                   : "from a given seed point (marker watershed)");
  if (segment.contains("spacing_mm") && segment.at("spacing_mm").is_array() && segment.at("spacing_mm").size() == 3)
    p << " at voxels of " << fixed(segment.at("spacing_mm")[0].get<double>(), 2) << " x "
      << fixed(segment.at("spacing_mm")[1].get<double>(), 2) << " x " << fixed(segment.at("spacing_mm")[2].get<double>(), 2)
      << " mm";
  p << "; its surface was extracted by marching cubes and smoothing";
  const json& edges = member(mesh, "ct_edges");
  if (member(edges, "moved") == true) {
    p << " and moved onto the CT's bone edge (sub-voxel: the steepest fall of the HU profile along each normal";
    if (text(edges, "edge_model") == "cortex")
      p << ", then the outer surface of a blurred-cortex model fitted to the voxels about it, with the scanner's "
        << "Gaussian point-spread " << (member(edges, "point_spread_estimated") == true ? "estimated from the CT" : "given")
        << ": " << fixed(numberAt(edges, "point_spread_mm"), 2) << " mm within the slices and "
        << fixed(numberAt(edges, "slice_point_spread_mm"), 2) << " mm across them"
        << (text(edges, "point_spread_applied") == "voxel_grid" ? ", applied to the voxels as an image filter does" : "");
    p << ")";
  }
  p << ". The articular surface was selected and down-sampled to ";
  const json* m = modelNamed(results, selected);
  const double n_points = m ? numberAt(member(*m, "errors"), "n_points") : NAN;
  p << (n_points > 0 ? fixed(n_points, 0) : std::string("its")) << " points with normals";
  if (sample.contains("selected_points")) p << " (of " << text(sample, "selected_points") << " selected)";
  p << ". Five implicit shape models (sphere, ellipsoid, superellipsoid, ovoid, superovoid) were fitted in a hierarchy, "
       "each from its parent's fit, by least squares of the exact signed Euclidean distances of the points. The "
    << selected << " was selected as the simplest model whose RMS error exceeded the least by at most the larger of "
    << fixed(100 * numberAt(selection, "relative_tolerance"), 0) << " % and "
    << fixed(numberAt(selection, "absolute_tolerance_mm"), 2) << " mm";
  if (m) {
    const json& parameters = member(*m, "parameters");
    p << "; its RMS error was " << fixed(numberAt(member(*m, "errors"), "rms_mm"), 2) << " mm and its centre lay at ("
      << fixed(numberAt(parameters, "t1_mm"), 1) << ", " << fixed(numberAt(parameters, "t2_mm"), 1) << ", "
      << fixed(numberAt(parameters, "t3_mm"), 1) << ") mm (LPS)";
  }
  const std::string status = text(member(results, "qc"), "status");
  p << ". The result's checks were " << (status.empty() ? "not run" : status) << ".";
  return p.str();
}

std::string aboutSection(const json& results, const fs::path& folder) {
  const json& provenance = member(results, "provenance");
  std::string html = "<section id=\"about\"><h2>About</h2>\n<table>";
  html += "<tr><th>articula</th><td>" + report::escapeMarkup(text(provenance, "articula_version")) + " (commit " +
          report::escapeMarkup(text(provenance, "git_commit")) + ")</td></tr>";
  // The command the user typed first; the report stage's own when a run ran it.
  const std::string invoked_by = text(provenance, "invoked_by");
  html += "<tr><th>command</th><td><code>" + report::escapeMarkup(invoked_by.empty() ? text(provenance, "command") : invoked_by) +
          "</code></td></tr>";
  if (!invoked_by.empty())
    html += "<tr><th>its report stage</th><td><code>" + report::escapeMarkup(text(provenance, "command")) + "</code></td></tr>";
  html += "<tr><th>written</th><td>" + utcNow() + "</td></tr>";
  html += "<tr><th>input</th><td>" + report::escapeMarkup(results.value("input", "")) + "</td></tr>";
  for (const auto& [key, value] : member(provenance, "parameters").items())
    if (key != "input")  // shown above
      html += "<tr><th>" + report::escapeMarkup(key) + "</th><td>" +
              report::escapeMarkup(value.is_string() ? value.get<std::string>() : value.dump()) + "</td></tr>";
  for (const auto& input : member(provenance, "inputs"))
    html += "<tr><th>SHA-256</th><td>" + report::escapeMarkup(text(input, "path")) + ": <code>" + report::escapeMarkup(text(input, "sha256")) +
            "</code></td></tr>";
  html += "</table>\n<h3>Methods</h3>\n<p id=\"methods\">" + report::escapeMarkup(methodsParagraph(results, folder)) + "</p>\n";
  return html + "<p class=\"note\">Coordinates are LPS millimetres, as in ITK and 3D Slicer. The numbers of this page are "
                "those of results.json beside it.</p></section>\n";
}

constexpr const char* kStyle = R"(body{font-family:sans-serif;max-width:1000px;margin:1em auto;padding:0 1em;color:#222}
table{border-collapse:collapse;margin:.5em 0}th,td{border:1px solid #ccc;padding:.2em .5em;text-align:left}
th{background:#f4f4f4}.status{font-size:1.3em}.status.pass{color:#176f2c}.status.warn{color:#a15c00}
.status.fail{color:#b00020}tr.fail td{background:#fde7e9}tr.warn td{background:#fff4e0}figure{margin:1em 0}
figure svg{max-width:100%;height:auto}.slices{display:flex;flex-wrap:wrap;gap:.5em}
.slices figure{margin:0;max-width:240px}.slices figcaption{font-size:.85em}
.view3d-controls label{margin-right:1em}.colour-bar{display:flex;align-items:center;gap:.5em;max-width:960px;margin:.3em 0}
.colour-bar .bar{flex:1;height:12px;border:1px solid #999}.note{color:#666;font-size:.9em}code{font-size:.9em})";

}  // namespace

std::string subjectReportHtml(const json& results, const fs::path& folder, const std::string& slices_html,
                              const std::string& view_html) {
  const std::string title = "articula: " + results.value("side", "") + " " + results.value("joint", "") + " head";
  std::string html = report::htmlPageStart(title, kStyle) + "<h1>" + report::escapeMarkup(title) + "</h1>\n<p>" +
                     report::escapeMarkup(results.value("input", "")) + "</p>\n";  // A subject of a study (STUDY/subjects/<id>/): the way back to its study page.
  if (fs::absolute(folder).lexically_normal().parent_path().filename() == "subjects")
    html += "<p><a href=\"../../study.html\">&larr; the study</a></p>\n";
  html += verdictSection(results);
  html += view_html;
  html += "<section id=\"slices\"><h2>CT through the head</h2>\n<p class=\"note\">The selected model's outline in "
          "magenta, the segmentation's edge in yellow; radiological view (the patient's left on the right).</p>\n" +
          slices_html + "</section>\n";
  html += checksSection(results);
  html += departuresSection(results);
  html += modelsSection(results);
  html += "<section id=\"errors\"><h2>Signed distances of the points to each model</h2>\n" +
          inlineSvg(folder / "errors" / "histogram.svg") + "\n" + inlineSvg(folder / "errors" / "error_map.svg") +
          "\n</section>\n";
  html += aboutSection(results, folder);
  return html + "</body></html>\n";
}

}  // namespace articula::pipeline
