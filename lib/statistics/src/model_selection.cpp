#include "articula/statistics/model_selection.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>

#include <boost/math/distributions/fisher_f.hpp>

#include "articula/core/error.hpp"
#include "articula/geometry/shape.hpp"

namespace articula::statistics {

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
    out.push_back({geometry::modelName(f.parameters.model), geometry::freeParameterCount(f.parameters.model), fits.points,
                   f.sse_mm2, std::isfinite(n_eff) ? n_eff : f.uncertainty.correlation.n_eff,
                   determinedByPoints(f.parameters.model, f.uncertainty.not_identifiable),
                   f.uncertainty.edge_offset_absorbed_mm2, f.uncertainty.edge_offset_absorbed_terms_mm2});
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
  const double noise = richer.sse_mm2 / step.df2 * n / step.n_eff;  // s^2 per effective point
  const double noise_mean = noise * step.df1, noise_variance = 2 * noise * noise * step.df1;
  // What the edge offset field the voxels allow gives the richer model's
  // extra parameters (a slice-shaped offset passes for an egg's terms).
  double field_mean = 0, field_variance = 0;
  const Eigen::MatrixXd& a_r = richer.edge_offset_absorbed_terms_mm2;
  const Eigen::MatrixXd& a_s = simpler.edge_offset_absorbed_terms_mm2;
  if (a_r.size() > 0 && a_r.rows() == a_r.cols() && a_r.rows() == a_s.rows() && a_r.cols() == a_s.cols()) {
    const Eigen::MatrixXd gained = 0.5 * ((a_r - a_s) + (a_r - a_s).transpose());
    field_mean = std::max(0.0, gained.trace());
    if (field_mean > 0) field_variance = 2 * gained.squaredNorm();
  } else {
    field_mean = std::max(0.0, richer.edge_offset_absorbed_mm2 - simpler.edge_offset_absorbed_mm2);
    field_variance = 2 * field_mean * field_mean;
  }
  const double mean = noise_mean + field_mean;
  step.f = fall / mean;
  step.df1_effective = 2 * mean * mean / (noise_variance + field_variance);
  step.p_value =
      boost::math::cdf(boost::math::complement(boost::math::fisher_f(step.df1_effective, step.df2), step.f));
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

}  // namespace articula::statistics
