#include "articula/study/study.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

#include "articula/core/json_file.hpp"
#include "articula/core/atomic_file.hpp"
#include "articula/core/error.hpp"
#include "articula/core/log.hpp"
#include "articula/core/csv.hpp"
#include "articula/study/ratings.hpp"
#include "articula/statistics/cohort.hpp"
#include "articula/statistics/model_selection.hpp"
#include "articula/study/study_html.hpp"
#include "articula/report/study_svg.hpp"

namespace articula::study {

namespace fs = std::filesystem;

namespace {

std::string number(double v) {
  if (!std::isfinite(v)) return "";
  std::ostringstream s;
  s.precision(10);
  s << v;
  return s.str();
}

// Error-statistic columns of study.csv, in order, read from models[].errors.
// (the columns of the errors stage's summary, thesis tables 3.3-3.4).
const std::vector<std::string> kErrorColumns = {"n_points",    "rms_mm",     "min_mm",      "max_mm",         "mean_abs_mm",
                                                "std_abs_mm", "gauss_mu_mm", "gauss_sigma_mm", "sse_mm2"};

struct ModelRow {
  std::string subject, model;
  nlohmann::json entry;  // the model's entry of results.json
  bool best = false;  // the least RMS
  bool selected = false;  // results.json's selected_model
  std::string qc_status, qc_reasons;  // results.json's qc (the subject's)
  bool determined = true;  // not in results.json's selection.undetermined
  nlohmann::json step;     // results.json's selection step into this model (null for the sphere)
};

// The hierarchy's step into `model` among a subject's selection.steps: the
// superovoid's from its parent of the lower SSE, as results.csv has it.
nlohmann::json stepInto(const nlohmann::json& results, const std::string& model) {
  nlohmann::json chosen;
  double chosen_sse = INFINITY;
  const auto sse = [&results](const std::string& name) {
    for (const auto& m : results.at("models"))
      if (m.value("model", "") == name && m.contains("errors")) return m.at("errors").value("sse_mm2", static_cast<double>(INFINITY));
    return static_cast<double>(INFINITY);
  };
  if (!results.contains("selection") || !results.at("selection").is_object()) return chosen;
  for (const auto& st : results.at("selection").value("steps", nlohmann::json::array()))
    if (st.value("richer", "") == model && sse(st.value("simpler", "")) < chosen_sse) {
      chosen = st;
      chosen_sse = sse(st.value("simpler", ""));
    }
  return chosen;
}

// study.svg: RMS per model, subject by subject (subjects in manifest order).
std::string studyFigure(const std::vector<ModelRow>& rows, const std::vector<std::string>& model_order,
                        const fs::path& study_dir) {
  report::StudyRms study;
  study.models = model_order;
  for (const auto& r : rows)
    if (std::find(study.subjects.begin(), study.subjects.end(), r.subject) == study.subjects.end())
      study.subjects.push_back(r.subject);
  study.rms_mm = Eigen::MatrixXd::Constant(static_cast<Eigen::Index>(study.subjects.size()),
                                           static_cast<Eigen::Index>(model_order.size()), NAN);
  for (const auto& r : rows) {
    const auto s = std::find(study.subjects.begin(), study.subjects.end(), r.subject) - study.subjects.begin();
    const auto m = std::find(model_order.begin(), model_order.end(), r.model) - model_order.begin();
    study.rms_mm(s, m) = r.entry.at("errors").value("rms_mm", NAN);
  }
  const std::string name = fs::absolute(study_dir).lexically_normal().filename().string();
  return report::studyRmsSvg(study, "RMS of the fitted models across " + std::to_string(study.subjects.size()) +
                                        " subjects" + (name.empty() ? "" : " (" + name + ")"));
}

}  // namespace

nlohmann::json writeStudyTables(const fs::path& study_dir, const std::vector<pipeline::Subject>& subjects,
                                const pipeline::BatchSummary& batch, const nlohmann::json& provenance) {
  std::vector<ModelRow> rows;
  std::vector<std::string> parameter_columns;  // union, in order of first appearance
  std::vector<std::string> model_order;
  std::vector<std::pair<std::string, nlohmann::json>> finished;  // results.json of each finished subject kept
  const std::map<std::string, Rating> ratings = readRatings(study_dir, subjects);
  const auto excluded = [&ratings](const std::string& id) {
    const auto it = ratings.find(id);
    return it != ratings.end() && it->second.decision == "exclude";
  };
  for (size_t i = 0; i < subjects.size(); ++i) {
    if (batch.outcomes[i].status != "ok" || excluded(subjects[i].id)) continue;
    const fs::path path = pipeline::subjectDir(study_dir, subjects[i].id) / "results.json";
    const nlohmann::json& results =
        finished.emplace_back(subjects[i].id, readJsonFile(path, "study (" + subjects[i].id + ")")).second;
    const std::string best = results.value("least_rms_model", ""), selected = results.value("selected_model", "");
    std::string qc_status, qc_reasons;
    if (results.contains("qc") && results.at("qc").is_object()) {
      qc_status = results.at("qc").value("status", "");
      for (const auto& reason : results.at("qc").value("reasons", nlohmann::json::array()))
        if (reason.is_string()) qc_reasons += (qc_reasons.empty() ? "" : "; ") + reason.get<std::string>();
    }
    const nlohmann::json undetermined =
        results.contains("selection") && results.at("selection").is_object()
            ? results.at("selection").value("undetermined", nlohmann::json::array())
            : nlohmann::json::array();
    for (const auto& m : results.at("models")) {
      ModelRow row{subjects[i].id, m.at("model").get<std::string>(), m, m.at("model") == best, m.at("model") == selected,
                   qc_status, qc_reasons, true, nlohmann::json()};
      row.determined = std::find(undetermined.begin(), undetermined.end(), m.at("model")) == undetermined.end();
      row.step = stepInto(results, row.model);
      for (const auto& [key, value] : m.at("parameters").items())
        if (std::find(parameter_columns.begin(), parameter_columns.end(), key) == parameter_columns.end())
          parameter_columns.push_back(key);
      if (std::find(model_order.begin(), model_order.end(), row.model) == model_order.end())
        model_order.push_back(row.model);
      rows.push_back(std::move(row));
    }
  }

  // study.csv
  std::vector<std::string> header = {"subject", "model", "n_parameters"};
  header.insert(header.end(), kErrorColumns.begin(), kErrorColumns.end());
  header.insert(header.end(), {"aic", "bic", "least_rms", "selected", "determined", "qc_status", "qc_reasons",
                               "semi_axis_a_mm", "semi_axis_b_mm", "semi_axis_c_mm", "n_eff", "step_from", "step_f",
                               "step_p_value", "richer_needed"});
  header.insert(header.end(), parameter_columns.begin(), parameter_columns.end());
  for (const auto& c : parameter_columns) header.push_back(c + "_se");  // standard errors, same units
  std::string study_csv = csvLine(header) + "\n";
  for (const auto& r : rows) {
    std::vector<std::string> f = {r.subject, r.model, number(r.entry.value("n_parameters", 0))};
    for (const auto& c : kErrorColumns) f.push_back(number(r.entry.at("errors").value(c, NAN)));
    f.push_back(number(r.entry.value("aic", NAN)));
    f.push_back(number(r.entry.value("bic", NAN)));
    f.push_back(r.best ? "1" : "0");
    f.push_back(r.selected ? "1" : "0");
    f.push_back(r.determined ? "1" : "0");
    f.push_back(r.qc_status);
    f.push_back(r.qc_reasons);
    const nlohmann::json axes = r.entry.value("semi_axes_mm", nlohmann::json::array());
    for (size_t k = 0; k < 3; ++k) f.push_back(k < axes.size() && axes[k].is_number() ? number(axes[k].get<double>()) : "");
    const nlohmann::json correlation = r.entry.value("residual_correlation", nlohmann::json::object());
    f.push_back(number(correlation.value("n_eff", NAN)));
    const bool stepped = r.step.is_object();
    f.push_back(stepped ? r.step.value("simpler", "") : "");
    f.push_back(stepped && r.step.value("f", nlohmann::json()).is_number() ? number(r.step.at("f").get<double>()) : "");
    f.push_back(stepped && r.step.value("p_value", nlohmann::json()).is_number() ? number(r.step.at("p_value").get<double>()) : "");
    f.push_back(stepped ? (r.step.value("richer_needed", false) ? "1" : "0") : "");
    for (const auto& c : parameter_columns)
      f.push_back(r.entry.at("parameters").contains(c) ? number(r.entry.at("parameters").at(c).get<double>()) : "");
    const nlohmann::json se = r.entry.value("standard_errors", nlohmann::json::object());
    for (const auto& c : parameter_columns)
      f.push_back(se.contains(c) && se.at(c).is_number() ? number(se.at(c).get<double>()) : "");
    study_csv += csvLine(f) + "\n";
  }

  // Per subject, the model with the least AIC and BIC; per model, RMS by subject.
  std::map<std::string, std::map<std::string, const ModelRow*>> by_subject;
  for (const auto& r : rows) by_subject[r.subject][r.model] = &r;
  std::map<std::string, int> best_rms, best_aic, best_bic, times_selected;
  for (const auto& [subject, models] : by_subject) {
    const ModelRow *a = nullptr, *b = nullptr;
    for (const auto& [name, row] : models) {
      if (!a || row->entry.value("aic", INFINITY) < a->entry.value("aic", INFINITY)) a = row;
      if (!b || row->entry.value("bic", INFINITY) < b->entry.value("bic", INFINITY)) b = row;
      if (row->best) ++best_rms[name];
      if (row->selected) ++times_selected[name];
    }
    if (a) ++best_aic[a->model];
    if (b) ++best_bic[b->model];
  }

  nlohmann::json summary_json = nlohmann::json::array();
  std::string summary_csv = csvLine({"model", "n_subjects", "rms_mean_mm", "rms_sd_mm", "times_selected", "times_least_rms",
                                     "times_best_by_aic", "times_best_by_bic", "mean_delta_aic_vs_sphere",
                                     "mean_delta_bic_vs_sphere", "wilcoxon_n_vs_sphere", "wilcoxon_p_vs_sphere"}) +
                            "\n";
  for (const auto& model : model_order) {
    std::vector<double> rms, rms_sphere, d_aic, d_bic;
    for (const auto& [subject, models] : by_subject) {
      auto it = models.find(model);
      if (it == models.end()) continue;
      rms.push_back(it->second->entry.at("errors").value("rms_mm", NAN));
      auto sphere = models.find("sphere");
      if (sphere != models.end()) {
        rms_sphere.push_back(sphere->second->entry.at("errors").value("rms_mm", NAN));
        d_aic.push_back(it->second->entry.value("aic", NAN) - sphere->second->entry.value("aic", NAN));
        d_bic.push_back(it->second->entry.value("bic", NAN) - sphere->second->entry.value("bic", NAN));
      }
    }
    const statistics::Summary s = statistics::summarise(rms);
    statistics::WilcoxonResult w;
    const bool paired = model != "sphere" && rms_sphere.size() == rms.size() && !rms.empty();
    if (paired) w = statistics::wilcoxonSignedRank(rms, rms_sphere);
    const std::vector<std::string> f = {model,
                                        std::to_string(s.n),
                                        number(s.mean),
                                        number(s.sd),
                                        std::to_string(times_selected[model]),
                                        std::to_string(best_rms[model]),
                                        std::to_string(best_aic[model]),
                                        std::to_string(best_bic[model]),
                                        d_aic.empty() ? "" : number(statistics::summarise(d_aic).mean),
                                        d_bic.empty() ? "" : number(statistics::summarise(d_bic).mean),
                                        paired ? std::to_string(w.n_used) : "",
                                        paired ? number(w.p_value) : ""};
    summary_csv += csvLine(f) + "\n";
    nlohmann::json entry = {{"model", model},
                            {"n_subjects", s.n},
                            {"rms_mean_mm", s.mean},
                            {"rms_sd_mm", s.sd},
                            {"times_selected", times_selected[model]},
                            {"times_least_rms", best_rms[model]},
                            {"times_best_by_aic", best_aic[model]},
                            {"times_best_by_bic", best_bic[model]}};
    if (paired)
      entry["wilcoxon_vs_sphere"] = {{"n", w.n_used}, {"w_plus", w.w_plus}, {"p_value", w.p_value}, {"exact", w.exact}};
    summary_json.push_back(entry);
  }

  // Per step of the hierarchy: how many subjects need the richer model, and
  // the cohort's tests over the subjects' own (statistics.hpp, statistics::cohortStep).
  nlohmann::json steps_json = nlohmann::json::array();
  std::string steps_csv = csvLine({"simpler", "richer", "subjects", "richer_needed", "fisher_p", "sign_test_p"}) + "\n";
  for (const auto& [simpler, richer] : std::vector<std::pair<std::string, std::string>>{{"sphere", "ellipsoid"},
                                                                                      {"ellipsoid", "superellipsoid"},
                                                                                      {"ellipsoid", "ovoid"},
                                                                                      {"superellipsoid", "superovoid"},
                                                                                      {"ovoid", "superovoid"}}) {
    std::vector<double> p_values;
    std::vector<bool> needed;
    for (const auto& [id, results] : finished) {
      if (!results.contains("selection") || !results.at("selection").is_object()) continue;
      for (const auto& st : results.at("selection").value("steps", nlohmann::json::array()))
        if (st.value("simpler", "") == simpler && st.value("richer", "") == richer) {
          p_values.push_back(st.value("p_value", nlohmann::json()).is_number() ? st.at("p_value").get<double>() : NAN);
          needed.push_back(st.value("richer_needed", false));
        }
    }
    if (needed.empty()) continue;
    const statistics::CohortStep c = statistics::cohortStep(p_values, needed);
    steps_csv += csvLine({simpler, richer, std::to_string(c.subjects), std::to_string(c.richer_needed), number(c.fisher_p),
                          number(c.sign_test_p)}) +
                 "\n";
    steps_json.push_back({{"simpler", simpler},
                          {"richer", richer},
                          {"subjects", c.subjects},
                          {"richer_needed", c.richer_needed},
                          {"fisher_p", std::isfinite(c.fisher_p) ? nlohmann::json(c.fisher_p) : nlohmann::json()},
                          {"sign_test_p", std::isfinite(c.sign_test_p) ? nlohmann::json(c.sign_test_p) : nlohmann::json()}});
  }

  std::string status_csv =
      csvLine({"subject", "status", "exit_code", "seconds", "message", "review", "review_note"}) + "\n";
  nlohmann::json status_json = nlohmann::json::array();
  int n_excluded = 0;
  for (size_t i = 0; i < subjects.size(); ++i) {
    const auto& o = batch.outcomes[i];
    const auto rating = ratings.find(o.id);
    const Rating review = rating == ratings.end() ? Rating{} : rating->second;
    n_excluded += review.decision == "exclude";
    status_csv += csvLine({o.id, o.status, std::to_string(o.exit_code), number(o.seconds), o.message, review.decision,
                           review.note}) +
                  "\n";
    status_json.push_back({{"subject", o.id},
                           {"status", o.status},
                           {"exit_code", o.exit_code},
                           {"message", o.message},
                           {"resumed", o.resumed},
                           {"review", review.decision},
                           {"review_note", review.note}});
  }

  nlohmann::json study = {{"subjects", status_json},
                          {"models", summary_json},
                          {"steps", steps_json},
                          {"succeeded", batch.succeeded},
                          {"failed", batch.failed},
                          {"excluded", n_excluded},
                          {"coordinate_system", "LPS"},
                          {"units", "mm"},
                          {"provenance", provenance}};
  // study.json first: it marks the tables as a batch's own (a batch rerun
  // replaces them, and refuses tables no batch wrote).
  writeFileAtomically(study_dir / "study.json", study.dump(2) + "\n");
  writeFileAtomically(study_dir / "study.csv", study_csv);
  writeFileAtomically(study_dir / "study_summary.csv", summary_csv);
  writeFileAtomically(study_dir / "study_status.csv", status_csv);
  writeFileAtomically(study_dir / "study_steps.csv", steps_csv);
  if (!rows.empty()) writeFileAtomically(study_dir / "study.svg", studyFigure(rows, model_order, study_dir));
  writeFileAtomically(study_dir / "study.html", studyReportHtml(study, finished, study_dir));
  return study;
}

}  // namespace articula::study
