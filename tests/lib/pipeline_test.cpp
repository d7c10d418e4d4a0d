// Batch manifests, study statistics, Slicer markups and the batch scheduler.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "articula/core/error.hpp"
#include "articula/pipeline/batch.hpp"
#include "articula/core/csv.hpp"
#include "articula/pipeline/manifest.hpp"
#include "articula/pipeline/markups.hpp"
#include "articula/pipeline/statistics.hpp"
#include "articula/pipeline/study.hpp"

namespace p = articula::pipeline;
namespace fs = std::filesystem;

namespace {
fs::path scratch(const std::string& name) {
  fs::path dir = fs::temp_directory_path() / ("articula-pipeline-test-" + std::to_string(::getpid())) / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}
void write(const fs::path& path, const std::string& text) {
  std::ofstream(path) << text;
}

// Brute force: enumerate all 2^n sign assignments of the (average) ranks.
double bruteForceWilcoxonP(const std::vector<double>& x, const std::vector<double>& y) {
  std::vector<double> d;
  for (size_t i = 0; i < x.size(); ++i)
    if (x[i] != y[i]) d.push_back(x[i] - y[i]);
  const size_t n = d.size();
  std::vector<double> rank(n);
  for (size_t i = 0; i < n; ++i) {
    double less = 0, equal = 0;
    for (size_t j = 0; j < n; ++j) {
      if (std::fabs(d[j]) < std::fabs(d[i])) ++less;
      if (std::fabs(d[j]) == std::fabs(d[i])) ++equal;
    }
    rank[i] = less + (equal + 1) / 2.0;
  }
  double w = 0;
  for (size_t i = 0; i < n; ++i)
    if (d[i] > 0) w += rank[i];
  double lower = 0, upper = 0;
  const double total = std::pow(2.0, static_cast<double>(n));
  for (unsigned long mask = 0; mask < (1ul << n); ++mask) {
    double s = 0;
    for (size_t i = 0; i < n; ++i)
      if (mask >> i & 1) s += rank[i];
    if (s <= w + 1e-9) lower += 1;
    if (s >= w - 1e-9) upper += 1;
  }
  return std::min(1.0, 2 * std::min(lower, upper) / total);
}
}  // namespace

TEST(Statistics, WilcoxonMatchesBruteForceEnumeration) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> gauss;
  for (int trial = 0; trial < 40; ++trial) {
    const int n = 3 + trial % 14;
    std::vector<double> x(n), y(n);
    for (int i = 0; i < n; ++i) {
      x[i] = std::round(4 * gauss(rng)) / 4;  // quarters: ties and zero differences happen
      y[i] = std::round(4 * (gauss(rng) + 0.3 * (trial % 3))) / 4;
    }
    const p::WilcoxonResult r = p::wilcoxonSignedRank(x, y);
    EXPECT_TRUE(r.exact);
    EXPECT_NEAR(r.p_value, bruteForceWilcoxonP(x, y), 1e-12) << "trial " << trial;
  }
}

TEST(Statistics, WilcoxonKnownValuesAndLargeSamples) {
  // All 10 differences positive: W+ = 55, exact two-sided p = 2 / 2^10.
  std::vector<double> x, y;
  for (int i = 1; i <= 10; ++i) {
    x.push_back(i + 0.1 * i);
    y.push_back(i);
  }
  const auto r = p::wilcoxonSignedRank(x, y);
  EXPECT_EQ(r.w_plus, 55.0);
  EXPECT_NEAR(r.p_value, 2.0 / 1024.0, 1e-15);
  EXPECT_EQ(p::wilcoxonSignedRank(y, y).p_value, 1.0);
  // Normal approximation beyond 60 pairs: symmetric differences give p near 1,
  // a consistent shift gives a tiny p.
  std::vector<double> a(200), b(200), c(200);
  for (int i = 0; i < 200; ++i) {
    a[i] = i;
    b[i] = i + (i % 2 ? 0.5 + i * 1e-3 : -0.5 - i * 1e-3);
    c[i] = i - 0.5 - i * 1e-3;
  }
  EXPECT_FALSE(p::wilcoxonSignedRank(a, b).exact);
  EXPECT_GT(p::wilcoxonSignedRank(a, b).p_value, 0.5);
  EXPECT_LT(p::wilcoxonSignedRank(a, c).p_value, 1e-30);
  EXPECT_THROW(p::wilcoxonSignedRank({1.0}, {1.0, 2.0}), articula::ProcessingError);
}

