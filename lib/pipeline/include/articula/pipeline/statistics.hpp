#pragma once
// Statistics of a morphology study: summaries of signed errors, the paired
// Wilcoxon signed-rank test, and information criteria that weigh the number
// of parameters beside the fit.
#include <cmath>
#include <string>
#include <vector>

#include "articula/fit/fit_hierarchy.hpp"
#include "articula/geometry/shape.hpp"

namespace articula::pipeline {

struct Summary {
  int n = 0;
  double mean = 0.0, sd = 0.0;  // sd with n - 1 (0 when n < 2)
};
Summary summarise(const std::vector<double>& values);

struct WilcoxonResult {
  int n_used = 0;          // pairs with a non-zero difference
  double w_plus = 0.0;     // sum of the ranks of positive differences x - y
  double p_value = 1.0;    // two-sided
  bool exact = false;      // exact permutation distribution (n_used <= 60) or normal approximation
};
/// Paired two-sided Wilcoxon signed-rank test of x against y (zero
/// differences dropped, tied |differences| given their average rank). Exact
/// for up to 60 non-zero pairs (conditional on the ties); beyond, the normal
/// approximation with tie and continuity corrections.
WilcoxonResult wilcoxonSignedRank(const std::vector<double>& x, const std::vector<double>& y);

/// Gaussian-likelihood information criteria from n residuals with sum of
/// squares `sse` and k model parameters: AIC = n ln(sse/n) + 2k,
/// BIC = n ln(sse/n) + k ln(n) (constants dropped: compare within one point set).
double aic(double sse, int n, int k);
double bic(double sse, int n, int k);

/// Which model the points support: a nested test along the hierarchy
/// sphere -> ellipsoid -> {superellipsoid, ovoid} -> superovoid that counts
/// the points the residuals' spatial correlation leaves (fit/residual_correlation.hpp).
///
/// The test of a simpler model against a richer one that contains it is the
/// F test of the fall of the sum of squared distances with an effective
/// number of independent points n_eff, the geometric mean of the two
/// models' ModelEvidence::n_eff (the report stage gives every model the
/// points' n_eff at the selection's correlation length, subject_report.hpp;
/// with length 0, each fit's own from its residuals, where the simpler
/// model's count the richer model's gain as correlated noise and the richer
/// model's have absorbed part of the noise):
///   F = ((SSE_s - SSE_r) / (k_r - k_s)) / (SSE_r / (n - k_r)) x n_eff / n,
/// on (k_r - k_s, n - k_r) degrees of freedom. A smooth error field (blur,
/// partial volume, anisotropic voxels) projects onto a richer model's extra
/// directions about n / n_eff times more than independent noise would; the
/// denominator's variance comes from all the points. Without the factor
/// (the plain F test, AIC, BIC) every small gain on a CT surface looks real.
///
/// The choice: every determined model is tested against each determined
/// model that contains it, at alpha / (their number) (Bonferroni). A model
/// is supported when it is the simplest or needed over every supported
/// model it contains; the selected model is the simplest supported one that
/// no model containing it beats. So a superellipsoid of equal
/// radii is chosen over the sphere although the ellipsoid adds nothing, and
/// an egg-shaped head whose ovoid leaves the superovoid nothing to add is
/// an ovoid, also where the superellipsoid (fewer parameters, not
/// containing the ovoid) is needed over the ellipsoid too.
///
/// Only models the points determine take part: one with a centre, radius,
/// exponent or ovoid term the points leave open (not_identifiable in
/// fits.json; an open angle, such as a spheroid's spin, is allowed, and an
/// ovoid's c0x and c0y are a gauge) would report parameters as if measured;
/// nor does a model containing such a one (more parameters cannot pin down
/// those they share). When no model is determined, all take part.
struct ModelEvidence {
  std::string model;
  int n_parameters = 0;
  int n_points = 0;
  double sse_mm2 = NAN;
  double n_eff = NAN;  // NaN: taken as n_points (independent residuals)
  bool determined = true;
};
struct NestedStep {
  std::string simpler, richer;
  double f = NAN;          // the statistic above
  int df1 = 0, df2 = 0;
  double n_eff = NAN;      // as used: the geometric mean of the two models'
  double p_value = NAN;    // P(F(df1, df2) >= f)
  double alpha = NAN;      // the level it was judged at
  bool richer_needed = false;  // p_value < alpha
};
/// Whether the points determine a model's shape and place: none of its
/// parameters among those its fit calls not identifiable but its angles (a
/// spheroid's spin may be open; its shape is not).
bool determinedByPoints(geometry::ShapeModel model, const std::vector<std::string>& not_identifiable);

/// The evidence of a fitted hierarchy, every model's points counted as
/// `n_eff` (NaN: each fit's own residual correlation).
std::vector<ModelEvidence> modelEvidence(const fit::Summary& fits, double n_eff);

/// The test of `simpler` against `richer` at level `alpha`.
NestedStep nestedFTest(const ModelEvidence& simpler, const ModelEvidence& richer, double alpha);

struct ModelSelection {
  std::string selected;
  std::vector<NestedStep> steps;   // the hierarchy's five steps (sphere -> ellipsoid, ellipsoid -> superellipsoid,
                                   // ellipsoid -> ovoid, superellipsoid -> superovoid, ovoid -> superovoid), each at alpha
  std::vector<NestedStep> path;    // every determined model against each containing it, at their Bonferroni levels
  std::vector<std::string> undetermined;  // left out, in the order given
};
/// `models` in any order (names of geometry::modelName); alpha in [0, 1):
/// 0 never takes a richer model.
ModelSelection selectNested(const std::vector<ModelEvidence>& models, double alpha = 0.05);

/// The cohort's evidence for one step from per-subject tests (p-values and
/// decisions at alpha): Fisher's combination of the p-values (-2 sum ln p
/// against chi-square with 2k degrees of freedom: is the richer model
/// needed in any subject?) and a sign test of the decisions (one-sided
/// binomial, P(X >= x) for X ~ Bin(k, 1/2): does a majority need it?).
/// Subjects are taken as independent. Fisher's method is carried by single
/// extreme subjects; the sign test cannot fall below 0.05 with fewer than 5
/// subjects (0.5^k).
struct CohortStep {
  int subjects = 0, richer_needed = 0;
  double fisher_p = NAN, sign_test_p = NAN;
};
CohortStep cohortStep(const std::vector<double>& p_values, const std::vector<bool>& richer_needed);

}  // namespace articula::pipeline
