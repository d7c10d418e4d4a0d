#include "articula/subject/subject_html.hpp"

#include <cmath>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <sstream>
#include <vector>

#include "articula/core/json_file.hpp"
#include "articula/report/html_page.hpp"
#include "articula/report/markup_text.hpp"
#include "articula/subject/results_json.hpp"

namespace articula::subject {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using namespace subject::results_json;

std::string fixed(double v, int digits) {
  if (!std::isfinite(v)) return "-";
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*f", digits, v);
  return buffer;
}

bool listed(const json& names, const std::string& name) {
  for (const auto& n : names)
    if (n.is_string() && n.get<std::string>() == name) return true;
  return false;
}

// "22.72 ± 0.19" (the 95 % interval's half width), the value alone, "not
// determined" for a parameter the points leave open (in the model's
// not_identifiable: its name is the key without its unit), or the value
// marked as held for an ovoid's gauge (c0x, c0y).
std::string withInterval(const json& model, const std::string& key, int digits) {
  const double v = numberAt(member(model, "parameters"), key);
  const std::string name = key.substr(0, key.find('_'));
  if (listed(member(model, "not_identifiable"), name)) return "<span class=\"note\">not determined</span>";
  if (listed(member(model, "gauge"), name))
    return fixed(v, digits) + " <span class=\"note\">(held: the scale it shares with " + (name == "c0x" ? "a" : "b") +
           ")</span>";
  const double se = numberAt(member(model, "standard_errors"), key);
  return fixed(v, digits) + (std::isfinite(se) ? " &plusmn; " + fixed(1.96 * se, digits) : "");
}

// The semi-axes through the centre with their intervals, "not determined"
// where the radius along them is open.
std::string semiAxesWithIntervals(const json& model) {
  const json& semi = member(model, "semi_axes_mm");
  const json& se = member(model, "semi_axes_se_mm");
  std::string out;
  const char* radius[3] = {"a", "b", "c"};
  for (size_t k = 0; k < 3 && semi.is_array() && semi.size() == 3; ++k) {
    out += k ? ", " : "";
    if (listed(member(model, "not_identifiable"), radius[k])) {
      out += "<span class=\"note\">not determined</span>";
      continue;
    }
    out += fixed(semi[k].is_number() ? semi[k].get<double>() : NAN, 2);
    if (se.is_array() && se.size() == 3 && se[k].is_number()) out += " &plusmn; " + fixed(1.96 * se[k].get<double>(), 2);
  }
  return out;
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
  html += "<table><tr><th>selected model</th><td id=\"selected-model\">" + report::escapeMarkup(selected) + "</td></tr>\n";
  const std::string least = text(results, "least_rms_model");
  if (!least.empty() && least != selected)
    html += "<tr><th>least RMS (not selected)</th><td id=\"least-rms\">" +
            report::escapeMarkup(least) + "</td></tr>\n";
  std::string open_models;
  for (const auto& m : member(member(results, "selection"), "undetermined"))
    open_models += (open_models.empty() ? "" : ", ") + report::escapeMarkup(m.is_string() ? m.get<std::string>() : "");
  if (!open_models.empty())
    html += "<tr><th>not determined by the points (not selectable)</th><td id=\"undetermined\">" + open_models + "</td></tr>\n";
  const json* chosen = modelNamed(results, selected);
  // An ovoid's or a superovoid's parameters hold its egg terms' scales c0x and c0y.
  const bool egg = chosen && member(*chosen, "parameters").contains("c0x");
  if (const json* m = chosen) {
    html += "<tr><th>head centre (mm, LPS)</th><td id=\"head-centre\">" + withInterval(*m, "t1_mm", 2) + ", " +
            withInterval(*m, "t2_mm", 2) + ", " + withInterval(*m, "t3_mm", 2) + "</td></tr>\n";
    const json& parameters = member(*m, "parameters");
    if (egg) {
      html += "<tr><th>semi-axes through the centre (mm): a&middot;c0x, b&middot;c0y, c</th><td id=\"semi-axes\">" +
              semiAxesWithIntervals(*m) +
              " <span class=\"note\">(an ovoid's a and b share their scale with c0x and c0y; these products are its "
              "shape)</span></td></tr>\n";
    } else {
      std::string radii;
      for (const char* key : {"a_mm", "b_mm", "c_mm"})
        if (parameters.contains(key)) radii += (radii.empty() ? "" : ", ") + withInterval(*m, key, 2);
      html += "<tr><th>radii (mm)</th><td id=\"radii\">" + radii + "</td></tr>\n";
    }
    html += "<tr><th>RMS error (mm)</th><td id=\"rms\">" +
            fixed(numberAt(member(*m, "errors"), "rms_mm"), 3) + "</td></tr>\n";
  }
  const json& correlation = member(chosen ? *chosen : results, "residual_correlation");
  std::string note = "&plusmn;: half the 95 % interval (1.96 standard errors), with the residuals' spatial correlation";
  if (correlation.is_object())
    note += " (" + fixed(numberAt(correlation, "n_eff"), 0) + " effective independent points of " +
            fixed(numberAt(correlation, "n_points"), 0) + ")";
  if (results.contains("edge_offset_field") && results.at("edge_offset_field").is_object())
    note += ", and an edge offset varying over the surface, sized from the CT's voxels (standard deviations " +
            fixed(numberAt(results.at("edge_offset_field"), "linear_sd_mm"), 3) + " mm for a tilt, " +
            fixed(numberAt(results.at("edge_offset_field"), "across_slices_sd_mm"), 3) + " mm across the slices, its odd part as large)";
  note += ". It does not hold a shift of the whole surface shared by every point (an edge found outside a thin "
          "cortex): the radii carry it.";
  // Measured: bench-selection-caps and bench/coverage.py (docs/benchmarks.md).
  if (egg) {
    const double spanned = chosen ? numberAt(*chosen, "other_optima_spanned") : NAN;
    const int others = std::isfinite(spanned) && spanned > 0 ? static_cast<int>(spanned) : 0;
    note += " An egg's centre and semi-axes lie on its equator, beyond a cap about its pole, and the egg fitted along "
            "another of the ellipsoid's axes often fits about as well: their intervals take in every such optimum "
            "within the likelihood-ratio bound (" + std::to_string(others) +
            " here), so they may lie off-centre about the estimate (fits.json gives their ends), and held the truth "
            "for about 86-94 % of simulated caps of 60-120 degrees.";
  }
  return html + "</table>\n<p class=\"note\">" + note + "</p></section>\n";
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
            report::escapeMarkup(kind == "fovea"         ? "fovea (a pit at the medial pole: anatomy)"
                                 : kind == "bone_beyond" ? "bone beyond (no joint gap seen: not the head's edge)"
                                                         : kind) +
            "</td><td>" +
            fixed(numberAt(r, "area_mm2"), 0) + "</td><td>" + fixed(numberAt(r, "depth_mm"), 1) + "</td><td>" +
            report::escapeMarkup(text(r, "where")) + "</td><td>" + at + "</td></tr>\n";
  }
  return html + "</table></section>\n";
}

