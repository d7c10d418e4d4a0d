// The model selection on caps whose errors neighbouring points share
// (docs/benchmarks.md, "Model selection on caps with correlated errors"):
// for each true model of the hierarchy, caps of random head-like shapes
// (testsupport::randomHeadShape, radii within 6 % of each other) with a
// Gaussian error field along the normal of 0.05-0.2 mm and correlation
// length 0-5 mm, caps of half-angle 60-120 degrees about the shape's local
// z, 1,000 points; each fitted with the hierarchy and selected by
// statistics::selectNested at 0.05 with
//   - the points' n_eff at the selection's length (the report's default, 4 mm),
//   - each fit's own residual correlation (--selection-length 0).
// Prints one JSON line per cap (true model, length, noise, the truth's
// departure from the nearest simpler model on its exact cap, each model's
// RMS, the true model's fitted from the truth, the models the points leave
// undetermined, the two selections, every test of the first with its
// p-value (to score another rule from the same caps), and the errors of each fit containing
// the truth in its standard errors, the true model's own fit's parameters
// with the truth's and their standard errors); then per rule and true model the share
// right, richer than the truth (the test's false positives) and simpler or
// beside it (an ovoid for a superellipsoid); and the power: the share right
// by the truth's departure from its simpler models over the noise; and the
// coverage of the 95 % intervals (fit/uncertainty.hpp's default, the fit's
// own variogram) of the centre and semi-axes, of the true model's own fit
// and of every fit containing it, and of ovoids' and superovoids' own fits
// by where their egg terms c1 lie against the bound c1 >= 0. Every
// cap is seeded: a line is reproduced from its seed.
//   bench-selection-caps [--caps 200] [--jobs 2] [--seed 1] [--length 4] [--true MODEL]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <map>
#include <mutex>
#include <random>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "articula/fit/fit_hierarchy.hpp"
#include "articula/fit/residual_correlation.hpp"
#include "articula/geometry/shape.hpp"
#include "articula/statistics/model_selection.hpp"
#include "articula/testsupport/interval_errors.hpp"
#include "articula/testsupport/run_all.hpp"
#include "articula/testsupport/synthetic_cap.hpp"

using articula::geometry::ShapeModel;

