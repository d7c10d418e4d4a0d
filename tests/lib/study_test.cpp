// The study's tables and figures from its subjects' results.
#include <filesystem>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "articula/pipeline/batch.hpp"
#include "articula/study/study.hpp"
#include "articula/testsupport/scratch_dir.hpp"

namespace p = articula::pipeline;
namespace fs = std::filesystem;
using articula::testsupport::readText;
using articula::testsupport::scratchDir;
using articula::testsupport::writeText;

TEST(StudyTables, FigureShowsEverySubjectsRmsAndTheMeans) {
  const fs::path dir = scratchDir("study");
  const std::vector<std::string> ids = {"s2", "s1", "bad"};  // manifest order, not sorted
  const double rms[2][2] = {{0.5, 0.2}, {0.3, 0.1}};
  std::vector<p::Subject> subjects;
  p::BatchSummary batch;
  for (size_t i = 0; i < ids.size(); ++i) {
    subjects.push_back({ids[i], dir / ids[i], "hip", "right", {}, static_cast<int>(i) + 2});
    batch.outcomes.push_back({ids[i], i < 2 ? "ok" : "failed", i < 2 ? 0 : 3, "", 1.0, false});
    if (i == 2) continue;
    nlohmann::json models = nlohmann::json::array();
    for (int m = 0; m < 2; ++m)
      models.push_back({{"model", m ? "ellipsoid" : "sphere"},
                        {"n_parameters", m ? 9 : 4},
                        {"parameters", {{"a_mm", 20.0}}},
                        {"errors", {{"n_points", 100}, {"rms_mm", rms[i][m]}}},
                        {"aic", -100.0 * (m + 1)},
                        {"bic", -90.0 * (m + 1)}});
    fs::create_directories(p::subjectDir(dir, ids[i]));
    writeText(p::subjectDir(dir, ids[i]) / "results.json",
          nlohmann::json({{"best_model", "ellipsoid"},
                          {"selected_model", "sphere"},
                          {"joint", "hip"},
                          {"side", i ? "left" : "right"},
                          {"qc", {{"status", i ? "warn" : "pass"}, {"reasons", {"a check warned"}}}},
                          {"models", models}})
              .dump());
  }
  articula::study::writeStudyTables(dir, subjects, batch, nlohmann::json::object());
  const std::string svg = readText(dir / "study.svg");
  auto has = [&](const std::string& s) { return svg.find(s) != std::string::npos; };
  EXPECT_TRUE(has("<title>s2 sphere: 0.5 mm</title>"));
  EXPECT_TRUE(has("<title>s1 ellipsoid: 0.1 mm</title>"));
  EXPECT_TRUE(has("<title>mean sphere: 0.4 mm (2 subjects)</title>"));
  EXPECT_TRUE(has("<title>mean ellipsoid: 0.15 mm (2 subjects)</title>"));
  EXPECT_TRUE(has("across 2 subjects"));
  EXPECT_FALSE(has("bad"));
  EXPECT_LT(svg.find("<title>s2 sphere"), svg.find("<title>s1 sphere"));  // manifest order

  // study.html: a lane per joint and side, the flagged subject ringed and
  // named, the per-model table, and the bound two subjects put on the
  // signed-rank test (2 / 2^2 = 0.5, the smallest p they can give).
  const std::string page = readText(dir / "study.html");
  auto on_page = [&](const std::string& s) { return page.find(s) != std::string::npos; };
  EXPECT_TRUE(on_page("<text class=\"lane\" x=\"4\" y=\"54\">hip, right</text>"));
  EXPECT_TRUE(on_page("<text class=\"lane\" x=\"4\" y=\"98\">hip, left</text>"));
  EXPECT_TRUE(on_page("<title>s1: 0.3 mm (checks: warn)</title>"));
  EXPECT_TRUE(on_page("<title>s2: 0.5 mm</title>"));
  EXPECT_FALSE(on_page("s2: 0.5 mm (checks"));
  EXPECT_TRUE(on_page("<tr><td>ellipsoid</td><td>2</td><td>0.150 &plusmn; 0.071</td><td>0</td><td>0</td><td>0.5 (n = 2) *</td></tr>"))
      << page.substr(page.find("model-summary"), 800);
  EXPECT_TRUE(on_page("id=\"small-sample\""));
  EXPECT_TRUE(on_page("<tr class=\"warn\"><td><a href=\"subjects/s1/run.log\">s1</a></td><td>checks: warn</td><td>a check warned</td></tr>") ||
              on_page("<tr class=\"warn\"><td>s1</td><td>checks: warn</td><td>a check warned</td></tr>"));
}
