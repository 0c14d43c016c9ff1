// bireg's benchmark suite (Google Benchmark; run all with bench/run_all.sh).
//
//   B1  BM_Cost/<group>/<order>     one paper-solver fit at a fixed iteration
//                                   count, per observation and iteration, for
//                                   series order M (0 = adaptive, -1 = exact);
//                                   compare with BM_ExpLogTwoCompositions in
//                                   bench_groups
//   B3  BM_Solver/<solver>/<length> SE(3), N = 100, noise 0.1, geodesic length
//                                   0.3, 1, 2.5 rad (x10 in the argument), to
//                                   tolerance 1e-10: time and iterations
//   B4  BM_Scaling/<N>              SE(3), default options, N = 1e2 .. 1e6:
//                                   time per observation and iteration
//
// Counters: `iterations` per fit; `time_per_obs_iter` = fit time / (N x
// iterations), in seconds (printed with an SI prefix: 308n = 308 ns).
#include <algorithm>
#include <random>
#include <vector>

#include <benchmark/benchmark.h>

#include "bireg/groups/se2.hpp"
#include "bireg/groups/se3.hpp"
#include "bireg/groups/so3.hpp"
#include "bireg/regression.hpp"

namespace {

template <class G>
struct Problem {
  std::vector<typename G::Element> f;
  std::vector<double> t;
};

// N observations along a geodesic whose rotation part has length `length`
// rad (translation part of comparable size), noise entries uniform in
// [-noise, noise].
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
  problem.f.reserve(static_cast<std::size_t>(n));
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
void run_fits(benchmark::State& state, const Problem<G>& problem,
              const typename bireg::GeodesicRegression<G>::Options& options) {
  const bireg::GeodesicRegression<G> regression(options);
  int iterations = 0;
  for (auto _ : state) {
    const auto result = regression.fit(problem.f, problem.t);
    iterations = result.iterations;
    benchmark::DoNotOptimize(result.geodesic);
  }
  state.counters["iterations"] = iterations;
  state.counters["time_per_obs_iter"] = benchmark::Counter(
      static_cast<double>(problem.f.size()) * iterations,
      benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

// B1: 20 paper iterations (tolerance 0) on N = 1000, so that the per-fit
// set-up is amortised and the figure is the loop's cost.
template <class G>
void BM_Cost(benchmark::State& state) {
  static const Problem<G> problem = make_problem<G>(1000, 1.0, 0.1, 3);
  typename bireg::GeodesicRegression<G>::Options options;
  options.solver = bireg::Solver::paper;
  const int order = static_cast<int>(state.range(0));
  options.method = order < 0    ? bireg::Method::exact
                   : order == 0 ? bireg::Method::series_adaptive
                                : bireg::Method::series;
  options.series_order = std::max(order, 0);
  state.SetLabel(bireg::to_string(options.method));
  options.tolerance = 0;
  options.max_iterations = 20;
  run_fits(state, problem, options);
}
BENCHMARK_TEMPLATE(BM_Cost, bireg::SO3<double>)
    ->DenseRange(0, 0)
    ->Arg(2)
    ->Arg(4)
    ->Arg(8)
    ->Arg(16)
    ->Arg(32)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_TEMPLATE(BM_Cost, bireg::SE2<double>)
    ->DenseRange(0, 0)
    ->Arg(2)
    ->Arg(4)
    ->Arg(8)
    ->Arg(16)
    ->Arg(32)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_TEMPLATE(BM_Cost, bireg::SE3<double>)
    ->DenseRange(0, 0)
    ->Arg(2)
    ->Arg(4)
    ->Arg(8)
    ->Arg(16)
    ->Arg(32)
    ->Unit(benchmark::kMillisecond);

// B3: each solver to tolerance 1e-10. Arguments: solver index, length x 10.
void BM_Solver(benchmark::State& state) {
  using G = bireg::SE3<double>;
  const auto solver = static_cast<bireg::Solver>(state.range(0));
  const Problem<G> problem = make_problem<G>(100, state.range(1) / 10.0, 0.1, 11);
  bireg::GeodesicRegression<G>::Options options;
  options.solver = solver;
  options.tolerance = 1e-10;
  state.SetLabel(bireg::to_string(solver));
  run_fits(state, problem, options);
}
BENCHMARK(BM_Solver)->ArgsProduct({{0, 1, 2, 3}, {3, 10, 25}})->Unit(benchmark::kMicrosecond);

// B4: scaling in N at the default options.
void BM_Scaling(benchmark::State& state) {
  using G = bireg::SE3<double>;
  const Problem<G> problem = make_problem<G>(static_cast<int>(state.range(0)), 1.0, 0.1, 5);
  run_fits(state, problem, bireg::GeodesicRegression<G>::Options());
}
BENCHMARK(BM_Scaling)->RangeMultiplier(10)->Range(100, 1000000)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
