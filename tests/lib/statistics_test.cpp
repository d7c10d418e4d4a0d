// The study statistics: the Wilcoxon test against brute force, summaries
// and information criteria, and the model selection's nested tests.
#include <cmath>
#include <random>

#include <boost/math/distributions/fisher_f.hpp>
#include <gtest/gtest.h>

#include "articula/core/error.hpp"
#include "articula/fit/fit_hierarchy.hpp"
#include "articula/fit/residual_correlation.hpp"
#include "articula/statistics/cohort.hpp"
#include "articula/statistics/model_selection.hpp"
#include "articula/testsupport/synthetic_cap.hpp"

namespace p = articula::statistics;

namespace {
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

namespace articula {
namespace {

TEST(ModelSelection, TheNestedFTestCountsTheEffectivePoints) {
  // F(2, d2) has the closed-form tail (1 + 2 f / d2)^(-d2 / 2).
  const statistics::ModelEvidence sphere{"sphere", 4, 1004, 10.0, 1004.0, true};
  const statistics::ModelEvidence ellipsoid{"sphere-like", 6, 1004, 9.9, 1004.0, true};
  const statistics::NestedStep plain = statistics::nestedFTest(sphere, ellipsoid, 0.05);
  const double f = (0.1 / 2) / (9.9 / 998);
  EXPECT_NEAR(plain.f, f, 1e-9);
  EXPECT_NEAR(plain.p_value, std::pow(1 + 2 * f / 998, -998 / 2.0), 1e-9);
  EXPECT_TRUE(plain.richer_needed);  // p = 0.0066: as independent points, a 1 % gain is real
  // The same fall with 50 effective points in both models' residuals: F / 20,
  // no longer significant; with 50 in one and 200.8 in the other, their
  // geometric mean (100.4): F / 10.
  statistics::ModelEvidence simpler = sphere, correlated = ellipsoid;
  simpler.n_eff = correlated.n_eff = 50.2;
  statistics::NestedStep step = statistics::nestedFTest(simpler, correlated, 0.05);
  EXPECT_NEAR(step.f, f / 20, 1e-9);
  EXPECT_GT(step.p_value, 0.5);
  EXPECT_FALSE(step.richer_needed);
  correlated.n_eff = 200.8;
  step = statistics::nestedFTest(simpler, correlated, 0.05);
  EXPECT_NEAR(step.f, f / 10, 1e-9);
  EXPECT_NEAR(step.n_eff, 100.4, 1e-9);
}

// The test's degrees of freedom are the free parameters: an ovoid's c0x and
// c0y trade with a and b (one surface), so an ovoid has 6 more than an
// ellipsoid, not 8. The edge offset field the voxels allow adds its expected
// part to the fall's expected value and its spread to the degrees of freedom
// (Satterthwaite): F = fall / (s^2 df1 + mu), h = 2 (s^2 df1 + mu)^2 / (2 s^4 df1 + v).
TEST(ModelSelection, TheTestCountsFreeParametersAndTheEdgeFieldsSpread) {
  using geometry::ShapeModel;
  EXPECT_EQ(geometry::freeParameterCount(ShapeModel::Sphere), 4);
  EXPECT_EQ(geometry::freeParameterCount(ShapeModel::Superellipsoid), 12);
  EXPECT_EQ(geometry::freeParameterCount(ShapeModel::Ovoid), 15);
  EXPECT_EQ(geometry::freeParameterCount(ShapeModel::Superovoid), 18);
  statistics::ModelEvidence ellipsoid{"ellipsoid", 9, 1000, 10.0, 1000.0, true, 0.0};
  statistics::ModelEvidence ovoid{"ovoid", geometry::freeParameterCount(ShapeModel::Ovoid), 1000, 9.9, 1000.0, true, 0.0};
  const double s2 = 9.9 / 985;
  // No field: the plain F test on (6, 985).
  statistics::NestedStep step = statistics::nestedFTest(ellipsoid, ovoid, 0.05);
  EXPECT_EQ(step.df1, 6);
  EXPECT_NEAR(step.f, (0.1 / 6) / s2, 1e-9);
  EXPECT_NEAR(step.df1_effective, 6.0, 1e-12);
  // The field's terms: the ovoid takes up 0.03 and 0.02 mm^2 more of two.
  ellipsoid.edge_offset_absorbed_terms_mm2 = Eigen::MatrixXd::Zero(5, 5);
  ellipsoid.edge_offset_absorbed_terms_mm2(0, 0) = 0.01;
  ovoid.edge_offset_absorbed_terms_mm2 = ellipsoid.edge_offset_absorbed_terms_mm2;
  ovoid.edge_offset_absorbed_terms_mm2(0, 0) += 0.03;
  ovoid.edge_offset_absorbed_terms_mm2(3, 3) += 0.02;
  step = statistics::nestedFTest(ellipsoid, ovoid, 0.05);
  const double mean = 6 * s2 + 0.05;
  EXPECT_NEAR(step.f, 0.1 / mean, 1e-9);
  EXPECT_NEAR(step.df1_effective, 2 * mean * mean / (12 * s2 * s2 + 2 * (0.03 * 0.03 + 0.02 * 0.02)), 1e-9);
  const double h_terms = step.df1_effective;
  // Only the sums known (an older fits.json): the field taken as one term,
  // the widest spread.
  statistics::ModelEvidence e_sum = ellipsoid, o_sum = ovoid;
  e_sum.edge_offset_absorbed_terms_mm2.resize(0, 0);
  o_sum.edge_offset_absorbed_terms_mm2.resize(0, 0);
  e_sum.edge_offset_absorbed_mm2 = 0.01;
  o_sum.edge_offset_absorbed_mm2 = 0.06;
  step = statistics::nestedFTest(e_sum, o_sum, 0.05);
  EXPECT_NEAR(step.f, 0.1 / mean, 1e-9);
  EXPECT_NEAR(step.df1_effective, 2 * mean * mean / (12 * s2 * s2 + 2 * 0.05 * 0.05), 1e-9);
  EXPECT_LT(step.df1_effective, h_terms);  // one term spreads more than two
  // A field the richer model takes up less of (it never can: clamped) adds nothing.
  std::swap(o_sum.edge_offset_absorbed_mm2, e_sum.edge_offset_absorbed_mm2);
  EXPECT_NEAR(statistics::nestedFTest(e_sum, o_sum, 0.05).f, (0.1 / 6) / s2, 1e-9);
}

// Where the simpler model is right, the richer model's gain is noise plus
// the edge offset field's share; a field carried by one term spreads like
// chi^2(1), several times its mean. The test must then take the richer
// model 5 % of the time at alpha 0.05; subtracting the field's mean alone
// took it 15-27 % of the time. Simulated: gains s^2 chi^2(6) + sum_t w_t chi^2(1).
TEST(ModelSelection, TheTestHoldsItsLevelWhenTheEdgeFieldCarriesTheGain) {
  const int n = 100000, draws = 20000;
  for (const auto& [s2, weights] : std::vector<std::pair<double, std::vector<double>>>{
           {0.001, {0.03}}, {0.005, {0.02, 0.01, 0.005}}, {0.01, {0.002}}}) {
    statistics::ModelEvidence simpler{"ellipsoid", 9, n, NAN, static_cast<double>(n), true, 0.0};
    statistics::ModelEvidence richer{"ovoid", 15, n, s2 * (n - 15), static_cast<double>(n), true, 0.0};
    simpler.edge_offset_absorbed_terms_mm2 = richer.edge_offset_absorbed_terms_mm2 = Eigen::MatrixXd::Zero(5, 5);
    for (size_t t = 0; t < weights.size(); ++t)
      richer.edge_offset_absorbed_terms_mm2(static_cast<Eigen::Index>(t), static_cast<Eigen::Index>(t)) = weights[t];
    std::mt19937 rng(7);
    std::chi_squared_distribution<double> noise(6.0), term(1.0);
    int taken = 0, taken_by_mean = 0;
    double field_mean = 0;
    for (double w : weights) field_mean += w;
    for (int i = 0; i < draws; ++i) {
      double fall = s2 * noise(rng);
      for (double w : weights) fall += w * term(rng);
      simpler.sse_mm2 = richer.sse_mm2 + fall;
      taken += statistics::nestedFTest(simpler, richer, 0.05).richer_needed;
      const double by_mean = std::max(0.0, fall - field_mean) / (6 * s2);
      taken_by_mean += boost::math::cdf(boost::math::complement(boost::math::fisher_f(6, n - 15), by_mean)) < 0.05;
    }
    SCOPED_TRACE(s2);
    EXPECT_NEAR(static_cast<double>(taken) / draws, 0.05, 0.008);
    if (field_mean > 3 * s2 * 6) {
      EXPECT_GT(static_cast<double>(taken_by_mean) / draws, 0.12);
    }
  }
}

TEST(ModelSelection, UndeterminedModelsAreNeverSelected) {
  // The ovoid's gain passes its test, but the points leave one of its
  // parameters open: it is listed, not selected; the ellipsoid is.
  std::vector<statistics::ModelEvidence> models = {{"sphere", 4, 2000, 50.0, 20, true},
                                                 {"ellipsoid", 9, 2000, 10.0, 40, true},
                                                 {"superellipsoid", 12, 2000, 9.99, 40, true},
                                                 {"ovoid", 17, 2000, 2.0, 40, false},
                                                 {"superovoid", 20, 2000, 1.99, 40, false}};
  statistics::ModelSelection s = statistics::selectNested(models);
  EXPECT_EQ(s.selected, "ellipsoid");
  EXPECT_EQ(s.undetermined, (std::vector<std::string>{"ovoid", "superovoid"}));
  ASSERT_EQ(s.steps.size(), 5u);
  EXPECT_TRUE(s.steps[0].richer_needed);   // sphere -> ellipsoid
  EXPECT_FALSE(s.steps[1].richer_needed);  // ellipsoid -> superellipsoid
  EXPECT_TRUE(s.steps[2].richer_needed);   // ellipsoid -> ovoid: needed, but not determined
  models[3].determined = true;
  EXPECT_EQ(statistics::selectNested(models).selected, "ovoid");
  // A level of 0 never takes a richer model.
  EXPECT_EQ(statistics::selectNested(models, 0.0).selected, "sphere");
  // None determined: all take part.
  for (auto& m : models) m.determined = false;
  EXPECT_EQ(statistics::selectNested(models).selected, "ovoid");
  // A superovoid whose own check passed, over an ovoid the points leave
  // open, is open too: the ellipsoid.
  for (auto& m : models) m.determined = m.model != "ovoid";
  s = statistics::selectNested(models);
  EXPECT_EQ(s.selected, "ellipsoid");
  EXPECT_EQ(s.undetermined, (std::vector<std::string>{"ovoid", "superovoid"}));
}

TEST(ModelSelection, CohortTestsOfPerSubjectSteps) {
  // Fisher: -2 (ln 0.05 + ln 0.05) = 11.98 against chi-square(4): e^(-x/2) (1 + x/2).
  const statistics::CohortStep two = statistics::cohortStep({0.05, 0.05}, {false, false});
  const double x = -4 * std::log(0.05);
  EXPECT_NEAR(two.fisher_p, std::exp(-x / 2) * (1 + x / 2), 1e-9);
  EXPECT_EQ(two.richer_needed, 0);
  EXPECT_NEAR(two.sign_test_p, 1.0, 1e-12);
  // Sign test: 4 of 4 cannot reach 0.05 (0.0625); 5 of 5 can (0.03125); 3 of 5: 0.5.
  EXPECT_NEAR(statistics::cohortStep({0.01, 0.01, 0.01, 0.01}, {true, true, true, true}).sign_test_p, 0.0625, 1e-12);
  EXPECT_NEAR(statistics::cohortStep({0.01, 0.01, 0.01, 0.01, 0.01}, {true, true, true, true, true}).sign_test_p, 0.03125, 1e-12);
  EXPECT_NEAR(statistics::cohortStep({0.01, 0.01, 0.01, 0.5, 0.5}, {true, true, true, false, false}).sign_test_p, 0.5, 1e-12);
}

// Both of the ellipsoid's children are needed over it, and the superovoid
// adds to the superellipsoid (p 0.038) but nothing to the ovoid (p 0.94):
// the ovoid is the simplest model nothing beats. (Moving on to the simplest
// child that passes, the superellipsoid, would have reached the superovoid
// without testing it against the ovoid.)
TEST(ModelSelection, TheSimplestModelNoRicherOneBeats) {
  const std::vector<statistics::ModelEvidence> models = {{"sphere", 4, 2000, 50.0, 40, true},
                                                       {"ellipsoid", 9, 2000, 10.0, 40, true},
                                                       {"superellipsoid", 12, 2000, 7.0, 40, true},
                                                       {"ovoid", 17, 2000, 5.0, 40, true},
                                                       {"superovoid", 20, 2000, 4.95, 40, true}};
  const statistics::ModelSelection s = statistics::selectNested(models);
  EXPECT_EQ(s.selected, "ovoid");
  EXPECT_TRUE(s.steps[1].richer_needed);   // ellipsoid -> superellipsoid
  EXPECT_TRUE(s.steps[2].richer_needed);   // ellipsoid -> ovoid
  EXPECT_TRUE(s.steps[3].richer_needed);   // superellipsoid -> superovoid
  EXPECT_FALSE(s.steps[4].richer_needed);  // ovoid -> superovoid
  // The tests made: the sphere against 4 models, the ellipsoid against 3,
  // the superellipsoid and the ovoid against the superovoid.
  ASSERT_EQ(s.path.size(), 9u);
  EXPECT_EQ(s.path.back().simpler, "ovoid");
  EXPECT_FALSE(s.path.back().richer_needed);
}

// Exact caps of each model of the hierarchy (head-like shapes whose
// departures from the parent are clear: radii 25/22/20 mm, exponents
// 2.2-2.6, egg terms c1 0.05-0.08) with errors that neighbouring points
// share (a field of 0.05 mm, correlation length 1.5 mm, 700 points), two
// caps each. With the points counted at the selection's length (4 mm, the
// report's default) the nested tests select the true model of at least 6 of
// the 10 and never a richer one (measured: 6; the misses are the ovoids'
// egg terms, which 25 effective points of a cap this small do not show);
// with each fit's own residual correlation, richer models absorb correlated
// noise its n_eff does not wholly count (measured: 3 of 10 richer, 5
// right); with the points taken as independent (the plain F test), a richer
// model nearly every time (measured: 0 right).
TEST(ModelSelection, SelectsTheTrueModelOfCapsWithCorrelatedErrors) {
  using geometry::ShapeModel;
  int right = 0, richer = 0, per_fit_richer = 0, plain_right = 0;
  for (ShapeModel model : geometry::allModels()) {
    geometry::ShapeParameters truth;
    truth.model = model;
    truth.center = Eigen::Vector3d(-35.0, 12.0, 160.0);
    truth.angles = Eigen::Vector3d(0.4, -0.3, 0.9);
    truth.radii = model == ShapeModel::Sphere ? Eigen::Vector3d::Constant(23.0) : Eigen::Vector3d(25.0, 22.0, 20.0);
    if (model == ShapeModel::Superellipsoid || model == ShapeModel::Superovoid) truth.exponents = Eigen::Vector3d(2.4, 2.2, 2.6);
    if (model == ShapeModel::Ovoid || model == ShapeModel::Superovoid) {
      truth.cx = Eigen::Vector4d(1.0, 0.08, 0.0, 0.0);
      truth.cy = Eigen::Vector4d(1.0, 0.05, 0.0, 0.0);
    }
    for (unsigned seed : {11u, 12u}) {
      const Eigen::MatrixX3d pts = fit::correlatedCap(truth, 80.0 * M_PI / 180.0, 700, 0.05, 1.5, seed);
      const fit::Summary s = fit::fitHierarchy(pts);
      const std::string chosen =
          statistics::selectNested(statistics::modelEvidence(s, fit::nEffectiveAtLength(pts, statistics::kDefaultSelectionLengthMm))).selected;
      right += chosen == geometry::modelName(model);
      richer += chosen != geometry::modelName(model) && geometry::contains(geometry::modelFromName(chosen), model);
      const std::string per_fit = statistics::selectNested(statistics::modelEvidence(s, NAN)).selected;
      per_fit_richer += per_fit != geometry::modelName(model) && geometry::contains(geometry::modelFromName(per_fit), model);
      plain_right += statistics::selectNested(statistics::modelEvidence(s, static_cast<double>(s.points))).selected == geometry::modelName(model);
    }
  }
  EXPECT_GE(right, 6);
  EXPECT_EQ(richer, 0);
  EXPECT_GE(per_fit_richer, 1);
  EXPECT_LE(plain_right, 2);
}

}  // namespace
}  // namespace articula
