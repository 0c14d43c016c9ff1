// Cost of a whole fit and of one observation-iteration, SE(3) and SO(3),
// default options (adaptive series order, paper step 1/mu_max).
//
//   ./build/bench/bench_regression --benchmark_format=json
//
// Counters: `iterations` per fit, and `time_per_obs_iter`, the fit time
// divided by N x iterations, in seconds (printed with an SI prefix, e.g.
// 308n = 308 ns): the figure the solver's cost model is stated in.
#include <random>
#include <vector>

#include <benchmark/benchmark.h>

#include "bireg/groups/se3.hpp"
#include "bireg/groups/so3.hpp"
#include "bireg/regression.hpp"

namespace {

template <class G>
struct Problem {
  std::vector<typename G::Element> f;
  std::vector<double> t;
};

// N observations along a geodesic of length `length` rad, noise `noise`
// (uniform per tangent coordinate) — the SE(3) benchmark case.
template <class G>
Problem<G> make_problem(int n, double length, double noise, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uniform(-1, 1);
  typename G::Tangent start, x;
  for (int k = 0; k < G::dof; ++k) {
    start[k] = uniform(rng);
    x[k] = uniform(rng);
  }
  x *= length / x.norm();
  const typename G::Element g0 = G::exp(start);
  Problem<G> problem;
  for (int i = 0; i < n; ++i) {
    const double s = static_cast<double>(i) / (n - 1);
    typename G::Tangent e;
    for (int k = 0; k < G::dof; ++k)
      e[k] = noise * uniform(rng);
    problem.f.push_back(G::compose(G::compose(g0, G::exp(s * x)), G::exp(e)));
    problem.t.push_back(s);
  }
  return problem;
}

template <class G>
void BM_Fit(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const Problem<G> problem = make_problem<G>(n, 1.0, 0.1, 7);
  const bireg::GeodesicRegression<G> regression;
  int iterations = 0;
  for (auto _ : state) {
    const auto result = regression.fit(problem.f, problem.t);
    iterations = result.iterations;
    benchmark::DoNotOptimize(result.geodesic);
  }
  state.counters["iterations"] = iterations;
  state.counters["time_per_obs_iter"] = benchmark::Counter(
      static_cast<double>(n) * iterations,
      benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

BENCHMARK_TEMPLATE(BM_Fit, bireg::SE3<double>)->Arg(100)->Arg(1000)->Unit(benchmark::kMicrosecond);
BENCHMARK_TEMPLATE(BM_Fit, bireg::SO3<double>)->Arg(100)->Arg(1000)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
