#include "articula/pipeline/statistics.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>

#include <boost/math/distributions/chi_squared.hpp>
#include <boost/math/distributions/fisher_f.hpp>
#include <boost/math/special_functions/beta.hpp>

#include "articula/core/error.hpp"
#include "articula/geometry/shape.hpp"

namespace articula::pipeline {

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

double aic(double sse, int n, int k) { return n * std::log(sse / n) + 2.0 * k; }
double bic(double sse, int n, int k) { return n * std::log(sse / n) + k * std::log(static_cast<double>(n)); }

bool determinedByPoints(geometry::ShapeModel model, const std::vector<std::string>& not_identifiable) {
  const auto names = geometry::parameterNames(model);
  const auto kinds = geometry::parameterKinds(model);
  for (const std::string& name : not_identifiable) {
    const auto it = std::find(names.begin(), names.end(), name);
    if (it == names.end() || kinds[static_cast<size_t>(it - names.begin())] != geometry::ParameterKind::Angle) return false;
  }
  return true;
}

std::vector<ModelEvidence> modelEvidence(const fit::Summary& fits, double n_eff) {
  std::vector<ModelEvidence> out;
  for (const auto& f : fits.fits)
    out.push_back({geometry::modelName(f.parameters.model), geometry::parameterCount(f.parameters.model), fits.points,
                   f.sse_mm2, std::isfinite(n_eff) ? n_eff : f.uncertainty.correlation.n_eff,
                   determinedByPoints(f.parameters.model, f.uncertainty.not_identifiable)});
  return out;
}

NestedStep nestedFTest(const ModelEvidence& simpler, const ModelEvidence& richer, double alpha) {
  NestedStep step;
  step.simpler = simpler.model;
  step.richer = richer.model;
  step.alpha = alpha;
  const int n = richer.n_points;
  step.df1 = richer.n_parameters - simpler.n_parameters;
  step.df2 = n - richer.n_parameters;
  // Each model's residuals misjudge the noise in one direction: the
  // simpler model's hold the richer model's gain as if it were correlated
  // noise (n_eff too low where the richer model is right), the richer
  // model's have absorbed part of the noise (n_eff too high where the
  // simpler one is right). Their geometric mean is used.
  const double n_simpler = std::isfinite(simpler.n_eff) ? std::min(simpler.n_eff, static_cast<double>(n)) : n;
  const double n_richer = std::isfinite(richer.n_eff) ? std::min(richer.n_eff, static_cast<double>(n)) : n;
  step.n_eff = std::sqrt(n_simpler * n_richer);
  if (step.df1 <= 0 || step.df2 <= 0 || !(richer.sse_mm2 > 0) || !std::isfinite(simpler.sse_mm2)) return step;
  // The hierarchy keeps SSE_r <= SSE_s; a hair above from rounding is no fall.
  const double fall = std::max(0.0, simpler.sse_mm2 - richer.sse_mm2);
  step.f = (fall / step.df1) / (richer.sse_mm2 / step.df2) * step.n_eff / n;
  step.p_value = boost::math::cdf(boost::math::complement(boost::math::fisher_f(step.df1, step.df2), step.f));
  step.richer_needed = step.p_value < alpha;
  return step;
}

ModelSelection selectNested(const std::vector<ModelEvidence>& models, double alpha) {
  ModelSelection out;
  const auto named = [&models](const std::string& name) -> const ModelEvidence* {
    for (const auto& m : models)
      if (m.model == name) return &m;
    return nullptr;
  };
  const auto contains = [](const std::string& general, const std::string& special) {
    try {
      return geometry::contains(geometry::modelFromName(general), geometry::modelFromName(special));
    } catch (const Error&) {
      return general == special;
    }
  };
  // A model containing one the points leave open is open too: more
  // parameters cannot pin down the ones they share (its own check, at
  // another optimum, may miss that).
  const auto determined = [&](const ModelEvidence& m) {
    return std::all_of(models.begin(), models.end(),
                       [&](const ModelEvidence& o) { return o.determined || !contains(m.model, o.model); });
  };
  const bool any_determined = std::any_of(models.begin(), models.end(), [&](const ModelEvidence& m) {
    return determined(m) && std::isfinite(m.sse_mm2);
  });
  for (const auto& m : models)
    if (!determined(m)) out.undetermined.push_back(m.model);
  const auto candidate = [&](const ModelEvidence& m) { return std::isfinite(m.sse_mm2) && (determined(m) || !any_determined); };
  for (const auto& [s, r] : std::vector<std::pair<const char*, const char*>>{{"sphere", "ellipsoid"},
                                                                            {"ellipsoid", "superellipsoid"},
                                                                            {"ellipsoid", "ovoid"},
                                                                            {"superellipsoid", "superovoid"},
                                                                            {"ovoid", "superovoid"}})
    if (named(s) && named(r)) out.steps.push_back(nestedFTest(*named(s), *named(r), alpha));
  // Every candidate against each candidate containing it, at alpha / the
  // number of those. A model is supported when it is the simplest or needed
  // over every supported model it contains; the selected one is the
  // simplest supported model that no model containing it beats.
  // (A walk that moved on to the simplest richer model passing its test
  // could reach the superovoid through the superellipsoid where the ovoid
  // was enough, never testing the superovoid against the ovoid.)
  std::vector<const ModelEvidence*> order;
  for (const auto& m : models)
    if (candidate(m)) order.push_back(&m);
  if (order.empty()) return out;
  std::stable_sort(order.begin(), order.end(),
                   [](const ModelEvidence* a, const ModelEvidence* b) { return a->n_parameters < b->n_parameters; });
  const auto within = [&](const ModelEvidence* richer, const ModelEvidence* simpler) {
    return richer != simpler && richer->n_parameters > simpler->n_parameters && contains(richer->model, simpler->model);
  };
  std::map<std::pair<const ModelEvidence*, const ModelEvidence*>, bool> needed;
  for (const ModelEvidence* simpler : order) {
    std::vector<const ModelEvidence*> richer;
    for (const ModelEvidence* m : order)
      if (within(m, simpler)) richer.push_back(m);
    for (const ModelEvidence* m : richer) {
      out.path.push_back(nestedFTest(*simpler, *m, alpha / static_cast<double>(richer.size())));
      needed[{simpler, m}] = out.path.back().richer_needed;
    }
  }
  std::vector<const ModelEvidence*> supported;
  for (const ModelEvidence* m : order) {
    bool over_all = true;
    for (const ModelEvidence* s : supported) over_all = over_all && (!within(m, s) || needed[{s, m}]);
    if (supported.empty() || over_all) supported.push_back(m);
  }
  for (const ModelEvidence* m : supported) {
    bool beaten = false;
    for (const ModelEvidence* r : order) beaten = beaten || (within(r, m) && needed[{m, r}]);
    if (!beaten) {
      out.selected = m->model;
      break;
    }
  }
  // Each supported model beaten by one its Bonferroni level let pass over
  // it but not over a simpler one: the richest supported.
  if (out.selected.empty()) out.selected = supported.back()->model;
  return out;
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

}  // namespace articula::pipeline
