// Fitting synthetic caps of known shapes: parameters recovered without
// noise, RMS near sigma with noise, the nesting guarantee, determinism.
#include <array>
#include <cmath>
#include <limits>
#include <random>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "articula/core/error.hpp"
#include "articula/distance/signed_distance.hpp"
#include "articula/geometry/algebraic_fit.hpp"
#include "articula/fit/fit_hierarchy.hpp"
#include "articula/fit/levenberg_marquardt.hpp"
#include "articula/fit/other_optima.hpp"
#include "articula/fit/parameter_gradient.hpp"
#include "articula/fit/residual_correlation.hpp"
#include "articula/geometry/pose.hpp"
#include "articula/testsupport/synthetic_cap.hpp"
#include "articula/geometry/surface.hpp"

namespace {

using articula::fit::Options;
using articula::fit::Summary;
using articula::geometry::ShapeModel;
using articula::geometry::ShapeParameters;
using Eigen::Vector3d;

ShapeParameters trueShape(ShapeModel model) {
  ShapeParameters p;
  p.model = model;
  p.center = Vector3d(-35.0, 12.0, 160.0);
  p.angles = Vector3d(0.4, -0.3, 0.9);
  p.radii = model == ShapeModel::Sphere ? Vector3d::Constant(23.0) : Vector3d(25.0, 22.0, 20.0);
  if (model == ShapeModel::Superellipsoid || model == ShapeModel::Superovoid) p.exponents = Vector3d(2.4, 2.2, 2.6);
  if (model == ShapeModel::Ovoid || model == ShapeModel::Superovoid) {
    p.cx = Eigen::Vector4d(0.95, 0.08, 0.05, -0.04);
    p.cy = Eigen::Vector4d(0.97, 0.05, -0.06, 0.03);
  }
  return p;
}

void expectNested(const Summary& s) {
  const std::pair<ShapeModel, ShapeModel> edges[] = {{ShapeModel::Ellipsoid, ShapeModel::Sphere},
                                                     {ShapeModel::Superellipsoid, ShapeModel::Ellipsoid},
                                                     {ShapeModel::Ovoid, ShapeModel::Ellipsoid},
                                                     {ShapeModel::Superovoid, ShapeModel::Superellipsoid},
                                                     {ShapeModel::Superovoid, ShapeModel::Ovoid}};
  auto has = [&](ShapeModel m) {
    for (const auto& f : s.fits)
      if (f.parameters.model == m) return true;
    return false;
  };
  for (const auto& [child, parent] : edges)
    if (has(child) && has(parent)) {
      EXPECT_LE(s.fit(child).rms_mm, s.fit(parent).rms_mm + 1e-9);
    }
}


// The fitted axis (a column of `fitted`) most nearly along `axis`: a fit's
// radii come in its own axes' order.
int fittedAxisAlong(const Eigen::Matrix3d& fitted, const Eigen::Vector3d& axis) {
  int j = 0;
  for (int k = 1; k < 3; ++k)
    if (std::abs(fitted.col(k).dot(axis)) > std::abs(fitted.col(j).dot(axis))) j = k;
  return j;
}

TEST(AlgebraicStart, SphereAndEllipsoidExactOnExactPoints) {
  const ShapeParameters e = trueShape(ShapeModel::Ellipsoid);
  const Eigen::MatrixX3d pts = articula::fit::syntheticCap(e, 1.2, 400, 0.0, 1);
  const ShapeParameters fit = articula::geometry::algebraicEllipsoid(pts);
  EXPECT_LT((fit.center - e.center).norm(), 1e-6);
  Eigen::Vector3d r = fit.radii, rt = e.radii;
  std::sort(r.data(), r.data() + 3);
  std::sort(rt.data(), rt.data() + 3);
  EXPECT_LT((r - rt).norm(), 1e-6);
  const ShapeParameters s = articula::geometry::algebraicSphere(articula::fit::syntheticCap(trueShape(ShapeModel::Sphere), 1.0, 300, 0.0, 1));
  EXPECT_NEAR(s.radii[0], 23.0, 1e-9);
  EXPECT_LT((s.center - Vector3d(-35.0, 12.0, 160.0)).norm(), 1e-9);
}

TEST(ParameterGradient, MatchesFiniteDifferencesForEveryModel) {
  for (ShapeModel model : articula::geometry::allModels()) {
    const ShapeParameters p = trueShape(model);
    const Eigen::MatrixX3d at = articula::fit::syntheticCap(p, 1.5, 50, 0.8, 6);
    Eigen::MatrixXd J;
    Eigen::VectorXd norms;
    articula::fit::parameterGradient(p, at, J, norms);
    const Eigen::VectorXd lambda = articula::geometry::toVector(p);
    for (Eigen::Index k = 0; k < lambda.size(); ++k) {
      const double h = 1e-6;
      Eigen::VectorXd lp = lambda, lm = lambda;
      lp[k] += h;
      lm[k] -= h;
      const auto sp = articula::geometry::makeSurface(articula::geometry::fromVector(model, lp));
      const auto sm = articula::geometry::makeSurface(articula::geometry::fromVector(model, lm));
      for (Eigen::Index i = 0; i < at.rows(); ++i) {
        const Vector3d x = at.row(i).transpose();
        const double fd = (sp->value(x) - sm->value(x)) / (2 * h);
        EXPECT_NEAR(J(i, k), fd, 1e-6 * (1.0 + std::fabs(fd))) << articula::geometry::modelName(model) << " "
                                                              << articula::geometry::parameterNames(model)[k];
      }
    }
    const auto s = articula::geometry::makeSurface(p);
    EXPECT_NEAR(norms[0], s->gradient(at.row(0).transpose()).norm(), 1e-12);
  }
}

// Rosenbrock as least squares, r = (10 (y - x^2), 1 - x): minimum at (1, 1);
// with x <= 0.5 the bound holds x and the minimum is (0.5, 0.25). Points
// with y > 1.5 are invalid (as an ovoid whose denominator vanishes): the
// free run must end at (1, 1) anyway, and the invalid start is reported.
class Rosenbrock : public articula::fit::LeastSquaresProblem {
 public:
  bool evaluate(const Eigen::VectorXd& x, Eigen::VectorXd& r) override {
    if (x[1] > 1.5) return false;
    r = Eigen::Vector2d(10.0 * (x[1] - x[0] * x[0]), 1.0 - x[0]);
    last_ = x;
    return true;
  }
  void accept(Eigen::MatrixXd& J) override {
    J.resize(2, 2);
    J << -20.0 * last_[0], 10.0, -1.0, 0.0;
  }

