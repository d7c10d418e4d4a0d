#include "articula/study/study_html.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "articula/report/html_page.hpp"
#include "articula/report/markup_text.hpp"
#include "articula/report/strip_plot_svg.hpp"
#include "articula/subject/results_json.hpp"

namespace articula::study {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using namespace subject::results_json;
using report::escapeMarkup;

// The subject's page if the study holds it, else its log; relative to the study folder.
std::string subjectLink(const fs::path& study_dir, const std::string& id) {
  for (const char* file : {"report.html", "run.log"})
    if (fs::exists(study_dir / "subjects" / id / file)) return "subjects/" + id + "/" + file;
  return "";
}

std::string linked(const std::string& label, const std::string& link) {
  return link.empty() ? escapeMarkup(label) : "<a href=\"" + escapeMarkup(link) + "\">" + escapeMarkup(label) + "</a>";
}

struct Quantity {
  std::string title, unit, model, parameter;  // model "" : the subject's selected model
};

std::string plots(const std::vector<std::pair<std::string, json>>& results, const fs::path& study_dir,
                  const std::vector<std::string>& models) {
  std::vector<Quantity> quantities;
  for (const auto& model : models) quantities.push_back({"RMS of the " + model, "mm", model, "rms_mm"});
  // Semi-axes, not raw radii: an ovoid's a shares its scale with c0x, and
  // only a c0x, its semi-axis, is what the points determine.
  for (const char* axis : {"a", "b", "c"})
    quantities.push_back({std::string("Semi-axis ") + axis + " of the selected model", "mm", "", std::string("semi_axis_") + axis});
  for (const char* exponent : {"gamma1", "gamma2", "gamma3"})
    quantities.push_back({std::string("Superellipsoid exponent ") + exponent, "", "superellipsoid", exponent});
  std::string html;
  for (const Quantity& q : quantities) {
    std::vector<report::StripPoint> points;
    for (const auto& [id, r] : results) {
      const json* m = modelNamed(r, q.model.empty() ? text(r, "selected_model") : q.model);
      double v = NAN;
      if (m && q.parameter == "rms_mm") v = numberAt(member(*m, "errors"), "rms_mm");
      else if (m && q.parameter.rfind("semi_axis_", 0) == 0) {
        const json& axes = member(*m, "semi_axes_mm");
        const size_t k = static_cast<size_t>(q.parameter.back() - 'a');
        if (axes.is_array() && k < axes.size() && axes[k].is_number()) v = axes[k].get<double>();
      } else if (m) {
        v = numberAt(member(*m, "parameters"), q.parameter);
      }
      const std::string status = text(member(r, "qc"), "status");
      points.push_back({id, v, subjectLink(study_dir, id), text(r, "joint") + ", " + text(r, "side"),
                        status == "warn" || status == "fail" ? status : ""});
    }
    html += "<figure>" + report::stripPlotSvg(q.title, q.unit, points) + "</figure>\n";
  }
  return html;
}

// Per step of the hierarchy: the subjects whose own test needs the richer
// model, and the cohort's tests (study.json "steps").
std::string cohortSteps(const json& study) {
  std::string html = "<table id=\"cohort-steps\"><tr><th>step</th><th>subjects</th><th>richer model needed</th>"
                     "<th>Fisher's combined p</th><th>sign test p (a majority needs it)</th></tr>\n";
  const auto p_text = [](const json& v) {
    if (!v.is_number()) return std::string("-");
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%.3g", v.get<double>());
    return std::string(buffer);
  };
  for (const auto& st : member(study, "steps"))
    html += "<tr><td>" + escapeMarkup(text(st, "simpler")) + " &rarr; " + escapeMarkup(text(st, "richer")) + "</td><td>" +
            text(st, "subjects") + "</td><td>" + text(st, "richer_needed") + "</td><td>" + p_text(member(st, "fisher_p")) +
            "</td><td>" + p_text(member(st, "sign_test_p")) + "</td></tr>\n";
  return html + "</table>\n<p class=\"note\">Each subject's step is its nested F test with its residuals' "
                "effective number of independent points (results.json, selection.steps). Fisher's method asks whether "
                "any subject needs the richer model and is carried by single extreme subjects; the sign test asks "
                "whether a majority does and cannot fall below 0.05 with fewer than 5 subjects. Both take the subjects "
                "as independent.</p>\n";
}

// Per model over the cohort (study.json "models"): mean RMS, how often it is
// selected and has the least RMS, and the paired test of its RMS against the
// sphere's, with the smallest p its number of subjects can give.
std::string modelSummary(const json& study) {
  std::string html = "<table id=\"model-summary\"><tr><th>model</th><th>subjects</th><th>RMS mean &plusmn; SD (mm)</th>"
                     "<th>selected</th><th>least RMS</th><th>Wilcoxon p, RMS against the sphere's</th></tr>\n";
  bool bound = false;
  for (const auto& m : member(study, "models")) {
    char rms[64];
    std::snprintf(rms, sizeof rms, "%.3f &plusmn; %.3f", numberAt(m, "rms_mean_mm"), numberAt(m, "rms_sd_mm"));
    std::string p = "-";
    const json& w = member(m, "wilcoxon_vs_sphere");
    if (w.is_object() && w.contains("p_value")) {
      const int n = static_cast<int>(numberAt(w, "n"));
      // Two-sided exact signed-rank test: no p below 2 / 2^n with n pairs.
      const double smallest = n > 0 && n < 1000 ? std::ldexp(2.0, -n) : 0.0;
      char buffer[96];
      std::snprintf(buffer, sizeof buffer, "%.3g (n = %d)", numberAt(w, "p_value"), n);
      p = buffer;
      if (smallest > 0 && numberAt(w, "p_value") <= smallest * (1 + 1e-9)) {
        p += " *";
        bound = true;
      }
    }
    html += "<tr><td>" + escapeMarkup(text(m, "model")) + "</td><td>" + text(m, "n_subjects") + "</td><td>" + rms +
            "</td><td>" + text(m, "times_selected") + "</td><td>" + text(m, "times_least_rms") + "</td><td>" + p +
            "</td></tr>\n";
  }
  html += "</table>\n";
  if (bound)
    html += "<p class=\"note\" id=\"small-sample\">* the smallest p this number of subjects can give (2 / 2<sup>n</sup>): "
            "the test cannot say more with so few subjects.</p>\n";
  return html + "<p class=\"note\">A richer model always fits with less RMS; whether a subject needs it is its "
                "nested test (the hierarchy's table below), not this difference.</p>\n";
}

std::string selectedModels(const std::vector<std::pair<std::string, json>>& results, const fs::path& study_dir,
                           const std::vector<std::string>& models) {
  std::string html = "<table><tr><th>selected model</th><th>subjects</th><th>count</th></tr>\n";
  for (const auto& model : models) {
    std::string subjects;
    int count = 0;
    for (const auto& [id, r] : results)
      if (text(r, "selected_model") == model) subjects += (count++ ? ", " : "") + linked(id, subjectLink(study_dir, id));
    html += "<tr><td>" + escapeMarkup(model) + "</td><td>" + subjects + "</td><td>" + std::to_string(count) + "</td></tr>\n";
  }
  return html + "</table>\n";
}

// The reviewer's desk: a decision (include or exclude) and a note per
// subject, saved as ratings.csv (study/ratings.hpp) from the page itself,
// offline: the browser downloads the file, which the reviewer moves into the
// study folder; the tables are then gathered again without the excluded.
constexpr const char* kReviewScript = R"JS(
(function () {
  var rows = document.querySelectorAll('#review tr[data-subject]');
  var text = document.getElementById('ratings-csv');
  function field(v) { return /[",\n\r]/.test(v) ? '"' + v.replace(/"/g, '""') + '"' : v; }
  function csv() {
    var lines = ['subject,decision,note'];
    rows.forEach(function (row) {
      var decision = row.querySelector('select').value, note = row.querySelector('input').value;
      if (decision) lines.push([row.getAttribute('data-subject'), decision, note].map(field).join(','));
    });
    return lines.join('\n') + '\n';
  }
  function update() { text.textContent = text.value = csv(); }
  rows.forEach(function (row) {
    row.querySelector('select').addEventListener('change', update);
    row.querySelector('input').addEventListener('input', update);
  });
  document.getElementById('save-ratings').addEventListener('click', function () {
    var a = document.createElement('a');
    a.href = URL.createObjectURL(new Blob([csv()], {type: 'text/csv'}));
    a.download = 'ratings.csv';
    document.body.appendChild(a);
    a.click();
    a.remove();
  });
  update();
})();
)JS";

std::string reviewSection(const json& subjects) {
  std::string excluded, desk;
  for (const auto& s : subjects) {
    const std::string id = text(s, "subject"), decision = text(s, "review"), note = text(s, "review_note");
    if (decision == "exclude")
      excluded += "<tr><td>" + escapeMarkup(id) + "</td><td>" + escapeMarkup(note) + "</td></tr>\n";
    desk += "<tr data-subject=\"" + escapeMarkup(id) + "\"><td>" + escapeMarkup(id) + "</td><td>" + escapeMarkup(text(s, "status")) +
            "</td><td><select><option value=\"\"" + (decision.empty() ? " selected" : "") +
            ">not rated</option><option value=\"include\"" + (decision == "include" ? " selected" : "") +
            ">include</option><option value=\"exclude\"" + (decision == "exclude" ? " selected" : "") +
            ">exclude</option></select></td><td><input type=\"text\" size=\"40\" value=\"" + escapeMarkup(note) +
            "\"></td></tr>\n";
  }
  std::string html = "<section id=\"excluded\"><h2>Excluded by the reviewer</h2>\n";
  html += excluded.empty() ? "<p>None.</p>\n"
                           : "<p class=\"note\">Left out of every table and plot of this page (ratings.csv).</p>\n<div "
                             "class=\"scroll\"><table><tr><th>subject</th><th>note</th></tr>\n" + excluded + "</table></div>\n";
  html += "</section>\n<section id=\"review\"><h2>Review</h2>\n<p class=\"note\">Include or exclude a subject, with a "
          "note; then save ratings.csv into this study's folder and gather the study again (<code>articula batch "
          "MANIFEST -o STUDY --gather-only</code>, or the Snakefile again): the tables and this page leave the excluded "
          "out and list them above.</p>\n<div class=\"scroll\"><table><tr><th>subject</th><th>status</th><th>decision</th>"
          "<th>note</th></tr>\n" + desk + "</table></div>\n<p><button id=\"save-ratings\" type=\"button\">Save ratings.csv"
          "</button></p>\n<textarea id=\"ratings-csv\" rows=\"6\" cols=\"80\" readonly></textarea>\n<script>" +
          kReviewScript + "</script>\n</section>\n";
  return html;
}

constexpr const char* kStyle = R"(body{font-family:sans-serif;max-width:1000px;margin:1em auto;padding:0 1em;color:#222}
table{border-collapse:collapse;margin:.5em 0}th,td{border:1px solid #ccc;padding:.2em .5em;text-align:left}
th{background:#f4f4f4}tr.failed td{background:#fde7e9}tr.fail td{background:#fde7e9}tr.warn td{background:#fff4e0}
figure{margin:.5em 0}figure svg{max-width:100%;height:auto}.note{color:#666;font-size:.9em}
.scroll{max-height:32em;overflow-y:auto;display:inline-block})";

}  // namespace

std::string studyReportHtml(const json& study, const std::vector<std::pair<std::string, json>>& results,
                            const fs::path& study_dir) {
  std::vector<std::string> models;
  for (const auto& m : member(study, "models")) models.push_back(text(m, "model"));
  const json& subjects = member(study, "subjects");
  int flagged = 0;
  std::string look = "<table><tr><th>subject</th><th>status</th><th>reason</th></tr>\n";
  for (const auto& s : subjects) {
    const std::string id = text(s, "subject");
    if (text(s, "status") != "ok") {
      look += "<tr class=\"failed\"><td>" + linked(id, subjectLink(study_dir, id)) + "</td><td>failed (exit " +
              text(s, "exit_code") + ")</td><td>" + escapeMarkup(text(s, "message")) + "</td></tr>\n";
      continue;
    }
    for (const auto& [rid, r] : results) {
      const std::string status = text(member(r, "qc"), "status");
      if (rid != id || status == "pass") continue;
      ++flagged;
      std::string reasons;
      for (const auto& reason : member(member(r, "qc"), "reasons"))
        reasons += (reasons.empty() ? "" : "; ") + (reason.is_string() ? reason.get<std::string>() : reason.dump());
      look += "<tr class=\"" + escapeMarkup(status) + "\"><td>" + linked(id, subjectLink(study_dir, id)) + "</td><td>checks: " +
              escapeMarkup(status) + "</td><td>" + escapeMarkup(reasons) + "</td></tr>\n";
    }
  }
  look += "</table>\n";
  // A cohort's list scrolls within the page; an empty one says so.
  look = look.find("<tr class=") == std::string::npos ? "<p>None: every subject finished and passed its checks.</p>\n"
                                                      : "<div class=\"scroll\">" + look + "</div>\n";
  const json& provenance = member(study, "provenance");
  std::ostringstream html;
  html << report::htmlPageStart("articula study", kStyle) << "<h1>articula study</h1>\n<p id=\"counts\">" << subjects.size()
       << " subjects: <span id=\"succeeded\">" << numberAt(study, "succeeded") << "</span> finished, <span id=\"failed\">"
       << numberAt(study, "failed") << "</span> failed, <span id=\"flagged\">" << flagged
       << "</span> flagged by their checks, <span id=\"excluded-count\">" << numberAt(study, "excluded")
       << "</span> excluded by the reviewer.</p>\n<section id=\"look\"><h2>Subjects to look at</h2>\n" << look
       << "</section>\n<section id=\"quantities\"><h2>Across the subjects</h2>\n<p class=\"note\">A dot per subject, a lane per "
          "joint and side; ringed, in orange or red, where its checks warned or failed; a click opens its page.</p>\n"
       << "<h3>Models</h3>\n" << modelSummary(study) << plots(results, study_dir, models) << "<h3>Selected models</h3>\n<div class=\"scroll\">" << selectedModels(results, study_dir, models) << "</div>\n"
       << "<h3>Which steps of the hierarchy the cohort needs</h3>\n" << cohortSteps(study)
       << "</section>\n" << reviewSection(subjects) << "<section id=\"tables\"><h2>Tables</h2><ul>";
  for (const char* file : {"study.csv", "study_summary.csv", "study_steps.csv", "study_status.csv", "study.json", "study.svg", "ratings.csv"})
    if (fs::exists(study_dir / file)) html << "<li><a href=\"" << file << "\">" << file << "</a></li>";
  html << "</ul></section>\n<section id=\"about\"><h2>About</h2><table><tr><th>articula</th><td>"
       << escapeMarkup(text(provenance, "articula_version")) << " (commit " << escapeMarkup(text(provenance, "git_commit"))
       << ")</td></tr><tr><th>command</th><td><code>" << escapeMarkup(text(provenance, "command"))
       << "</code></td></tr></table></section>\n</body></html>\n";
  return html.str();
}

}  // namespace articula::study
