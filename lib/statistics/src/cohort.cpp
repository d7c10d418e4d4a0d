#include "articula/statistics/cohort.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>

#include <boost/math/distributions/chi_squared.hpp>
#include <boost/math/special_functions/beta.hpp>

#include "articula/core/error.hpp"

namespace articula::statistics {

Summary summarise(const std::vector<double>& v) {
  Summary s;
  s.n = static_cast<int>(v.size());
  if (v.empty()) return s;
  s.mean = std::accumulate(v.begin(), v.end(), 0.0) / s.n;
  if (s.n > 1) {
    double ss = 0.0;
    for (double x : v) ss += (x - s.mean) * (x - s.mean);
    s.sd = std::sqrt(ss / (s.n - 1));
  }
  return s;
}

WilcoxonResult wilcoxonSignedRank(const std::vector<double>& x, const std::vector<double>& y) {
  if (x.size() != y.size())
    throw ProcessingError("Wilcoxon test: expected paired samples of equal size, found " + std::to_string(x.size()) +
                          " and " + std::to_string(y.size()));
  std::vector<double> d;
  for (size_t i = 0; i < x.size(); ++i)
    if (x[i] != y[i]) d.push_back(x[i] - y[i]);
  WilcoxonResult r;
  r.n_used = static_cast<int>(d.size());
  if (d.empty()) return r;
  // Average ranks of |d|, doubled so that they stay integers.
  std::vector<size_t> order(d.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&d](size_t a, size_t b) { return std::fabs(d[a]) < std::fabs(d[b]); });
  std::vector<int> rank2(d.size());
  double tie_term = 0.0;
  for (size_t i = 0; i < order.size();) {
    size_t j = i;
    while (j + 1 < order.size() && std::fabs(d[order[j + 1]]) == std::fabs(d[order[i]])) ++j;
    const int doubled = static_cast<int>(i + j + 2);  // 2 * average of ranks i+1..j+1
    for (size_t k = i; k <= j; ++k) rank2[order[k]] = doubled;
    const double t = static_cast<double>(j - i + 1);
    tie_term += t * t * t - t;
    i = j + 1;
  }
  int w2 = 0, total2 = 0;
  for (size_t i = 0; i < d.size(); ++i) {
    total2 += rank2[i];
    if (d[i] > 0) w2 += rank2[i];
  }
  r.w_plus = w2 / 2.0;
  const int n = r.n_used;
  if (n <= 60) {
    // Exact: each rank joins W+ with probability 1/2, independently.
    std::vector<double> prob(static_cast<size_t>(total2) + 1, 0.0);
    prob[0] = 1.0;
    int reach = 0;
    for (int rk : rank2) {
      for (int s = reach; s >= 0; --s)
        if (prob[s] != 0.0) {
          prob[s + rk] += 0.5 * prob[s];
          prob[s] *= 0.5;
        }
      reach += rk;
    }
    double lower = 0.0, upper = 0.0;
    for (int s = 0; s <= total2; ++s) {
      if (s <= w2) lower += prob[s];
      if (s >= w2) upper += prob[s];
    }
    r.p_value = std::min(1.0, 2.0 * std::min(lower, upper));
    r.exact = true;
    return r;
  }
  const double mean = n * (n + 1) / 4.0;
  const double var = n * (n + 1) * (2.0 * n + 1) / 24.0 - tie_term / 48.0;
  const double diff = r.w_plus - mean;
  const double z = (std::fabs(diff) - 0.5) / std::sqrt(var);
  r.p_value = std::min(1.0, std::erfc(std::max(z, 0.0) / std::sqrt(2.0)));
  return r;
}

CohortStep cohortStep(const std::vector<double>& p_values, const std::vector<bool>& richer_needed) {
  CohortStep out;
  double sum = 0;
  int k = 0;
  for (double p : p_values)
    if (std::isfinite(p)) {
      sum += -2.0 * std::log(std::max(p, 1e-300));
      ++k;
    }
  if (k > 0) out.fisher_p = boost::math::cdf(boost::math::complement(boost::math::chi_squared(2.0 * k), sum));
  out.subjects = static_cast<int>(richer_needed.size());
  out.richer_needed = static_cast<int>(std::count(richer_needed.begin(), richer_needed.end(), true));
  if (out.subjects > 0) {
    // P(X >= x), X ~ Bin(k, 1/2); ibeta gives the binomial tail exactly.
    out.sign_test_p = out.richer_needed == 0 ? 1.0 : boost::math::ibeta(out.richer_needed, out.subjects - out.richer_needed + 1, 0.5);
  }
  return out;
}

}  // namespace articula::statistics
