#pragma once
// Intervals that take in an egg model's other local optima.
//
// An ovoid or superovoid fitted to a cap often has several local optima of
// nearly the same sum of squares: the egg's axis along another of the
// parent ellipsoid's axes (or the other way along it), its centre and
// semi-axes millimetres apart. Each optimum's linearised interval holds
// only its own basin: on simulated caps with correlated errors the
// hierarchy's optimum held the true centre and semi-axes for about 70 % of
// them (docs/benchmarks.md, "Model selection and intervals on caps"), and
// 53 of 60 ovoid caps had another optimum within the bound below. The
// centre's and semi-axes' intervals are therefore widened to take in every
// other optimum the data do not rule out, each with its own interval: one
// whose sum of squares lies within the likelihood-ratio bound of the best
// (chi^2_1 at 95 % times the residuals' variance, times the design effect
// the sandwich found for the least-determined centre coordinate), or one
// that, taken as the truth, errors of the fit's covariance could have made
// look as much worse as it does (couldBeTheTruth, along the two surfaces'
// difference: a smooth difference, which correlated errors mimic, is ruled
// out only by a larger rise than the bound's). The egg terms and angles of
// another labelling describe another frame and are not compared: their
// intervals stay those of the reported optimum's basin.
#include <vector>

#include <Eigen/Core>

#include "articula/fit/residual_correlation.hpp"
#include "articula/fit/uncertainty.hpp"
#include "articula/geometry/shape.hpp"

namespace articula::fit {

/// Another local optimum of the same model on the same points (not the
/// reported one itself).
struct OtherOptimum {
  geometry::ShapeParameters parameters;
  double sse_mm2 = 0;
  ParameterUncertainty uncertainty;  // at it (needed only when within the bound)
};

/// The rise of the sum of squares above `sse_mm2` (the optimum's, on
/// `points` points, with uncertainty `u`) within which another optimum is
/// as supported: chi^2_1 at 95 % times SSE / (n - k), times the design
/// effect (standard error / independent one, squared, at least 1) of the
/// centre coordinate with the largest standard error. 0 where that is not finite.
double likelihoodRatioBoundMm2(const geometry::ShapeParameters& fitted, const ParameterUncertainty& u, double sse_mm2,
                               Eigen::Index points);

/// Whether errors of covariance `errors` (residual_correlation.hpp) about
/// another optimum, whose residuals on `points` are `theirs`, could have
/// favoured the reported one (residuals `own`) as much as they do. With
/// d = own - theirs the reported sum of squares is the other's + 2
/// theirs.d + |d|^2, so the other's residuals lean towards the reported
/// surface by -theirs.d = (rise + |d|^2) / 2; were the other the truth, that
/// lean would be normal with variance d^T Sigma d. False when it passes the
/// one-sided 5 % point over `alternatives` (Bonferroni: the reported optimum
/// is the best of that many others, so the truth's lean towards it is the
/// largest of as many chances; 2.33 standard deviations for five).
/// Correlated errors mimic a smooth difference between two surfaces, so
/// this admits rises many times the likelihood-ratio bound, which takes the
/// correlation from the centre's standard error alone.
bool couldBeTheTruth(const Eigen::VectorXd& own, const Eigen::VectorXd& theirs, const Eigen::MatrixX3d& points,
                     const ResidualCorrelation& errors, int alternatives = 1);

/// Widens the intervals of `fitted`'s centre (t1..t3) and semi-axes (a c0x,
/// b c0y, c; each matched to the other optimum's axis most nearly parallel)
/// to take in each of `others` (the optima the data do not rule out), with
/// that optimum's own interval (its value alone where that is not finite);
/// `bound_mm2` is recorded. A widened standard error
/// becomes its interval's half width over 1.96 (the interval may be
/// asymmetric); one whose interval grows useless is listed as not identifiable.
void spanOtherOptima(const geometry::ShapeParameters& fitted, double bound_mm2, const std::vector<OtherOptimum>& others,
                     ParameterUncertainty& u);

}  // namespace articula::fit