 private:
  Eigen::VectorXd last_;
};

TEST(LevenbergMarquardt, ReachesFreeAndBoundConstrainedMinima) {
  Rosenbrock problem;
  const Eigen::Vector2d start(-1.2, 1.0);
  const double inf = std::numeric_limits<double>::infinity();
  const auto free = articula::fit::levenbergMarquardt(problem, start, Eigen::Vector2d(-inf, -inf),
                                                      Eigen::Vector2d(inf, inf));
  EXPECT_TRUE(free.converged) << free.termination;
  EXPECT_LT((free.x - Eigen::Vector2d(1.0, 1.0)).norm(), 1e-6);
  const auto bound = articula::fit::levenbergMarquardt(problem, start, Eigen::Vector2d(-inf, -inf),
                                                       Eigen::Vector2d(0.5, inf));
  EXPECT_TRUE(bound.converged) << bound.termination;
  EXPECT_NEAR(bound.x[0], 0.5, 1e-12);
  EXPECT_NEAR(bound.x[1], 0.25, 1e-6);
  EXPECT_LE(bound.evaluations, 200);
  const auto invalid = articula::fit::levenbergMarquardt(problem, Eigen::Vector2d(0.0, 2.0),
                                                         Eigen::Vector2d(-inf, -inf), Eigen::Vector2d(inf, inf));
  EXPECT_FALSE(std::isfinite(invalid.cost));
  EXPECT_EQ(invalid.evaluations, 1);
}

class RecoveryTest : public ::testing::TestWithParam<ShapeModel> {};

// Noise-free caps a little beyond a hemisphere: the true model recovers its
// parameters, compared through the shape itself (centre, radii, exponents).
TEST_P(RecoveryTest, NoiseFreeCapRecoversParameters) {
  const ShapeModel model = GetParam();
  const ShapeParameters truth = trueShape(model);
  const Eigen::MatrixX3d pts = articula::fit::syntheticCap(truth, 100.0 * M_PI / 180.0, 600, 0.0, 2);
  Options o;
  // The true model and its ancestors (which are fitted anyway).
  o.models.clear();
  for (ShapeModel m : articula::geometry::allModels())
    if (articula::geometry::contains(model, m)) o.models.push_back(m);
  const Summary s = articula::fit::fitHierarchy(pts, o);
  expectNested(s);
  ShapeParameters f_p = s.fit(model).parameters;
  std::cout << s.fullReport();
  // The local x and y axes may come out swapped (a quarter turn about z
  // describes the same surface): compare in the truth's labelling.
  const Eigen::Matrix3d R = articula::geometry::rotationFromAngles(f_p.angles);
  const Eigen::Matrix3d Rt = articula::geometry::rotationFromAngles(truth.angles);
  if (std::fabs(R.col(0).dot(Rt.col(0))) < std::fabs(R.col(1).dot(Rt.col(0)))) {
    std::swap(f_p.radii[0], f_p.radii[1]);
    std::swap(f_p.exponents[0], f_p.exponents[1]);
    std::swap(f_p.cx, f_p.cy);
  }
  EXPECT_LT(s.fit(model).rms_mm, 1e-6);
  EXPECT_LT((f_p.center - truth.center).norm(), 1e-4);
  if (model == ShapeModel::Sphere) {
    EXPECT_NEAR(f_p.radii[0], truth.radii[0], 1e-4);
  } else if (model == ShapeModel::Ovoid || model == ShapeModel::Superovoid) {
    // Only the products a p_x(z) and b p_y(z) are determined (a common factor
    // of a and cx cancels): compare those, in mm.
    EXPECT_LT((f_p.radii[0] * f_p.cx - truth.radii[0] * truth.cx).cwiseAbs().maxCoeff(), 1e-4);
    EXPECT_LT((f_p.radii[1] * f_p.cy - truth.radii[1] * truth.cy).cwiseAbs().maxCoeff(), 1e-4);
    EXPECT_NEAR(f_p.radii[2], truth.radii[2], 1e-4);
  } else if (model == ShapeModel::Ellipsoid) {
    // Any labelling of the three axes is the same ellipsoid.
    Vector3d r = f_p.radii, rt = truth.radii;
    std::sort(r.data(), r.data() + 3);
    std::sort(rt.data(), rt.data() + 3);
    EXPECT_LT((r - rt).cwiseAbs().maxCoeff(), 1e-4);
  } else {
    EXPECT_LT((f_p.radii - truth.radii).cwiseAbs().maxCoeff(), 1e-4);
  }
  EXPECT_LT((f_p.exponents - truth.exponents).cwiseAbs().maxCoeff(), 1e-4);
}

// With sigma = 0.1 mm along the normal, the true model's RMS is sigma to 5%.
TEST_P(RecoveryTest, NoisyCapRmsMatchesSigma) {
  const ShapeModel model = GetParam();
  const Eigen::MatrixX3d pts = articula::fit::syntheticCap(trueShape(model), 80.0 * M_PI / 180.0, 1600, 0.1, 3);
  const Summary s = articula::fit::fitHierarchy(pts, Options{});
  expectNested(s);
  EXPECT_NEAR(s.fit(model).rms_mm, 0.1, 0.005);
  // The optimum is at least as good as the truth.
  const double truth_rms = std::sqrt(articula::fit::geometricObjective(trueShape(model), pts) / 1600.0);
  EXPECT_LE(s.fit(model).rms_mm, truth_rms + 1e-9) << s.fullReport();
}

INSTANTIATE_TEST_SUITE_P(AllModels, RecoveryTest,
                         ::testing::Values(ShapeModel::Sphere, ShapeModel::Ellipsoid, ShapeModel::Superellipsoid,
                                           ShapeModel::Ovoid, ShapeModel::Superovoid),
                         [](const auto& param_info) { return articula::geometry::modelName(param_info.param); });

// A 60-degree cap determines the ellipsoid's radii poorly: over five noise
// realisations the fit stays as good as the noise (RMS within 5 % of sigma,
// never worse than the truth), and the spread of the radii is reported, not
// asserted to be small.
TEST(FitHierarchy, SmallCapFitsTheNoiseAndReportsRadiusSpread) {
  const ShapeParameters truth = trueShape(ShapeModel::Ellipsoid);
  Options o;
  o.models = {ShapeModel::Sphere, ShapeModel::Ellipsoid};
  Eigen::MatrixXd radii(5, 3);
  for (int k = 0; k < 5; ++k) {
    const Eigen::MatrixX3d pts = articula::fit::syntheticCap(truth, 60.0 * M_PI / 180.0, 800, 0.1, 20 + k);
    const Summary s = articula::fit::fitHierarchy(pts, o);
    const double truth_rms = std::sqrt(articula::fit::geometricObjective(truth, pts) / 800.0);
    EXPECT_NEAR(s.fit(ShapeModel::Ellipsoid).rms_mm, 0.1, 0.005);
    EXPECT_LE(s.fit(ShapeModel::Ellipsoid).rms_mm, truth_rms + 1e-9);
    Vector3d r = s.fit(ShapeModel::Ellipsoid).parameters.radii;
    std::sort(r.data(), r.data() + 3);
    radii.row(k) = r.transpose();
  }
  const Eigen::RowVector3d mean = radii.colwise().mean();
  const Eigen::RowVector3d spread = ((radii.rowwise() - mean).array().square().colwise().sum() / 4.0).sqrt();
  std::cout << "60-degree cap, 5 noise realisations: sorted radii mean " << mean << " mm, std " << spread
            << " mm (truth 20 22 25)\n";
}

// Why each model stopped, as a type: converged runs on a noisy cap say
// which test ended them; an evaluation limit that cuts the ellipsoid short
// says so and is not converged, whatever the words say.
TEST(FitHierarchy, TerminationTypeTellsConvergedRunsFromCutOnes) {
  const Eigen::MatrixX3d pts = articula::fit::syntheticCap(trueShape(ShapeModel::Ellipsoid), 1.2, 600, 0.1, 8);
  Options o;
  o.models = {ShapeModel::Sphere, ShapeModel::Ellipsoid};
  for (const auto& f : articula::fit::fitHierarchy(pts, o).fits) {
    EXPECT_TRUE(f.converged) << f.termination;
    EXPECT_TRUE(articula::fit::isConverged(f.termination_type)) << articula::fit::terminationName(f.termination_type);
  }
  o.max_evaluations = 3;  // with no tolerance left to meet, only the limit ends a run
  o.relative_tolerance = 0;
  o.parameter_tolerance = 0;
  o.restarts = 0;
  const Summary cut_summary = articula::fit::fitHierarchy(pts, o);
  const articula::fit::ModelFit& cut = cut_summary.fit(ShapeModel::Ellipsoid);
  EXPECT_EQ(cut.termination_type, articula::fit::Termination::EvaluationLimit) << cut.termination;
  EXPECT_FALSE(cut.converged);
  EXPECT_STREQ(articula::fit::terminationName(cut.termination_type), "evaluation_limit");
}

TEST(FitHierarchy, DeterministicForAFixedSeed) {
  const Eigen::MatrixX3d pts = articula::fit::syntheticCap(trueShape(ShapeModel::Superovoid), 1.0, 400, 0.1, 4);
  Options o;
  o.strategy = articula::fit::Strategy::GlobalLocal;
  o.global_evaluations = 150;
  o.seed = 9;
  // The starts are screened over the threads: one thread or four, the same fits.
  o.threads = 1;
  const Summary a = articula::fit::fitHierarchy(pts, o);
  o.threads = 4;
  const Summary b = articula::fit::fitHierarchy(pts, o);
  for (size_t i = 0; i < a.fits.size(); ++i) {
    EXPECT_EQ(articula::geometry::toVector(a.fits[i].parameters), articula::geometry::toVector(b.fits[i].parameters));
    EXPECT_EQ(a.fits[i].evaluations, b.fits[i].evaluations);
    EXPECT_EQ(a.fits[i].started_from, b.fits[i].started_from);
  }
  expectNested(a);
}

// Many points: the hierarchy is fitted on a seeded random sample, then every
// model is finished on all the points. It ends where fitting all of them
// does (well within one standard error), and neither the seed nor the number
// of threads changes the result beyond the sample's own choice.
TEST(FitHierarchy, SampleThenAllPointsReachesTheFullOptimum) {
  const Eigen::MatrixX3d pts = articula::fit::syntheticCap(trueShape(ShapeModel::Superellipsoid), 1.2, 12000, 0.1, 31);
  Options all;
  all.models = {ShapeModel::Sphere, ShapeModel::Ellipsoid, ShapeModel::Superellipsoid};
  Options sampled = all;
  sampled.sample_points = 2000;
  sampled.threads = 4;  // against one thread below
  const Summary full = articula::fit::fitHierarchy(pts, all);
  const Summary part = articula::fit::fitHierarchy(pts, sampled);
  ASSERT_EQ(full.fits.size(), part.fits.size());
  expectNested(part);
  for (size_t i = 0; i < full.fits.size(); ++i) {
    const auto& f = full.fits[i];
    const auto& p = part.fits[i];
    const std::string model = articula::geometry::modelName(f.parameters.model);
    EXPECT_NE(p.started_from.find("random sample of 2000 of the 12000 points"), std::string::npos) << p.started_from;
    EXPECT_LE(p.rms_mm, f.rms_mm * (1 + 1e-5)) << model << ": " << p.termination;
    // The same surface where the points are (axis labellings may differ):
    // within a tenth of the noise.
    const Eigen::VectorXd gap = articula::distance::signedDistances(p.parameters, pts) -
                                articula::distance::signedDistances(f.parameters, pts);
    EXPECT_LT(gap.cwiseAbs().maxCoeff(), 0.01) << model;
  }
  Options one = sampled;
  one.threads = 1;
  const Summary one_thread = articula::fit::fitHierarchy(pts, one);
  for (size_t i = 0; i < part.fits.size(); ++i)
    EXPECT_EQ(articula::geometry::toVector(one_thread.fits[i].parameters), articula::geometry::toVector(part.fits[i].parameters));
}

// The exact-cap oracle of bench-fit-oracle on some of its near-spherical
// cases (radii within 3 %, random orientation, same seeds): 0 is reachable,
// so each family's own RMS must be <= 0.01 mm.
TEST(FitHierarchy, ExactNearSphericalCapsReachZero) {
  const ShapeModel families[] = {ShapeModel::Superellipsoid, ShapeModel::Ovoid, ShapeModel::Superovoid};
  for (int f = 0; f < 3; ++f)
    for (int k : {0, 2, 4}) {
      const unsigned seed = 1000003u + static_cast<unsigned>(f * 100000 + k);
      const ShapeParameters truth = articula::fit::randomHeadShape(families[f], 0.03, seed);
      std::mt19937 rng(seed);
      const double half_angle = std::uniform_real_distribution<double>(70.0, 110.0)(rng) * M_PI / 180.0;
      const Eigen::MatrixX3d pts = articula::fit::syntheticCap(truth, half_angle, 1500, 0.0, seed);
      Options o;  // the fits alone: their intervals, a third of the time under the sanitizers, are tested elsewhere
      o.span_other_optima = false;
      o.uncertainty = articula::fit::UncertaintyMethod::Independent;
      const Summary s = articula::fit::fitHierarchy(pts, o);
      EXPECT_LE(s.fit(families[f]).rms_mm, 0.01) << articula::geometry::modelName(families[f]) << " seed " << seed;
      expectNested(s);
    }
}

TEST(FitHierarchy, AlgebraicObjectiveKeepsNesting) {
  const Eigen::MatrixX3d pts = articula::fit::syntheticCap(trueShape(ShapeModel::Ovoid), 1.3, 600, 0.1, 5);
  Options o;
  o.objective = articula::fit::Objective::Algebraic;
  expectNested(articula::fit::fitHierarchy(pts, o));
}

TEST(FitHierarchy, RejectsBadOptionsAndTooFewPoints) {
  Options o;
  o.bounds["gamma9"] = {2.0, 3.0};
  const Eigen::MatrixX3d pts = articula::fit::syntheticCap(trueShape(ShapeModel::Sphere), 1.0, 100, 0.0, 1);
  EXPECT_THROW(articula::fit::fitHierarchy(pts, o), articula::UsageError);
  EXPECT_THROW(articula::fit::fitHierarchy(pts.topRows(10), Options{}), articula::InputError);
}

}  // namespace

