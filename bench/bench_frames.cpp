// bench-frames: thesis tables 4.3 and 4.4 redone. The five tangent-frame
// methods over 10^6 random unit normals, in cache (a 1024-normal block that
// stays in L1/L2) and streaming (all 10^6, 24 MB in and 48 MB out per pass).
// Counters with "err" in their names are the worst orthonormality errors
// over all 10^6 normals.
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <benchmark/benchmark.h>

#include "articula/geometry/frames.hpp"

namespace {

using articula::geometry::TangentFrame;
using Eigen::Vector3d;

const std::vector<Vector3d>& normals() {
  static const std::vector<Vector3d> data = [] {
    std::mt19937_64 rng(20261122);
    std::normal_distribution<double> gauss;
    std::vector<Vector3d> v(1000000);
    for (auto& n : v) {
      do n = Vector3d(gauss(rng), gauss(rng), gauss(rng));
      while (n.norm() < 1e-3);
      n.normalize();
    }
    return v;
  }();
  return data;
}

struct WorstErrors {
  double nt = 0, nb = 0, tb = 0, t_norm = 0, b_norm = 0, handed = 0;
};

template <TangentFrame (*Method)(const Vector3d&)>
WorstErrors worstErrors() {
  WorstErrors w;
  for (const Vector3d& n : normals()) {
    const TangentFrame f = Method(n);
    w.nt = std::max(w.nt, std::fabs(n.dot(f.t)));
    w.nb = std::max(w.nb, std::fabs(n.dot(f.b)));
    w.tb = std::max(w.tb, std::fabs(f.t.dot(f.b)));
    w.t_norm = std::max(w.t_norm, std::fabs(f.t.norm() - 1.0));
    w.b_norm = std::max(w.b_norm, std::fabs(f.b.norm() - 1.0));
    w.handed = std::max(w.handed, (f.t.cross(f.b) - n).norm());
  }
  return w;
}

template <TangentFrame (*Method)(const Vector3d&)>
void runFrames(benchmark::State& state) {
  const auto& all = normals();
  const size_t count = static_cast<size_t>(state.range(0));
  std::vector<TangentFrame> out(count);
  for (auto _ : state) {
    for (size_t i = 0; i < count; ++i) out[i] = Method(all[i]);
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * count));
  static const WorstErrors w = worstErrors<Method>();
  state.counters["err_nt"] = w.nt;
  state.counters["err_nb"] = w.nb;
  state.counters["err_tb"] = w.tb;
  state.counters["err_t_norm"] = w.t_norm;
  state.counters["err_b_norm"] = w.b_norm;
  state.counters["err_right_handed"] = w.handed;
  state.counters["ns_per_frame"] = benchmark::Counter(
      static_cast<double>(state.iterations() * count) * 1e-9, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

namespace g = articula::geometry;
constexpr int64_t kInCache = 1024;
constexpr int64_t kStreaming = 1000000;

#define ARTICULA_FRAME_BENCH(NAME, FN)                                                  \
  void BM_##NAME##_InCache(benchmark::State& s) { runFrames<FN>(s); }                    \
  void BM_##NAME##_Streaming(benchmark::State& s) { runFrames<FN>(s); }                  \
  BENCHMARK(BM_##NAME##_InCache)->Arg(kInCache)->Unit(benchmark::kNanosecond);           \
  BENCHMARK(BM_##NAME##_Streaming)->Arg(kStreaming)->Unit(benchmark::kMillisecond);

ARTICULA_FRAME_BENCH(Householder, g::householderFrameUnit)
ARTICULA_FRAME_BENCH(Duff, g::duffFrameUnit)
ARTICULA_FRAME_BENCH(Eberly, g::eberlyFrameUnit)
ARTICULA_FRAME_BENCH(SquarePlate, g::squarePlateFrameUnit)
ARTICULA_FRAME_BENCH(ProjectionMatrix, g::projectionMatrixFrameUnit)

}  // namespace

BENCHMARK_MAIN();
