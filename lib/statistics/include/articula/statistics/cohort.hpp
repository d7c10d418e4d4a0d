#pragma once
// Statistics of a morphology study's cohort: summaries of signed errors, the
// paired Wilcoxon signed-rank test, and the cohort's evidence for a step of
// the model hierarchy from its subjects' tests (model_selection.hpp).
#include <cmath>
#include <vector>

namespace articula::statistics {

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

}  // namespace articula::statistics