// --bounds: every fitted parameter a bound names stays inside it, even where
// the parent's optimum lies outside (the start is clamped in, the nesting
// guarantee yields); a bound excluding the free optimum changes the answer.
TEST(FitHierarchy, UserBoundsAreHonoured) {
  const ShapeParameters truth = trueShape(ShapeModel::Superellipsoid);  // gamma1 2.4, theta -0.3
  const Eigen::MatrixX3d pts = articula::fit::syntheticCap(truth, 90.0 * M_PI / 180.0, 800, 0.0, 7);
  Options free_fit;
  free_fit.models = {ShapeModel::Sphere, ShapeModel::Ellipsoid, ShapeModel::Superellipsoid};
  const Summary a = articula::fit::fitHierarchy(pts, free_fit);
  Options bounded = free_fit;
  bounded.bounds = {{"gamma1", {2.05, 2.15}}, {"gamma3", {2.0, 2.1}}, {"theta", {0.2, 0.5}}};
  const Summary b = articula::fit::fitHierarchy(pts, bounded);
  for (ShapeModel m : {ShapeModel::Ellipsoid, ShapeModel::Superellipsoid}) {
    const ShapeParameters p = b.fit(m).parameters;
    const auto names = articula::geometry::parameterNames(m);
    const Eigen::VectorXd x = articula::geometry::toVector(p);
    for (size_t k = 0; k < names.size(); ++k)
      if (auto it = bounded.bounds.find(names[k]); it != bounded.bounds.end()) {
        EXPECT_GE(x[static_cast<Eigen::Index>(k)], it->second.first - 1e-9) << names[k];
        EXPECT_LE(x[static_cast<Eigen::Index>(k)], it->second.second + 1e-9) << names[k];
      }
  }
  EXPECT_LT(a.fit(ShapeModel::Superellipsoid).rms_mm, 0.01);  // free: the exact surface
  EXPECT_GT(b.fit(ShapeModel::Superellipsoid).rms_mm, 0.05);  // the bounds exclude it
}