int main(int argc, char** argv) {
  CLI::App app{"The model selection on caps with correlated errors"};
  int caps = 200, jobs = 2, points = 1000;
  unsigned seed = 1;
  double length_mm = 4.0;
  app.add_option("--caps", caps, "Caps per true model");
  app.add_option("--jobs", jobs, "Caps fitted at once (each on one thread)")->check(CLI::PositiveNumber);
  app.add_option("--seed", seed, "Base seed of every cap");
  app.add_option("--length", length_mm, "The selection's correlation length (mm)");
  app.add_option("--points", points, "Points per cap");
  std::string only;
  app.add_option("--true", only, "Only caps of this true model (their seeds unchanged)");
  CLI11_PARSE(app, argc, argv);

  const auto& models = articula::geometry::allModels();
  const int total = caps * static_cast<int>(models.size());
  const int first = only.empty() ? 0 : caps * static_cast<int>(articula::geometry::modelFromName(only));
  std::vector<nlohmann::json> lines(static_cast<size_t>(total));
  std::mutex print;
  articula::testsupport::runAll(only.empty() ? total : caps, jobs, [&](int k) {
    const int i = first + k;
    const ShapeModel model = models[static_cast<size_t>(i / caps)];
    const unsigned cap_seed = seed * 1000003u + static_cast<unsigned>(i);
    std::mt19937 rng(cap_seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const double length = 5.0 * u(rng), sigma = 0.05 + 0.15 * u(rng), half_angle_deg = 60.0 + 60.0 * u(rng);
    const auto truth = articula::fit::randomHeadShape(model, 0.06, cap_seed);
    const double half_angle = half_angle_deg * M_PI / 180.0;
    const Eigen::MatrixX3d noisy = length > 0.05
                                       ? articula::fit::correlatedCap(truth, half_angle, points, sigma, length, cap_seed)
                                       : articula::fit::syntheticCap(truth, half_angle, points, sigma, cap_seed);
    nlohmann::json line = {{"seed", cap_seed}, {"true", articula::geometry::modelName(model)}, {"length_mm", length},
                           {"sigma_mm", sigma}, {"half_angle_deg", half_angle_deg}};
    try {
      // The truth's departure from each simpler model: their fits to its exact cap.
      const articula::fit::Summary exact = articula::fit::fitHierarchy(articula::fit::syntheticCap(truth, half_angle, points, 0.0, cap_seed));
      double departure = INFINITY;
      for (const auto& f : exact.fits)
        if (f.parameters.model != model && articula::geometry::contains(model, f.parameters.model))
          departure = std::min(departure, std::sqrt(f.sse_mm2 / exact.points));
      line["departure_mm"] = std::isfinite(departure) ? nlohmann::json(departure) : nlohmann::json(nullptr);
      const articula::fit::Summary s = articula::fit::fitHierarchy(noisy);
      for (const auto& f : s.fits) {
        line["rms_mm"][articula::geometry::modelName(f.parameters.model)] = std::sqrt(f.sse_mm2 / s.points);
        if (!f.uncertainty.not_identifiable.empty())
          line["not_identifiable"][articula::geometry::modelName(f.parameters.model)] = f.uncertainty.not_identifiable;
        if (f.parameters.model == model) {
          const auto names = articula::geometry::parameterNames(model);
          const Eigen::VectorXd fitted = articula::geometry::toVector(f.parameters), truth_v = articula::geometry::toVector(truth);
          for (size_t q = 0; q < names.size(); ++q)
            line["own"][names[q]] = {fitted[static_cast<Eigen::Index>(q)], truth_v[static_cast<Eigen::Index>(q)],
                                     f.uncertainty.standard_error[static_cast<Eigen::Index>(q)]};
        }
        if (articula::geometry::contains(f.parameters.model, model)) {
          const auto z = articula::fit::intervalErrors(f.parameters, f.uncertainty, truth);
          line["z"][articula::geometry::modelName(f.parameters.model)] = {
              {"centre", {z.centre_z[0], z.centre_z[1], z.centre_z[2]}},
              {"semi_axes", {z.semi_axis_z[0], z.semi_axis_z[1], z.semi_axis_z[2]}},
              {"length_mm", f.uncertainty.correlation.effectiveLength()},
              {"correlated_share", f.uncertainty.correlation.correlatedShare()}};
        }
      }
      // The truth's own RMS on these points: a fit of the true model above it has stopped short of its optimum.
      line["truth_rms_mm"] = std::sqrt(articula::fit::fitFrom(truth, noisy).sse_mm2 / s.points);
      const double n_eff = articula::fit::nEffectiveAtLength(noisy, length_mm);
      line["n_eff"] = n_eff;
      const articula::statistics::ModelSelection chosen = articula::statistics::selectNested(articula::statistics::modelEvidence(s, n_eff));
      line["at_length"] = chosen.selected;
      line["undetermined"] = chosen.undetermined;
      for (const articula::statistics::NestedStep& st : chosen.path)  // every test's p-value, for other rules
        line["path"].push_back({{"simpler", st.simpler}, {"richer", st.richer}, {"p", st.p_value}});
      line["per_fit"] = articula::statistics::selectNested(articula::statistics::modelEvidence(s, NAN)).selected;
    } catch (const std::exception& e) {
      line["error"] = e.what();
    }
    std::lock_guard<std::mutex> lock(print);
    std::cout << line.dump() << std::endl;
    lines[static_cast<size_t>(i)] = line;
  });

  // Per rule and true model: right, richer than the truth, simpler.
  for (const char* rule : {"at_length", "per_fit"}) {
    std::printf("\n%s (%s):\n| true | caps | right | richer | simpler or beside |\n|---|---|---|---|---|\n", rule,
                std::string(rule) == "at_length" ? ("n_eff at " + std::to_string(length_mm).substr(0, 4) + " mm").c_str()
                                                 : "each fit's own residual correlation");
    for (ShapeModel model : models) {
      int n = 0, right = 0, richer = 0, simpler = 0;
      for (const auto& line : lines) {
        if (!line.is_object() || line.value("true", "") != articula::geometry::modelName(model) || !line.contains(rule))
          continue;
        const ShapeModel chosen = articula::geometry::modelFromName(line[rule].get<std::string>());
        ++n;
        right += chosen == model;
        richer += chosen != model && articula::geometry::contains(chosen, model);
        simpler += chosen != model && !articula::geometry::contains(chosen, model);
      }
      std::printf("| %s | %d | %.1f %% | %.1f %% | %.1f %% |\n", articula::geometry::modelName(model).c_str(), n,
                  100.0 * right / std::max(n, 1), 100.0 * richer / std::max(n, 1), 100.0 * simpler / std::max(n, 1));
    }
  }
  // Power: the share right of the caps whose truth departs from every
  // simpler model, by that departure over the noise.
  std::printf("\npower (true models other than the sphere), by departure / noise:\n| rule | below 0.5 | 0.5-1 | 1-2 | 2 and more |\n"
              "|---|---|---|---|---|\n");
  for (const char* rule : {"at_length", "per_fit"}) {
    const double edges[] = {0.0, 0.5, 1.0, 2.0, INFINITY};
    std::printf("| %s |", rule);
    for (int b = 0; b < 4; ++b) {
      int n = 0, right = 0;
      for (const auto& line : lines) {
        if (!line.contains(rule) || !line.contains("departure_mm") || !line["departure_mm"].is_number()) continue;
        const double ratio = line["departure_mm"].get<double>() / line["sigma_mm"].get<double>();
        if (ratio < edges[b] || ratio >= edges[b + 1]) continue;
        ++n;
        right += line[rule] == line["true"];
      }
      std::printf(" %.0f %% of %d |", 100.0 * right / std::max(n, 1), n);
    }
    std::printf("\n");
  }
  // Coverage: the share of |z| <= 1.96 over the three coordinates of the
  // centre and the three semi-axes, of the true model's own fit and of every
  // fit containing the truth.
  std::printf("\ncoverage of the 95 %% intervals (centre / semi-axes):\n| true | own fit | every fit containing it |\n|---|---|---|\n");
  auto share = [](const std::vector<double>& zs) {
    const long held = std::count_if(zs.begin(), zs.end(), [](double z) { return std::abs(z) <= 1.96; });
    return zs.empty() ? 0.0 : 100.0 * static_cast<double>(held) / static_cast<double>(zs.size());
  };
  for (ShapeModel model : models) {
    const std::string name = articula::geometry::modelName(model);
    std::vector<double> own[2], every[2];
    for (const auto& line : lines) {
      if (!line.is_object() || line.value("true", "") != name || !line.contains("z")) continue;
      for (const auto& [fitted, z] : line["z"].items())
        for (int part = 0; part < 2; ++part)
          for (const auto& v : z[part == 0 ? "centre" : "semi_axes"]) {
            if (!v.is_number()) continue;  // an interval the points leave undetermined
            every[part].push_back(v.get<double>());
            if (fitted == name) own[part].push_back(v.get<double>());
          }
    }
    std::printf("| %s | %.1f / %.1f %% | %.1f / %.1f %% |\n", name.c_str(), share(own[0]), share(own[1]), share(every[0]),
                share(every[1]));
  }
  // The egg terms' lower bound (c1 >= 0, thesis section 3.2.5): the own
  // fits of ovoids and superovoids by whether an egg term c1 ends on it or
  // its interval reaches it (the likelihood cut there), or both lie clear.
  std::printf("\nown fits by the egg terms' bound c1 >= 0 (centre and semi-axes together):\n"
              "| true | c1x or c1y on 0 | an interval reaching 0 | both clear |\n|---|---|---|---|\n");
  for (ShapeModel model : {ShapeModel::Ovoid, ShapeModel::Superovoid}) {
    const std::string name = articula::geometry::modelName(model);
    std::vector<double> by[3];
    for (const auto& line : lines) {
      if (!line.is_object() || line.value("true", "") != name || !line.contains("own") || !line.contains("z") ||
          !line["z"].contains(name))
        continue;
      int group = 2;
      for (const char* c1 : {"c1x", "c1y"}) {
        const auto& v = line["own"][c1];  // fitted, true, standard error
        const double fitted = v[0].get<double>(), se = v[2].is_number() ? v[2].get<double>() : INFINITY;
        if (fitted < 1e-6) group = 0;
        else if (fitted - 1.96 * se < 0.0) group = std::min(group, 1);
      }
      for (const char* part : {"centre", "semi_axes"})
        for (const auto& z : line["z"][name][part])
          if (z.is_number()) by[group].push_back(z.get<double>());
    }
    std::printf("| %s | %.1f %% of %zu | %.1f %% of %zu | %.1f %% of %zu |\n", name.c_str(), share(by[0]), by[0].size() / 6,
                share(by[1]), by[1].size() / 6, share(by[2]), by[2].size() / 6);
  }
  return 0;
}
