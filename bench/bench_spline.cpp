// Benchmarks of the spline regression (issue 32's performance targets):
//   * SO(3), N = 1e5 samples, a knot every 10 samples, a cubic spline fit on
//     one thread (target: at most 1 s) and on two (target: at least 1.8x
//     faster; wall time);
//   * its cost per observation and Gauss-Newton iteration against the
//     geodesic fit's on the same observations (target: at most 3x).
// The data are bench_local_regression's: exp(0.5 (sin w t, cos w t - 1,
// sin 2 w t)) with w = 2 pi / 10 s sampled at 1 kHz, noise 0.01 rad per
// axis, seed 7.
#include <cmath>
#include <random>
#include <vector>

#include <benchmark/benchmark.h>

#include "bireg/groups/so3.hpp"
#include "bireg/regression.hpp"
#include "bireg/spline_regression.hpp"
#include "smooth_curve.hpp"

namespace {

using G = bireg::SO3d;

using Data = bench::SmoothCurve;
using bench::kSpacing;

Data curve(int n) {
  return bench::smooth_curve(n);
}

// Counters shared by both fits: Gauss-Newton steps proposed (the last
// certifies), and the time per observation and step.
void count(benchmark::State& state, double n, int iterations) {
  state.counters["iterations"] = iterations;
  state.counters["per_observation_iteration"] = benchmark::Counter(
      n * iterations, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

// Args: N, threads.
void BM_CubicSplineFit(benchmark::State& state) {
  const Data data = curve(static_cast<int>(state.range(0)));
  bireg::SplineOptions<double> options;
  options.degree = 3;
  options.threads = static_cast<int>(state.range(1));
  options.knot_spacing = 10 * kSpacing;
  const bireg::SplineRegression<G> regression(options);
  int iterations = 0, assemblies = 0;
  for (auto _ : state) {
    const auto fit = regression.fit(data.f, data.t);
    if (!fit.ok()) state.SkipWithError(fit.message.c_str());
    iterations = fit.iterations;
    assemblies = fit.jacobian_evaluations;
    benchmark::DoNotOptimize(fit.spline);
  }
  count(state, static_cast<double>(data.t.size()), iterations);
  state.counters["jacobian_evaluations"] = assemblies;  // of K, per fit
}
BENCHMARK(BM_CubicSplineFit)
    ->Args({10000, 1})
    ->Args({100000, 1})
    ->Args({100000, 2})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// The geodesic on the same observations (the whole curve, one geodesic:
// large residuals, the same per-observation work).
void BM_GeodesicFit(benchmark::State& state) {
  const Data data = curve(static_cast<int>(state.range(0)));
  const bireg::GeodesicRegression<G> regression;
  int iterations = 0;
  for (auto _ : state) {
    const auto fit = regression.fit(data.f, data.t);
    if (!fit.ok()) state.SkipWithError(fit.message.c_str());
    iterations = fit.iterations;
    benchmark::DoNotOptimize(fit.geodesic);
  }
  count(state, static_cast<double>(data.t.size()), iterations);
}
BENCHMARK(BM_GeodesicFit)->Arg(10000)->Arg(100000)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