TEST(Statistics, SummariesAndInformationCriteria) {
  const p::Summary s = p::summarise({2, 4, 4, 4, 5, 5, 7, 9});
  EXPECT_DOUBLE_EQ(s.mean, 5.0);
  EXPECT_NEAR(s.sd, std::sqrt(32.0 / 7.0), 1e-15);
  EXPECT_NEAR(p::aic(2.0, 100, 4), 100 * std::log(0.02) + 8, 1e-12);
  EXPECT_NEAR(p::bic(2.0, 100, 4), 100 * std::log(0.02) + 4 * std::log(100.0), 1e-12);
  // More parameters must buy enough fit: the same SSE costs more with more parameters.
  EXPECT_LT(p::bic(1.0, 1000, 4), p::bic(1.0, 1000, 20));
}

TEST(Csv, QuotedFieldsRoundTrip) {
  const fs::path dir = scratch("csv");
  const std::vector<std::string> fields = {"plain", "with,comma", "with \"quotes\"", "", "multi\nline"};
  write(dir / "t.csv", "a,b,c,d,e\n" + articula::csvLine(fields) + "\n# comment\n\n1,2\n");
  const articula::CsvTable t = articula::readCsv(dir / "t.csv");
  ASSERT_EQ(t.rows.size(), 2u);
  EXPECT_EQ(t.rows[0], fields);
  EXPECT_EQ(t.rows[1][1], "2");
  EXPECT_EQ(t.rows[1][4], "");
  EXPECT_EQ(t.row_lines[1], 6);
  write(dir / "bad.csv", "a,b\n1,2,3\n");
  try {
    articula::readCsv(dir / "bad.csv");
    FAIL();
  } catch (const articula::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.csv:2"), std::string::npos) << e.what();
  }
}

TEST(Manifest, ResolvesPathsAndOptions) {
  const fs::path dir = scratch("manifest");
  fs::create_directories(dir / "data");
  write(dir / "data" / "s1.nii.gz", "x");
  write(dir / "m.csv", "subject,input,joint,side,seed_point\ns1,data/s1.nii.gz,hip,left,\"1,2,3\"\ns2," +
                           (dir / "missing").string() + ",shoulder,right,\n");
  const auto subjects = p::readManifest(dir / "m.csv");
  ASSERT_EQ(subjects.size(), 2u);
  EXPECT_EQ(subjects[0].input, dir / "data" / "s1.nii.gz");
  EXPECT_EQ(subjects[0].options, (std::vector<std::string>{"--seed-point", "1,2,3"}));
  EXPECT_TRUE(subjects[1].options.empty());
  EXPECT_TRUE(p::checkSubjectInput(subjects[0]).empty());
  ASSERT_EQ(p::checkSubjectInput(subjects[1]).size(), 1u);
  EXPECT_NE(p::checkSubjectInput(subjects[1])[0].find("does not exist"), std::string::npos);

  auto rejects = [&](const std::string& text, const std::string& fragment) {
    write(dir / "bad.csv", text);
    try {
      p::readManifest(dir / "bad.csv");
      ADD_FAILURE() << "accepted: " << text;
    } catch (const articula::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
  };
  rejects("id,input,joint,side\na,b,hip,left\n", "subject,input,joint,side");
  rejects("subject,input,joint,side\na,x,knee,left\n", "bad.csv:2: joint");
  rejects("subject,input,joint,side\na,x,hip,up\n", "side");
  rejects("subject,input,joint,side\na,x,hip,left\na,y,hip,left\n", "bad.csv:3: subject id 'a' appears twice");
  rejects("subject,input,joint,side\n../a,x,hip,left\n", "expected a folder name");
  rejects("subject,input,joint,side\n..,x,hip,left\n", "not starting with '.'");
  rejects("subject,input,joint,side,until\na,x,hip,left,sample\n", "--until is set by the batch");
  rejects("subject,input,joint,side,output\na,x,hip,left,o\n", "--output is set by the batch");
  rejects("subject,input,joint,side,Seed Point\na,x,hip,left,1\n", "expected an option name");
  rejects("subject,input,joint,side,ratio,ratio\na,x,hip,left,1,2\n", "column 'ratio' appears twice");
  rejects("subject,input,joint,side,x\n\x1b[31m,x,hip,left,1\n", "\\x1b[31m");
  rejects("subject,input,joint,side\n", "at least one subject");
}

TEST(Manifest, SpreadsheetByteOrderMarkIsNoPartOfTheHeader) {
  const fs::path dir = scratch("manifest_bom");
  write(dir / "m.csv", "\xEF\xBB\xBFsubject,input,joint,side\ns1,a.nii,hip,left\n");
  const auto subjects = p::readManifest(dir / "m.csv");
  ASSERT_EQ(subjects.size(), 1u);
  EXPECT_EQ(subjects[0].id, "s1");
  write(dir / "m.csv", "\xEF\xBB\xBFid,input,joint,side\ns1,a.nii,hip,left\n");
  try {
    p::readManifest(dir / "m.csv");
    ADD_FAILURE() << "accepted a header without subject";
  } catch (const articula::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("found 'id,input,joint,side'"), std::string::npos) << e.what();
  }
}

