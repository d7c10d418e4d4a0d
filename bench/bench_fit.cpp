// bench-fit: the whole hierarchy (sphere ... superovoid) on 1,600 points of a
// femoral-head-like cap (thesis table 3.7: 27-38 min per model in MATLAB),
// with our Levenberg-Marquardt (the default) and each NLopt local method,
// the thesis-style baseline (GN_ESCH on the algebraic objective with a fixed
// budget, from the same start), and the throughput of the signed distances.
// Counters: rms_* in mm.
#include <cmath>
#include <random>

#include <benchmark/benchmark.h>
#include <nlopt.hpp>

#include "articula/distance/signed_distance.hpp"
#include "articula/geometry/algebraic_fit.hpp"
#include "articula/fit/fit_hierarchy.hpp"
#include "articula/testsupport/synthetic_cap.hpp"
#include "articula/geometry/surface.hpp"

namespace {

using articula::geometry::ShapeModel;
using articula::geometry::ShapeParameters;
using Eigen::Vector3d;

ShapeParameters headShape(ShapeModel model) {
  ShapeParameters p;
  p.model = model;
  p.center = Vector3d(-80.0, -20.0, 95.0);
  p.angles = Vector3d(0.5, -0.4, 1.2);
  p.radii = Vector3d(24.5, 23.5, 22.5);
  if (model == ShapeModel::Superovoid || model == ShapeModel::Superellipsoid) p.exponents = Vector3d(2.09, 2.0, 2.05);
  if (model == ShapeModel::Superovoid || model == ShapeModel::Ovoid) {
    p.cx = Eigen::Vector4d(0.95, 0.02, 0.05, 0.04);
    p.cy = Eigen::Vector4d(0.97, 0.03, 0.03, 0.07);
  }
  return p;
}

const Eigen::MatrixX3d& headPoints() {
  static const Eigen::MatrixX3d pts = articula::fit::syntheticCap(headShape(ShapeModel::Superovoid), 100.0 * M_PI / 180.0, 1600, 0.3, 11);
  return pts;
}

void setRmsCounters(benchmark::State& state, const articula::fit::Summary& s) {
  for (const auto& f : s.fits) state.counters["rms_" + articula::geometry::modelName(f.parameters.model)] = f.rms_mm;
  int evaluations = 0;
  for (const auto& f : s.fits) evaluations += f.evaluations;
  state.counters["evaluations"] = evaluations;
}

void BM_FitHierarchy(benchmark::State& state, std::string algorithm, articula::fit::Strategy strategy) {
  articula::fit::Options o;
  o.local_algorithm = algorithm;
  o.strategy = strategy;
  articula::fit::Summary s;
  for (auto _ : state) s = articula::fit::fitHierarchy(headPoints(), o);
  setRmsCounters(state, s);
}
// The default (Levenberg-Marquardt on the signed distances) and NLopt's
// local methods from the same start; medians over repetitions for the first two.
BENCHMARK_CAPTURE(BM_FitHierarchy, local_LM, std::string("LM"), articula::fit::Strategy::Local)
    ->Unit(benchmark::kMillisecond)->Iterations(3)->Repetitions(5);
BENCHMARK_CAPTURE(BM_FitHierarchy, local_LD_SLSQP, std::string("LD_SLSQP"), articula::fit::Strategy::Local)
    ->Unit(benchmark::kMillisecond)->Iterations(3)->Repetitions(3);
BENCHMARK_CAPTURE(BM_FitHierarchy, local_LN_BOBYQA, std::string("LN_BOBYQA"), articula::fit::Strategy::Local)
    ->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK_CAPTURE(BM_FitHierarchy, local_LD_LBFGS, std::string("LD_LBFGS"), articula::fit::Strategy::Local)
    ->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK_CAPTURE(BM_FitHierarchy, local_LD_MMA, std::string("LD_MMA"), articula::fit::Strategy::Local)
    ->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK_CAPTURE(BM_FitHierarchy, global_CRS2_then_LM, std::string("LM"), articula::fit::Strategy::GlobalLocal)
    ->Unit(benchmark::kMillisecond)->Iterations(1);

// Thesis-style baseline: an evolutionary search (NLopt GN_ESCH) on the
// algebraic objective (eq. 3.1) for the superovoid, from the same ellipsoid
// start and within the same bounds, with a fixed budget of evaluations.
void BM_ThesisBaselineEsch(benchmark::State& state) {
  const Eigen::MatrixX3d& pts = headPoints();
  const ShapeParameters start =
      articula::geometry::promote(articula::geometry::algebraicEllipsoid(pts), ShapeModel::Superovoid);
  const Eigen::VectorXd x0 = articula::geometry::toVector(start);
  const auto names = articula::geometry::parameterNames(ShapeModel::Superovoid);
  std::vector<double> lo(x0.size()), hi(x0.size());
  for (size_t k = 0; k < names.size(); ++k) {
    const double v = x0[static_cast<Eigen::Index>(k)];
    const std::string& n = names[k];
    if (n == "a" || n == "b" || n == "c") { lo[k] = 0.5 * v; hi[k] = 1.5 * v; }
    else if (n.rfind("gamma", 0) == 0) { lo[k] = 2.0; hi[k] = 4.0; }
    else if (n[0] == 'c' && (n[1] == '0' || n[1] == '1')) { lo[k] = 0.0; hi[k] = 1.0; }
    else if (n[0] == 'c') { lo[k] = -0.1; hi[k] = 0.1; }
    else if (n[0] == 't') { lo[k] = v - 12.0; hi[k] = v + 12.0; }
    else { lo[k] = v - M_PI; hi[k] = v + M_PI; }
  }
  struct Data { const Eigen::MatrixX3d* pts; };
  Data data{&pts};
  auto objective = [](const std::vector<double>& x, std::vector<double>&, void* d) -> double {
    const Eigen::VectorXd l = Eigen::Map<const Eigen::VectorXd>(x.data(), static_cast<Eigen::Index>(x.size()));
    try {
      return articula::fit::algebraicObjective(articula::geometry::fromVector(ShapeModel::Superovoid, l),
                                               *static_cast<Data*>(d)->pts);
    } catch (const std::exception&) {
      return 1e30;
    }
  };
  double rms = 0.0;
  for (auto _ : state) {
    nlopt::srand(42);
    nlopt::opt opt(nlopt::GN_ESCH, static_cast<unsigned>(x0.size()));
    opt.set_lower_bounds(lo);
    opt.set_upper_bounds(hi);
    opt.set_min_objective(objective, &data);
    opt.set_maxeval(static_cast<int>(state.range(0)));
    std::vector<double> x(x0.data(), x0.data() + x0.size());
    double f = 0.0;
    try {
      opt.optimize(x, f);
    } catch (const nlopt::roundoff_limited&) {
    }
    const Eigen::VectorXd l = Eigen::Map<const Eigen::VectorXd>(x.data(), static_cast<Eigen::Index>(x.size()));
    rms = std::sqrt(articula::fit::geometricObjective(articula::geometry::fromVector(ShapeModel::Superovoid, l), pts) /
                    static_cast<double>(pts.rows()));
  }
  state.counters["rms_superovoid"] = rms;
}
BENCHMARK(BM_ThesisBaselineEsch)->Arg(20000)->Unit(benchmark::kMillisecond)->Iterations(1);

// Signed distances of 1,600 noisy cap points; counter "points_per_s".
void BM_SignedDistance(benchmark::State& state) {
  const ShapeModel model = static_cast<ShapeModel>(state.range(0));
  const ShapeParameters p = headShape(model);
  const Eigen::MatrixX3d& pts = headPoints();
  const articula::distance::SignedDistance field(p);
  Eigen::VectorXd d;
  Eigen::MatrixX3d feet;
  for (auto _ : state) {
    field.evaluate(pts, d, feet);
    benchmark::DoNotOptimize(d.data());
  }
  state.counters["points_per_s"] =
      benchmark::Counter(static_cast<double>(pts.rows()) * static_cast<double>(state.iterations()),
                         benchmark::Counter::kIsRate);
  state.SetLabel(articula::geometry::modelName(model));
}
BENCHMARK(BM_SignedDistance)->DenseRange(0, 4)->Unit(benchmark::kMicrosecond);

// Exact signed distances (global search) of 1,600 points by where they lie:
// 0 on the surface (noise-free cap points), 1 scattered within 1 mm of the
// centre (the deepest, where every direction is nearly as close). Arguments:
// model, place; the interior/surface time ratio is the target (<= 3).
void BM_SignedDistanceByPlace(benchmark::State& state) {
  const ShapeModel model = static_cast<ShapeModel>(state.range(0));
  const bool interior = state.range(1) == 1;
  const ShapeParameters p = headShape(model);
  Eigen::MatrixX3d pts = articula::fit::syntheticCap(p, 100.0 * M_PI / 180.0, 1600, 0.0, 5);
  if (interior) {
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    for (Eigen::Index i = 0; i < pts.rows(); ++i) {
      Vector3d v;
      do v = Vector3d(unit(rng), unit(rng), unit(rng)); while (v.squaredNorm() > 1.0);
      pts.row(i) = (p.center + v).transpose();
    }
  }
  const articula::distance::SignedDistance field(p);
  Eigen::VectorXd d;
  Eigen::MatrixX3d feet;
  field.evaluate(pts, d, feet);  // builds the seeds outside the timing
  for (auto _ : state) {
    field.evaluate(pts, d, feet);
    benchmark::DoNotOptimize(d.data());
  }
  state.SetLabel(articula::geometry::modelName(model) + (interior ? " interior" : " surface"));
}
BENCHMARK(BM_SignedDistanceByPlace)->ArgsProduct({{2, 3, 4}, {0, 1}})->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