TEST(ParameterKinds, OneKindPerParameterAndNoneTakenForAnother) {
  for (ShapeModel m : articula::geometry::allModels()) {
    const auto names = articula::geometry::parameterNames(m);
    const auto kinds = articula::geometry::parameterKinds(m);
    ASSERT_EQ(names.size(), kinds.size());
    for (size_t k = 0; k < names.size(); ++k) {
      using K = articula::geometry::ParameterKind;
      const std::string& n = names[k];
      const K expected = n == "a" || n == "b" || n == "c"                       ? K::Radius
                         : n == "t1" || n == "t2" || n == "t3"                  ? K::Translation
                         : n == "phi" || n == "theta" || n == "psi"             ? K::Angle
                         : n.size() == 6 && n.substr(0, 5) == "gamma"           ? K::Exponent
                         : n == "c0x" || n == "c1x" || n == "c0y" || n == "c1y" ? K::OvoidScale
                                                                                : K::OvoidCurvature;
      EXPECT_EQ(kinds[k], expected) << articula::geometry::modelName(m) << " " << n;
    }
  }
  EXPECT_EQ(articula::geometry::parameterUnit(articula::geometry::ParameterKind::Angle), "rad");
}

// The 95 % intervals of the Gauss-Newton covariance contain the truth about
// 95 % of the time over noisy caps of a known ellipsoid (sigma 0.1 mm): the
// radii (each matched to the true axis it lies along: a fit may label the
// axes otherwise) and the centre, between 88 and 99.5 % over 150 caps.
// Intervals half as wide (a covariance 4x too small) would cover about 68 %.
TEST(ParameterUncertainty, IntervalsCoverTheTruthAsOftenAsTheyClaim) {
  const ShapeParameters truth = trueShape(ShapeModel::Ellipsoid);
  const Eigen::Matrix3d Rt = articula::geometry::rotationFromAngles(truth.angles);
  Eigen::VectorXi covered = Eigen::VectorXi::Zero(6);  // radius along true axis 1..3, t1..t3
  const int trials = 150;
  Options o;
  o.models = {ShapeModel::Sphere, ShapeModel::Ellipsoid};
  for (int t = 0; t < trials; ++t) {
    const Eigen::MatrixX3d pts = articula::fit::syntheticCap(truth, 90.0 * M_PI / 180.0, 300, 0.1, 1000 + t);
    const articula::fit::ModelFit f = articula::fit::fitHierarchy(pts, o).fit(ShapeModel::Ellipsoid);
    ASSERT_TRUE(f.uncertainty.not_identifiable.empty());
    const Eigen::Matrix3d Rf = articula::geometry::rotationFromAngles(f.parameters.angles);
    const auto& u = f.uncertainty;
    for (int i = 0; i < 3; ++i) {
      const int j = fittedAxisAlong(Rf, Rt.col(i));
      covered[i] += u.ci95_lower[j] <= truth.radii[i] && truth.radii[i] <= u.ci95_upper[j];
      const Eigen::Index t_index = 3 + i;  // ellipsoid: a b c t1 t2 t3 phi theta psi
      covered[3 + i] += u.ci95_lower[t_index] <= truth.center[i] && truth.center[i] <= u.ci95_upper[t_index];
    }
  }
  const char* names[6] = {"radius 1", "radius 2", "radius 3", "t1", "t2", "t3"};
  for (int k = 0; k < 6; ++k) {
    const double share = static_cast<double>(covered[k]) / trials;
    EXPECT_GE(share, 0.88) << names[k];
    EXPECT_LE(share, 0.995) << names[k];
  }
}