// A p-value to three significant digits.
std::string probability(double p) {
  if (!std::isfinite(p)) return "-";
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.3g", p);
  return buffer;
}

// A step's numerator degrees of freedom: those the voxels' edge offset field
// widened (df1_effective, one decimal), else the extra parameters.
std::string degreesOfFreedom(const json& step) {
  const double effective = numberAt(step, "df1_effective");
  return std::isfinite(effective) && std::abs(effective - numberAt(step, "df1")) > 0.05 ? fixed(effective, 1)
                                                                                          : text(step, "df1");
}

// The nested tests of the model selection: the hierarchy's steps, each at
// alpha, and the tests the choice made at their levels.
std::string selectionTable(const json& results) {
  const json& selection = member(results, "selection");
  std::string html = "<h3>Model selection</h3>\n<p class=\"note\">Each step tests whether the richer model's extra "
                     "parameters are needed: F = (fall of the SSE) / (the fall expected without them: the richer model's "
                     "residual variance &times; n / n<sub>eff</sub> per extra parameter, so that correlated points count as "
                     "the independent points they are worth, plus what the voxels' edge offset field gives those "
                     "parameters; its spread lowers the degrees of freedom) (n<sub>eff</sub>: the cap's points for errors shared over " +
                     fixed(numberAt(selection, "length_mm"), 1) +
                     " mm; 0 mm: from each fit's residuals). A model the points do not determine is never selected.</p>\n"
                     "<table id=\"selection-steps\"><tr><th>step</th><th>F</th><th>df</th><th>n<sub>eff</sub></th>"
                     "<th>p</th><th>level</th><th>richer model needed</th></tr>\n";
  const auto rows = [&](const json& steps, const std::string& kind) {
    for (const auto& st : steps)
      html += "<tr class=\"" + kind + "\"><td>" + report::escapeMarkup(text(st, "simpler")) + " &rarr; " +
              report::escapeMarkup(text(st, "richer")) + (kind == "path" ? " (choice)" : "") + "</td><td>" +
              fixed(numberAt(st, "f"), 2) + "</td><td>" + degreesOfFreedom(st) + ", " + text(st, "df2") + "</td><td>" +
              fixed(numberAt(st, "n_eff"), 0) + "</td><td>" + probability(numberAt(st, "p_value")) + "</td><td>" +
              fixed(numberAt(st, "alpha"), 4) + "</td><td>" + (member(st, "richer_needed") == true ? "yes" : "no") +
              "</td></tr>\n";
  };
  rows(member(selection, "steps"), "step");
  rows(member(selection, "path"), "path");
  return html + "</table>\n";
}

