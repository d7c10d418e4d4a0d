#pragma once
// Which shape model a head's points support: information criteria, and the
// nested F tests along the hierarchy with the points the residuals' spatial
// correlation leaves.
#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "articula/fit/fit_hierarchy.hpp"
#include "articula/geometry/shape.hpp"

namespace articula::statistics {

// Default of --selection-alpha: the level of the nested tests of the model
// selection (selectNested).
constexpr double kDefaultSelectionAlpha = 0.05;
// Default of --selection-length: the length over which the nested tests count
// a CT surface's errors as shared (mm). A fit's own residuals cannot tell it:
// over a cap they hold the shape a model misses and the slices' direction-
// dependent error, which a variogram takes for lengths of 5-50 mm, while the
// surface's making (blur, the mesh's and the edge model's smoothing over
// about 3 mm) ties neighbours over a few millimetres. Measured on phantom
// CTs of known shape (docs/benchmarks.md, model selection): 3.5-4.5 mm
// select best, from 0.6 to 3 mm voxels alike.
constexpr double kDefaultSelectionLengthMm = 4.0;

/// Gaussian-likelihood information criteria from n residuals with sum of
/// squares `sse` and k model parameters: AIC = n ln(sse/n) + 2k,
/// BIC = n ln(sse/n) + k ln(n) (constants dropped: compare within one point set).
double aic(double sse, int n, int k);
double bic(double sse, int n, int k);

/// Which model the points support: a nested test along the hierarchy
/// sphere -> ellipsoid -> {superellipsoid, ovoid} -> superovoid that counts
/// the points the residuals' spatial correlation leaves (fit/residual_correlation.hpp).
///
/// The test of a simpler model against a richer one that contains it is an
/// F test of the fall of the sum of squared distances with an effective
/// number of independent points n_eff, the geometric mean of the two
/// models' ModelEvidence::n_eff (the report stage gives every model the
/// points' n_eff at the selection's correlation length, subject_report.hpp;
/// with length 0, each fit's own from its residuals, where the simpler
/// model's count the richer model's gain as correlated noise and the richer
/// model's have absorbed part of the noise). Where the simpler model is
/// right, the fall is the noise's share, s^2 chi^2(df1) with
/// s^2 = SSE_r / (n - k_r) x n / n_eff (a smooth error field projects onto a
/// richer model's extra directions about n / n_eff times more than
/// independent noise would), plus the edge offset field's share, a quadratic
/// form in its few terms' weights of mean mu and variance v (fit/uncertainty.hpp,
/// edge_offset_absorbed_terms_mm2). Their sum is taken as a scaled chi^2 of the
/// same mean and variance (Satterthwaite):
///   F = fall / (s^2 df1 + mu) on (h, n - k_r) degrees of freedom,
///   h = 2 (s^2 df1 + mu)^2 / (2 s^4 df1 + v),
/// the plain F test with df1 = h where there is no field. Subtracting the
/// field's mean alone (an earlier rule) took a field carried by one or two
/// terms, which spreads as widely as chi^2(1), for a shape: spheres at
/// 2.5-3 mm slices became ovoids. Without the factor n_eff / n (the plain F
/// test, AIC, BIC) every small gain on a CT surface looks real.
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
  int n_parameters = 0;  // free ones (geometry::freeParameterCount): the F test's degrees of freedom
  int n_points = 0;
  double sse_mm2 = NAN;
  double n_eff = NAN;  // NaN: taken as n_points (independent residuals)
  bool determined = true;
  double edge_offset_absorbed_mm2 = 0;  // fits.json's: the edge offset field's sum of squares the model takes up
  // fits.json's, per pair of the field's terms (trace: the above). Empty: only
  // the sum known, taken as carried by one term (the widest spread).
  Eigen::MatrixXd edge_offset_absorbed_terms_mm2{};
};
struct NestedStep {
  std::string simpler, richer;
  double f = NAN;          // the statistic above
  int df1 = 0, df2 = 0;    // the richer model's extra free parameters; n - k_r
  double df1_effective = NAN;  // h above: df1 without an edge offset field
  double n_eff = NAN;      // as used: the geometric mean of the two models'
  double p_value = NAN;    // P(F(df1_effective, df2) >= f)
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

}  // namespace articula::statistics