TEST(ParameterUncertainty, TheOvoidsScaleIsAGaugeHeldWhileItsShapeIsDetermined) {
  // (a, c_jx) and (k a, c_jx / k) are one surface: c0x and c0y are held (the
  // gauge), and a true ovoid's semi-axes, centre and egg shape get intervals.
  const ShapeParameters truth = trueShape(ShapeModel::Ovoid);
  const Eigen::MatrixX3d pts = articula::fit::syntheticCap(truth, 1.4, 800, 0.05, 9);
  const articula::fit::Summary summary = articula::fit::fitHierarchy(pts, Options{});
  const articula::fit::ModelFit& f = summary.fit(ShapeModel::Ovoid);
  EXPECT_EQ(f.uncertainty.gauge, (std::vector<std::string>{"c0x", "c0y"}));
  EXPECT_TRUE(std::find(f.uncertainty.not_identifiable.begin(), f.uncertainty.not_identifiable.end(), "a") ==
              f.uncertainty.not_identifiable.end());
  EXPECT_TRUE(std::isfinite(f.uncertainty.condition_number));
  const auto names = articula::geometry::parameterNames(ShapeModel::Ovoid);
  const auto at = [&names](const char* n) { return std::find(names.begin(), names.end(), n) - names.begin(); };
  EXPECT_FALSE(std::isfinite(f.uncertainty.standard_error[at("c0x")]));
  // The semi-axis a c0x within its interval (c0x held, so a's interval scaled by it).
  const double semi = f.parameters.radii[0] * f.parameters.cx[0], se = f.uncertainty.standard_error[at("a")] * f.parameters.cx[0];
  EXPECT_LT(std::abs(semi - truth.radii[0] * truth.cx[0]), 4 * se);
  EXPECT_LT(se, 0.2);
  // The sphere misfits the egg: its residuals are the misfit, correlated over
  // the cap, and its radius is known far less well than independent
  // residuals would claim.
  const articula::fit::ModelFit& s = summary.fit(ShapeModel::Sphere);
  EXPECT_TRUE(s.uncertainty.not_identifiable.empty());
  EXPECT_GT(s.uncertainty.standard_error[0], 3 * s.uncertainty.independent_standard_error[0]);
}

