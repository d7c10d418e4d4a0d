#pragma once
// Statistics of a morphology study: summaries of signed errors, the paired
// Wilcoxon signed-rank test, and information criteria that weigh the number
// of parameters beside the fit.
#include <string>
#include <vector>

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

/// Which model the data support. The least RMS always goes to the most
/// flexible model, and AIC/BIC on a thousand points from a voxelised,
/// meshed surface reward fitting its systematic (staircase, smoothing)
/// deviations: on phantoms of known shape they pick the ovoid for a true
/// sphere. So the selected model is the simplest (fewest parameters, then
/// least RMS) whose RMS exceeds the least RMS by no more than the larger of
/// `relative_tolerance` x the least RMS and `absolute_tolerance_mm`;
/// `indistinguishable` lists every model within it, i.e. the models these
/// points cannot tell apart. The absolute part: once the surface sits on the
/// CT's edge (RMS ~0.1 mm), what is left is a few hundredths of a
/// millimetre of systematic, direction-dependent error (anisotropic voxels
/// blur a thin cortex more along their long axis), which a more flexible
/// model absorbs; on phantoms of known shape it leaves a true sphere 11-15 %
/// (0.015-0.02 mm) above the ovoids.
/// Only models the points determine take part: one whose centre, radii or
/// exponents the points leave open (fit/uncertainty.hpp's not_identifiable;
/// an angle may be open, as a spheroid's spin is, and so may the ovoid
/// terms, whose scale the ovoids share with a and b) has
/// bought its low RMS with freedom the data do not constrain, and its
/// parameters would be reported as if measured. On a real shoulder an ovoid
/// with radii at their bounds and +-28 mm intervals had the least RMS but
/// one. When no model is determined, all take part.
struct ModelScore {
  std::string model;
  int n_parameters = 0;
  double rms_mm = 0.0;
  bool determined = true;
};
struct ModelSelection {
  std::string selected;
  std::vector<std::string> indistinguishable;  // in the order given
  std::vector<std::string> undetermined;       // left out, in the order given
};
ModelSelection selectParsimonious(const std::vector<ModelScore>& scores, double relative_tolerance = 0.10,
                                  double absolute_tolerance_mm = 0.03);

}  // namespace articula::pipeline
