// Benchmarks of the local regression (the trajectory issue's targets):
//   * SO(3), N = 1e5 samples, a Gaussian kernel whose support holds about
//     20 samples, every observation queried, single thread (target: at most
//     1 s, at most 2 Gauss-Newton iterations per query on average);
//   * against the naive method (a cold global fit with Gaussian kernel
//     weights over all N observations per query, as the authors' package
//     does) at N = 1e4 (target: at least 100x faster per query). The naive
//     method is timed on 50 queries spread over the range and reported per
//     query; ours on all N queries, also per query.
// The data: a smooth SO(3) curve exp(0.5 (sin w t, cos w t - 1, sin 2 w t))
// with w = 2 pi / 10 s sampled at 1 kHz, noise 0.01 rad per axis, seed 7.
#include <cmath>
#include <random>
#include <vector>

#include <benchmark/benchmark.h>

#include "bireg/groups/so3.hpp"
#include "bireg/regression.hpp"
#include "bireg/statistics/smoothing/local_regression.hpp"
#include "smooth_curve.hpp"

namespace {

using G = bireg::SO3d;

using Data = bench::SmoothCurve;
using bench::kSpacing;
// Gaussian support 4 h each side: 8 h = 20 spacings.
constexpr double kBandwidth = 2.5 * bench::kSpacing;

Data curve(int n) {
  return bench::smooth_curve(n);
}

bireg::LocalRegressionOptions<double> options() {
  bireg::LocalRegressionOptions<double> o;
  o.kernel = bireg::Kernel::gaussian;
  o.bandwidth = kBandwidth;
  o.standard_errors = false;
  return o;
}

void BM_LocalSmoothAll(benchmark::State& state) {
  const Data data = curve(static_cast<int>(state.range(0)));
  const bireg::LocalGeodesicRegression<G> smoother(options());
  double iterations = 0, window = 0;
  int failed = 0;
  for (auto _ : state) {
    const auto estimates = smoother.smooth(data.f, data.t);
    benchmark::DoNotOptimize(estimates.data());
    iterations = window = 0;
    failed = 0;
    for (const auto& e : estimates) {
      iterations += e.iterations;
      window += static_cast<double>(e.window);
      failed += e.ok() ? 0 : 1;
    }
  }
  const double n = static_cast<double>(data.t.size());
  // Step evaluations: the Gauss-Newton steps taken plus the one that
  // certifies convergence (regression/iteration.hpp).
  state.counters["iterations_per_query"] = iterations / n;
  state.counters["window"] = window / n;
  state.counters["failed"] = failed;
  // Seconds per query (shown with its unit prefix).
  state.counters["per_query"] = benchmark::Counter(
      n, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_LocalSmoothAll)->Arg(10000)->Arg(100000)->Unit(benchmark::kMillisecond);

// The naive method: per query, Gaussian weights over all N and a cold fit.
void BM_NaivePerQuery(benchmark::State& state) {
  const Data data = curve(static_cast<int>(state.range(0)));
  const bireg::GeodesicRegression<G> regression;
  const int queries = 50;
  std::vector<double> weights(data.t.size());
  double iterations = 0;
  for (auto _ : state) {
    iterations = 0;
    for (int q = 0; q < queries; ++q) {
      const double tau = data.t[data.t.size() * static_cast<std::size_t>(q) / queries];
      for (std::size_t i = 0; i < weights.size(); ++i) {
        const double u = (data.t[i] - tau) / kBandwidth;
        weights[i] = std::exp(-u * u / 2);
      }
      const auto fit = regression.fit(data.f, data.t, weights);
      benchmark::DoNotOptimize(fit.geodesic);
      iterations += fit.iterations;
    }
  }
  state.counters["iterations_per_query"] = iterations / queries;
  state.counters["per_query"] = benchmark::Counter(
      queries, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_NaivePerQuery)->Arg(10000)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