// The edge offset field's part of the intervals against the shift the field
// itself causes: an exact ellipsoid cap (1,500 points, 80 degrees) whose
// points are moved along their normals by sd (f - mean f) for each of the
// field's terms (n_x, n_y, n_z, (n . s)^2 for an oblique slice axis s),
// refitted. To first order each term moves the estimate by bread J^T f sd,
// so the part reported for a radius or centre coordinate is the root sum of
// squares of those refits' shifts, and the field's sum of squares the model
// takes up is what the refits remove of it (each within 5 %, the fit's
// nonlinearity at a 0.05 mm field). A part off by the field's mean (the shared offset) or
// missing a term would miss by far more.
TEST(ParameterUncertainty, TheEdgeOffsetPartIsTheShiftItsFieldCauses) {
  const ShapeParameters truth = trueShape(ShapeModel::Ellipsoid);
  const Eigen::MatrixX3d cap = articula::fit::syntheticCap(truth, 80.0 * M_PI / 180.0, 1500, 0.0, 4);
  const auto surface = articula::geometry::makeSurface(truth);
  Eigen::MatrixX3d normals(cap.rows(), 3);
  for (Eigen::Index i = 0; i < cap.rows(); ++i)
    normals.row(i) = surface->gradient(cap.row(i).transpose()).normalized().transpose();
  const Eigen::Vector3d slice_axis = Eigen::Vector3d(0.2, -0.3, 1.0).normalized();
  articula::fit::EdgeOffsetField field;
  field.slice_axis = slice_axis;
  field.linear_sd_mm = 0.05;
  field.across_slices_sd_mm = 0.05;
  field.odd_across_slices_sd_mm = 0.05;
  Options o;
  o.models = {ShapeModel::Sphere, ShapeModel::Ellipsoid};
  // Shifts of the three radii (along the true axes) and the centre.
  Eigen::VectorXd expected_square = Eigen::VectorXd::Zero(6);
  double expected_absorbed = 0;
  const Eigen::VectorXd across = normals * slice_axis;
  std::array<double, 5> absorbed_by_term{};
  for (int term = 0; term < 5; ++term) {
    Eigen::VectorXd f = term < 3    ? Eigen::VectorXd(normals.col(term))
                        : term == 3 ? Eigen::VectorXd(across.array().square())
                                    : Eigen::VectorXd(across.array().cube());
    f.array() -= f.mean();
    const Eigen::MatrixX3d moved = cap + (0.05 * f).asDiagonal() * normals;
    const articula::fit::ModelFit refit = articula::fit::fitHierarchy(moved, o).fit(ShapeModel::Ellipsoid);
    const ShapeParameters& p = refit.parameters;
    // What the fit takes up of the field: the field's sum of squares less what it leaves.
    absorbed_by_term[term] = 0.05 * 0.05 * f.squaredNorm() - refit.sse_mm2;
    expected_absorbed += absorbed_by_term[term];
    const Eigen::Matrix3d Rf = articula::geometry::rotationFromAngles(p.angles);
    const Eigen::Matrix3d Rt = articula::geometry::rotationFromAngles(truth.angles);
    for (int i = 0; i < 3; ++i) {
      expected_square[i] += std::pow(p.radii[fittedAxisAlong(Rf, Rt.col(i))] - truth.radii[i], 2);
      expected_square[3 + i] += std::pow(p.center[i] - truth.center[i], 2);
    }
  }
  const articula::fit::ParameterUncertainty u =
      articula::fit::parameterUncertainty(truth, cap, {}, articula::fit::UncertaintyMethod::SpatialModel, field);
  EXPECT_GT(expected_absorbed, 0.5);
  EXPECT_NEAR(u.edge_offset_absorbed_mm2, expected_absorbed, 0.05 * expected_absorbed);
  // Per term, the diagonal of the terms' matrix (its trace the sum above).
  ASSERT_EQ(u.edge_offset_absorbed_terms_mm2.rows(), 5);
  EXPECT_NEAR(u.edge_offset_absorbed_terms_mm2.trace(), u.edge_offset_absorbed_mm2, 1e-12);
  for (int term = 0; term < 5; ++term)
    EXPECT_NEAR(u.edge_offset_absorbed_terms_mm2(term, term), absorbed_by_term[term], 0.05 * expected_absorbed) << term;
  for (int k = 0; k < 6; ++k) {
    const double expected = std::sqrt(expected_square[k]);
    EXPECT_GT(expected, 0.005) << k;  // the field moves every one of them
    EXPECT_NEAR(u.systematic_standard_error[k], expected, 0.05 * expected) << k;
  }
  // Sized from the voxels: none of the slices' term beyond its base for
  // isotropic 0.5 mm voxels, both larger at 1 x 1 x 3 mm.
  const auto fine = articula::fit::edgeOffsetField(Eigen::Vector3d(0.5, 0.5, 0.5), Eigen::Vector3d::UnitZ());
  const auto coarse = articula::fit::edgeOffsetField(Eigen::Vector3d(1.0, 1.0, 3.0), Eigen::Vector3d::UnitZ());
  EXPECT_LT(fine.linear_sd_mm, 0.005);
  EXPECT_GT(coarse.linear_sd_mm, 10 * fine.linear_sd_mm);
  EXPECT_GT(coarse.across_slices_sd_mm, 5 * fine.across_slices_sd_mm);
}

namespace {

// The correlation of the exponential field itself, summed over every pair:
// what n_eff estimates (n^2 sigma^2 / sum_ij cov_ij).
double trueEffectivePoints(const Eigen::MatrixX3d& points, double length_mm) {
  double sum = 0;
  for (Eigen::Index i = 0; i < points.rows(); ++i)
    for (Eigen::Index j = 0; j < points.rows(); ++j) sum += std::exp(-(points.row(i) - points.row(j)).norm() / length_mm);
  return static_cast<double>(points.rows()) * static_cast<double>(points.rows()) / sum;
}

}  // namespace

// Residual fields of known correlation length on an exact cap (a sphere of
// 23 mm, a hemisphere of 1,500 points about 1.2 mm apart): the variogram's
// fit gives back the length within 20 % on the mean of four fields (each
// within a factor 1.6: one field on a cap a dozen lengths across is a small
// sample of itself), the variance within 35 %, and n_eff within 30 % of the
// field's own on the geometric mean (each within a factor 2). White noise
// gives no correlated part and n_eff near n.
TEST(ResidualCorrelation, RecoversTheCorrelationLengthOfKnownFields) {
  const Eigen::MatrixX3d cap = articula::fit::syntheticCap(trueShape(ShapeModel::Sphere), 90.0 * M_PI / 180.0, 1500, 0.0, 1);
  for (double length : {1.5, 3.0}) {
    const double n_eff = trueEffectivePoints(cap, length);
    double mean_length = 0, mean_log_ratio = 0;
    for (unsigned seed = 1; seed <= 4; ++seed) {
      const Eigen::VectorXd field = articula::fit::exponentialField(cap, 0.1, length, seed);
      const articula::fit::ResidualCorrelation c = articula::fit::estimateResidualCorrelation(cap, field);
      EXPECT_GT(c.effectiveLength(), length / 1.6) << "L " << length << " seed " << seed;
      EXPECT_LT(c.effectiveLength(), length * 1.6) << "L " << length << " seed " << seed;
      EXPECT_NEAR(c.variance(), 0.01, 0.0035) << "L " << length << " seed " << seed;
      EXPECT_GT(c.n_eff, n_eff / 2) << "L " << length << " seed " << seed;
      EXPECT_LT(c.n_eff, n_eff * 2) << "L " << length << " seed " << seed;
      mean_length += c.effectiveLength() / 4;
      mean_log_ratio += std::log(c.n_eff / n_eff) / 4;
    }
    EXPECT_NEAR(mean_length, length, 0.2 * length);
    EXPECT_LT(std::abs(mean_log_ratio), std::log(1.3)) << "L " << length;
  }
  std::mt19937 rng(3);
  std::normal_distribution<double> gauss(0.0, 0.1);
  Eigen::VectorXd white(cap.rows());
  for (Eigen::Index i = 0; i < white.size(); ++i) white[i] = gauss(rng);
  const articula::fit::ResidualCorrelation c = articula::fit::estimateResidualCorrelation(cap, white);
  EXPECT_LT(c.correlatedShare(), 0.1);
  EXPECT_GT(c.n_eff, 0.8 * cap.rows());
}