TEST(Markups, SlicerSchemaInLps) {
  const fs::path dir = scratch("markups");
  p::writeSlicerMarkups(dir / "head.mrk.json", "femoral head",
                        {{"head_center", Eigen::Vector3d(1.5, -2, 3)}},
                        {{"axis_a", Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(25, 0, 0)}});
  std::ifstream in(dir / "head.mrk.json");
  const auto doc = nlohmann::json::parse(in);
  EXPECT_NE(doc.at("@schema").get<std::string>().find("markups-schema-v1.0.3"), std::string::npos);
  const auto& fiducial = doc.at("markups").at(0);
  EXPECT_EQ(fiducial.at("type"), "Fiducial");
  EXPECT_EQ(fiducial.at("coordinateSystem"), "LPS");
  EXPECT_EQ(fiducial.at("controlPoints").at(0).at("position"), nlohmann::json({1.5, -2.0, 3.0}));
  EXPECT_EQ(doc.at("markups").at(1).at("type"), "Line");
  EXPECT_EQ(doc.at("markups").at(1).at("controlPoints").size(), 2u);
}

TEST(StudyTables, FigureShowsEverySubjectsRmsAndTheMeans) {
  const fs::path dir = scratch("study");
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
    write(p::subjectDir(dir, ids[i]) / "results.json",
          nlohmann::json({{"best_model", "ellipsoid"}, {"models", models}}).dump());
  }
  p::writeStudyTables(dir, subjects, batch, nlohmann::json::object());
  std::ifstream in(dir / "study.svg");
  const std::string svg((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  auto has = [&](const std::string& s) { return svg.find(s) != std::string::npos; };
  EXPECT_TRUE(has("<title>s2 sphere: 0.5 mm</title>"));
  EXPECT_TRUE(has("<title>s1 ellipsoid: 0.1 mm</title>"));
  EXPECT_TRUE(has("<title>mean sphere: 0.4 mm (2 subjects)</title>"));
  EXPECT_TRUE(has("<title>mean ellipsoid: 0.15 mm (2 subjects)</title>"));
  EXPECT_TRUE(has("across 2 subjects"));
  EXPECT_FALSE(has("bad"));
  EXPECT_LT(svg.find("<title>s2 sphere"), svg.find("<title>s1 sphere"));  // manifest order
}

namespace articula {
namespace {

TEST(ModelSelection, TheSimplestModelWithinTheToleranceOfTheLeastRms) {
  // The RMS of tests/apps/batch_killed.sh's true sphere: the ovoids are 8 %
  // better, which the tolerance does not count as a difference.
  const std::vector<pipeline::ModelScore> sphere_truth = {{"sphere", 4, 0.1261}, {"ellipsoid", 9, 0.1212},
                                                          {"superellipsoid", 12, 0.1212}, {"ovoid", 15, 0.1165},
                                                          {"superovoid", 18, 0.1160}};
  pipeline::ModelSelection s = pipeline::selectParsimonious(sphere_truth);
  EXPECT_EQ(s.selected, "sphere");
  EXPECT_EQ(s.indistinguishable.size(), 5u);
  // A clear superellipsoid: the ellipsoid is 54 % worse, the ovoid 16 %.
  s = pipeline::selectParsimonious({{"sphere", 4, 0.325}, {"ellipsoid", 9, 0.169}, {"superellipsoid", 12, 0.1105},
                                    {"ovoid", 15, 0.128}, {"superovoid", 18, 0.1100}});
  EXPECT_EQ(s.selected, "superellipsoid");
  // (0.128 lies within the 0.03 mm floor of 0.1100: the ovoid is not told apart, but it is not simpler.)
  EXPECT_EQ(s.indistinguishable, (std::vector<std::string>{"superellipsoid", "ovoid", "superovoid"}));
  EXPECT_EQ(pipeline::selectParsimonious({{"sphere", 4, 0.325}, {"ellipsoid", 9, 0.169}, {"superellipsoid", 12, 0.1105},
                                          {"ovoid", 15, 0.128}, {"superovoid", 18, 0.1100}}, 0.10, 0.0)
                .indistinguishable,
            (std::vector<std::string>{"superellipsoid", "superovoid"}));
  // A 1 % tolerance without a floor keeps only the ovoids (0.1165 <= 1.01 x
  // 0.1160): the simpler ovoid; with none, the least RMS. Equal counts go by RMS.
  EXPECT_EQ(pipeline::selectParsimonious(sphere_truth, 0.01, 0.0).selected, "ovoid");
  EXPECT_EQ(pipeline::selectParsimonious(sphere_truth, 0.0, 0.0).selected, "superovoid");
  // A sphere on the CT's edge (articula run on the phantom of seed 21): the
  // ovoids 13 % better, 0.018 mm, below the floor; the sphere is selected.
  const std::vector<pipeline::ModelScore> sharp_sphere = {{"sphere", 4, 0.1397}, {"ellipsoid", 9, 0.1258},
                                                          {"superellipsoid", 12, 0.1253}, {"ovoid", 15, 0.1220},
                                                          {"superovoid", 18, 0.1216}};
  EXPECT_EQ(pipeline::selectParsimonious(sharp_sphere).selected, "sphere");
  EXPECT_EQ(pipeline::selectParsimonious(sharp_sphere, 0.10, 0.0).selected, "ellipsoid");
  EXPECT_EQ(pipeline::selectParsimonious({{"a", 4, 0.2}, {"b", 4, 0.19}}).selected, "b");
  // Nothing finite: nothing selected.
  EXPECT_EQ(pipeline::selectParsimonious({{"sphere", 4, NAN}}).selected, "");
}

TEST(ModelSelection, ModelsThePointsLeaveOpenTakeNoPart) {
  // The real thorax's right humeral head: the superellipsoid, ovoid and
  // superovoid had radii or centres with 95 % intervals of +-15 to +-28 mm.
  // With them, the ovoid (radii 33.8, 33.8, 14.9 mm) would be selected;
  // without, the ellipsoid, the least RMS of the determined models.
  std::vector<pipeline::ModelScore> shoulder = {{"sphere", 4, 0.4786},          {"ellipsoid", 9, 0.3957},
                                                {"superellipsoid", 12, 0.3731}, {"ovoid", 15, 0.3418},
                                                {"superovoid", 18, 0.3156}};
  EXPECT_EQ(pipeline::selectParsimonious(shoulder).selected, "ovoid");
  for (size_t i = 2; i < shoulder.size(); ++i) shoulder[i].determined = false;
  const pipeline::ModelSelection s = pipeline::selectParsimonious(shoulder);
  EXPECT_EQ(s.selected, "ellipsoid");
  EXPECT_EQ(s.indistinguishable, std::vector<std::string>{"ellipsoid"});
  EXPECT_EQ(s.undetermined, (std::vector<std::string>{"superellipsoid", "ovoid", "superovoid"}));
  // None determined: all take part, as before.
  for (auto& m : shoulder) m.determined = false;
  EXPECT_EQ(pipeline::selectParsimonious(shoulder).selected, "ovoid");
}

}  // namespace
}  // namespace articula