std::string modelsSection(const json& results) {
  const std::string selected = results.value("selected_model", ""), best = text(results, "least_rms_model");
  std::string html = "<section id=\"models\"><h2>Models</h2>\n<table><tr><th>model</th><th>parameters</th>"
                     "<th>RMS (mm)</th><th>mean |d| (mm)</th><th>max |d| (mm)</th><th>n<sub>eff</sub></th>"
                     "<th>correlation lengths (mm)</th><th></th></tr>\n";
  for (const auto& m : member(results, "models")) {
    const json& errors = member(m, "errors");
    const std::string name = m.value("model", "");
    const double max_abs = std::max(std::fabs(numberAt(errors, "min_mm")), std::fabs(numberAt(errors, "max_mm")));
    std::string marks = name == selected ? "selected" : "";
    if (name == best && best != selected) marks += "least RMS";
    const json& rc = member(m, "residual_correlation");
    const json& lengths = member(rc, "length_mm");
    std::string length_text;
    for (const auto& l : lengths)
      if (l.is_number() && l.get<double>() > 0) length_text += (length_text.empty() ? "" : ", ") + fixed(l.get<double>(), 1);
    html += "<tr data-model=\"" + report::escapeMarkup(name) + "\"><td>" + report::escapeMarkup(name) + "</td><td>" +
            std::to_string(m.value("n_parameters", 0)) + "</td><td class=\"rms\">" + fixed(numberAt(errors, "rms_mm"), 3) +
            "</td><td>" + fixed(numberAt(errors, "mean_abs_mm"), 3) + "</td><td>" + fixed(max_abs, 3) + "</td><td>" +
            fixed(numberAt(rc, "n_eff"), 0) + "</td><td>" + length_text + "</td><td>" + marks + "</td></tr>\n";
  }
  html += "</table>\n";
  html += selectionTable(results);
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
    << text(provenance, "git_commit") << ")";
  std::string libraries;
  for (const auto& [name, version] : member(results, "libraries").items())
    libraries += (libraries.empty() ? "" : ", ") + name + " " + (version.is_string() ? version.get<std::string>() : "");
  if (!libraries.empty()) p << ", built on " << libraries;
  p << ". ";
  const std::string seed_source = text(segment, "seed_source");
  p << "It was segmented from the CT " << (seed_source.rfind("automatic", 0) == 0 ? "automatically (a search for the "
                                                                                     "joint head, then a marker watershed)"
                                                                                   : "from a given seed point (marker watershed)");
  if (segment.contains("spacing_mm") && segment.at("spacing_mm").is_array() && segment.at("spacing_mm").size() == 3)
    p << " at voxels of " << fixed(segment.at("spacing_mm")[0].get<double>(), 2) << " x "
      << fixed(segment.at("spacing_mm")[1].get<double>(), 2) << " x " << fixed(segment.at("spacing_mm")[2].get<double>(), 2)
      << " mm";
  if (numberAt(segment, "smoothed_sigma_mm") > 0)
    p << " (the CT's noise, " << fixed(numberAt(segment, "noise_hu"), 0) << " HU voxel to voxel, was smoothed for the "
      << "search and the label by a Gaussian of " << fixed(numberAt(segment, "smoothed_sigma_mm"), 2) << " mm)";
  if (text(segment, "head_found_by") == "surface voxels")
    p << ", the head taken by the search's fallback (the bone surface voxels facing a centre: no sphere through its "
         "edges)";
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
    << selected << " was selected by nested F tests along the hierarchy at a level of "
    << fixed(numberAt(selection, "alpha"), 2)
    << " (Bonferroni-corrected over the richer models each was tested against): the simplest model needed over "
       "the simpler ones that no richer model beat. Each test counted the points as the "
    << (numberAt(selection, "length_mm") > 0
            ? "effective number of independent points of the cap for errors shared over " +
                  fixed(numberAt(selection, "length_mm"), 1) + " mm (" + fixed(numberAt(selection, "n_eff"), 0) + ")"
            : std::string("effective number of independent points their residuals' spatial correlation (a variogram "
                          "with a nugget and two exponential scales) leaves"))
    << "; models whose parameters the points did not determine took no part";
  if (m) {
    const json& parameters = member(*m, "parameters");
    p << "; its RMS error was " << fixed(numberAt(member(*m, "errors"), "rms_mm"), 2) << " mm and its centre lay at ("
      << fixed(numberAt(parameters, "t1_mm"), 1) << ", " << fixed(numberAt(parameters, "t2_mm"), 1) << ", "
      << fixed(numberAt(parameters, "t3_mm"), 1) << ") mm (LPS)";
  }
  p << ". The shape models, their fitting hierarchy and the signed Euclidean errors follow the thesis \"Smooth convex "
       "surfaces for modeling and simulating multibody systems with compliant contact elements\" (chapters 2-3).";
  // The checks as a sentence: which warned or failed, by name.
  const json& qc = member(results, "qc");
  std::string warned, failed;
  for (const auto& c : member(qc, "checks")) {
    std::string& list = text(c, "status") == "fail" ? failed : warned;
    if (text(c, "status") != "pass") list += (list.empty() ? "" : ", ") + text(c, "name");
  }
  const std::string status = text(qc, "status");
  if (status.empty()) p << " The head's checks were not run.";
  else if (status == "pass") p << " Every check of the head passed.";
  else
    p << (failed.empty() ? "" : " The head failed its checks (" + failed + ").")
      << (warned.empty() ? "" : " Checks that warned: " + warned + ".");
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

}  // namespace articula::subject