// A fit takes up the smooth part of a correlated error, so its residuals'
// variogram alone gives too short a length: on ellipsoid caps (1,000
// points, 100 degrees) with errors correlated over 4 mm, the residuals
// read straight give 0.6-0.7 of it on the mean of six caps; read through
// the fit's projection (the fit's own, with its parameters' directions),
// within 25 % of it.
TEST(ResidualCorrelation, TheFitsProjectionRestoresTheLengthItsResidualsHide) {
  const ShapeParameters truth = trueShape(ShapeModel::Ellipsoid);
  Options o;
  o.models = {ShapeModel::Ellipsoid};
  constexpr double kLength = 4.0;
  double through_fit = 0, straight = 0;
  for (unsigned seed = 1; seed <= 6; ++seed) {
    const Eigen::MatrixX3d pts = articula::fit::correlatedCap(truth, 100.0 * M_PI / 180.0, 1000, 0.1, kLength, 40 + seed);
    const articula::fit::ModelFit f = articula::fit::fitHierarchy(pts, o).fit(ShapeModel::Ellipsoid);
    Eigen::VectorXd residual;
    Eigen::MatrixX3d feet;
    articula::distance::SignedDistance(f.parameters).evaluate(pts, residual, feet);
    through_fit += f.uncertainty.correlation.effectiveLength() / 6;
    straight += articula::fit::estimateResidualCorrelation(pts, residual).effectiveLength() / 6;
  }
  EXPECT_NEAR(through_fit, kLength, 0.25 * kLength);
  EXPECT_LT(straight, 0.8 * kLength);
}

// The points' effective number at a given length against the brute-force
// sum over every pair (the cells' approximation within 3 %); n at length 0;
// on a hemisphere of 23 mm about its area over 2 pi L^2 (within 30 %: the
// rim's points have fewer neighbours).
TEST(ResidualCorrelation, EffectivePointsAtALengthMatchTheSumOverPairs) {
  const Eigen::MatrixX3d cap = articula::fit::syntheticCap(trueShape(ShapeModel::Sphere), 90.0 * M_PI / 180.0, 1500, 0.0, 1);
  for (double length : {1.0, 4.0}) {
    const double exact = trueEffectivePoints(cap, length);
    EXPECT_NEAR(articula::fit::nEffectiveAtLength(cap, length), exact, 0.03 * exact) << "L " << length;
    const double area = 2.0 * M_PI * 23.0 * 23.0;
    EXPECT_NEAR(exact, area / (2.0 * M_PI * length * length), 0.3 * area / (2.0 * M_PI * length * length)) << "L " << length;
  }
  EXPECT_EQ(articula::fit::nEffectiveAtLength(cap, 0.0), 1500.0);
}

// Intervals on caps whose errors neighbouring points share (an ellipsoid,
// 300 points, a field of 0.1 mm and correlation length 4 mm): with the
// residuals' correlation (the default) the 95 % intervals of the centre and
// radii hold the truth in 85-100 % of 40 caps; taken as independent, in far
// fewer (below 72 %): the failure this guards against.
TEST(ParameterUncertainty, IntervalsHoldWithCorrelatedErrors) {
  const ShapeParameters truth = trueShape(ShapeModel::Ellipsoid);
  const Eigen::Matrix3d Rt = articula::geometry::rotationFromAngles(truth.angles);
  Options o;
  o.models = {ShapeModel::Sphere, ShapeModel::Ellipsoid};
  int spatial = 0, independent = 0, total = 0;
  for (unsigned t = 0; t < 40; ++t) {
    const Eigen::MatrixX3d pts = articula::fit::correlatedCap(truth, 85.0 * M_PI / 180.0, 300, 0.1, 4.0, 500 + t);
    const articula::fit::ModelFit f = articula::fit::fitHierarchy(pts, o).fit(ShapeModel::Ellipsoid);
    const Eigen::Matrix3d Rf = articula::geometry::rotationFromAngles(f.parameters.angles);
    const auto& u = f.uncertainty;
    for (int i = 0; i < 3; ++i) {
      const int j = fittedAxisAlong(Rf, Rt.col(i));
      const double radius_miss = std::abs(f.parameters.radii[j] - truth.radii[i]);
      const double centre_miss = std::abs(f.parameters.center[i] - truth.center[i]);
      spatial += (radius_miss <= 1.96 * u.standard_error[j]) + (centre_miss <= 1.96 * u.standard_error[3 + i]);
      independent += (radius_miss <= 1.96 * u.independent_standard_error[j]) +
                     (centre_miss <= 1.96 * u.independent_standard_error[3 + i]);
      total += 2;
    }
  }
  const double share = static_cast<double>(spatial) / total, naive = static_cast<double>(independent) / total;
  // Measured: 0.879 and 0.64 (0.825 with the residuals' variogram read
  // without the fit's projection; the variogram of one cap of a dozen
  // correlation lengths is itself a small sample, which the interval does
  // not widen for).
  EXPECT_GE(share, 0.85);
  EXPECT_LE(share, 1.0);
  EXPECT_LT(naive, 0.72);
}

// An ovoid cap with errors correlated over 4.5 mm (bench-selection-caps'
// cap of seed 1000198: 95 degrees, 1,000 points, 0.115 mm): the egg's
// optimum from the hierarchy lies 2.6 mm from the true centre along the cap's
// axis, 32 of its linearised standard errors, while the optimum from the
// true labelling of the ellipsoid's axes fits as well within the
// likelihood-ratio bound. The intervals that take in the other optima hold
// the true centre and semi-axes; the linearised ones do not.
TEST(ParameterUncertainty, AnEggsIntervalsTakeInItsOtherOptimaThatFitAsWell) {
  const unsigned seed = 1000198;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double length = 5.0 * u(rng), sigma = 0.05 + 0.15 * u(rng), half_angle = (60.0 + 60.0 * u(rng)) * M_PI / 180.0;
  const ShapeParameters truth = articula::fit::randomHeadShape(ShapeModel::Ovoid, 0.06, seed);
  const Eigen::MatrixX3d pts = articula::fit::correlatedCap(truth, half_angle, 1000, sigma, length, seed);
  Options linear;
  linear.span_other_optima = false;
  const auto names = articula::geometry::parameterNames(ShapeModel::Ovoid);
  const auto at = [&names](const std::string& n) { return std::find(names.begin(), names.end(), n) - names.begin(); };
  const auto holdsCentre = [&](const articula::fit::ModelFit& f) {
    bool all = true;
    for (int i = 0; i < 3; ++i) {
      const auto j = at("t" + std::to_string(i + 1));
      all = all && f.uncertainty.ci95_lower[j] <= truth.center[i] && truth.center[i] <= f.uncertainty.ci95_upper[j];
    }
    return all;
  };
  const articula::fit::ModelFit narrow = articula::fit::fitHierarchy(pts, linear).fit(ShapeModel::Ovoid);
  EXPECT_FALSE(holdsCentre(narrow));
  EXPECT_EQ(narrow.uncertainty.other_optima, 0);
  const articula::fit::ModelFit wide = articula::fit::fitHierarchy(pts, Options{}).fit(ShapeModel::Ovoid);
  EXPECT_EQ(wide.parameters.center, narrow.parameters.center);  // the same optimum reported
  EXPECT_GE(wide.uncertainty.other_optima, 1);
  EXPECT_GT(wide.uncertainty.other_optima_bound_mm2, 0.0);
  EXPECT_TRUE(holdsCentre(wide));
  // The true semi-axes (a c0x, b c0y, c), each within the interval of the fitted axis along it.
  const Eigen::Matrix3d Rt = articula::geometry::rotationFromAngles(truth.angles);
  const Eigen::Matrix3d Rf = articula::geometry::rotationFromAngles(wide.parameters.angles);
  const Vector3d true_semi(truth.radii[0] * truth.cx[0], truth.radii[1] * truth.cy[0], truth.radii[2]);
  const Vector3d factor(wide.parameters.cx[0], wide.parameters.cy[0], 1.0);
  for (int i = 0; i < 3; ++i) {
    const int j = fittedAxisAlong(Rf, Rt.col(i));
    const auto k = at(std::string(1, "abc"[j]));
    EXPECT_LE(wide.uncertainty.ci95_lower[k] * factor[j], true_semi[i]) << "axis " << i;
    EXPECT_GE(wide.uncertainty.ci95_upper[k] * factor[j], true_semi[i]) << "axis " << i;
  }
}

// A well-determined egg (an ovoid cap of 2 rad, 115 degrees, with
// independent errors of 0.05 mm): no other labelling's optimum comes within
// the bound, and the intervals stay the linearised ones. (On a cap of 1.4
// rad its c is known to +-16 mm and another optimum comes within it.)
// The test that takes in another optimum as the truth, on errors drawn
// with the covariance it is given (exponential, 0.1 mm over 3 mm, on a 20 x
// 20 mm patch of 400 points) about the other surface, the reported one a
// smooth 0.05 mm away: it holds the other as often as it claims (95 %, and
// 99 % as the best of five); told the same errors are independent, it
// rules it out far more often.
TEST(ParameterUncertainty, AnotherOptimumIsHeldAsOftenAsItsCorrelatedErrorsAllow) {
  const int side = 20, n = side * side;
  Eigen::MatrixX3d points(n, 3);
  for (int i = 0; i < n; ++i) points.row(i) = Vector3d(i % side, i / side, 0.0);
  articula::fit::ResidualCorrelation correlated;
  correlated.sill_mm2 = Eigen::Vector2d(0.01, 0.0);
  correlated.length_mm = Eigen::Vector2d(3.0, 0.0);
  articula::fit::ResidualCorrelation independent;
  independent.nugget_mm2 = 0.01;
  Eigen::MatrixXd covariance(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) covariance(i, j) = 0.01 * std::exp(-(points.row(i) - points.row(j)).norm() / 3.0);
  const Eigen::MatrixXd root = covariance.llt().matrixL();
  Eigen::VectorXd difference(n);
  for (int i = 0; i < n; ++i) difference[i] = 0.05 * std::cos(points(i, 0) / 6.0) * std::cos(points(i, 1) / 8.0);
  std::mt19937 rng(17);
  std::normal_distribution<double> normal;
  const int draws = 400;
  int held = 0, held_as_independent = 0, held_as_best_of_five = 0;
  for (int k = 0; k < draws; ++k) {
    Eigen::VectorXd z(n);
    for (int i = 0; i < n; ++i) z[i] = normal(rng);
    const Eigen::VectorXd theirs = root * z;
    held += articula::fit::couldBeTheTruth(theirs + difference, theirs, points, correlated);
    held_as_independent += articula::fit::couldBeTheTruth(theirs + difference, theirs, points, independent);
    held_as_best_of_five += articula::fit::couldBeTheTruth(theirs + difference, theirs, points, correlated, 5);
  }
  EXPECT_NEAR(static_cast<double>(held) / draws, 0.95, 0.03);
  EXPECT_NEAR(static_cast<double>(held_as_best_of_five) / draws, 0.99, 0.015);
  EXPECT_LT(static_cast<double>(held_as_independent) / draws, 0.8);
}

TEST(ParameterUncertainty, AWellDeterminedEggKeepsItsLinearisedIntervals) {
  const ShapeParameters truth = trueShape(ShapeModel::Ovoid);
  const Eigen::MatrixX3d pts = articula::fit::syntheticCap(truth, 2.0, 800, 0.05, 9);
  Options linear;
  linear.span_other_optima = false;
  const articula::fit::ModelFit narrow = articula::fit::fitHierarchy(pts, linear).fit(ShapeModel::Ovoid);
  const articula::fit::ModelFit wide = articula::fit::fitHierarchy(pts, Options{}).fit(ShapeModel::Ovoid);
  EXPECT_EQ(wide.uncertainty.other_optima, 0);
  EXPECT_GT(wide.uncertainty.other_optima_bound_mm2, 0.0);
  EXPECT_EQ(wide.uncertainty.ci95_lower, narrow.uncertainty.ci95_lower);
  EXPECT_EQ(wide.uncertainty.ci95_upper, narrow.uncertainty.ci95_upper);
}
