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
//   B2  BM_Tradeoff/<group>/<length>/<method>/<tolerance>
//                                   SO(3), SE(3), lengths 0.5, 1.5, 3.0 rad,
//                                   noise 0.05, N = 100: fit time and
//                                   `endpoint_error` against a long double
//                                   reference fit (exact, tolerance 1e-15)
//   B5  BM_Precision/<scalar>       SE(3), N = 1000, length 1.5, noise 0.05:
//                                   float against double, time and
//                                   `endpoint_error` against the same reference
//   B6  BM_Scene<group>             every group, N = 1000, length 1, noise
//                                   0.1, default method, 20 paper iterations:
//                                   the per-observation-iteration cost of the
//                                   scene groups next to SE(3)'s
//
// Counters: `iterations` per fit; `time_per_obs_iter` = fit time / (N x
// iterations), in seconds (printed with an SI prefix: 308n = 308 ns).
#include <algorithm>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include <benchmark/benchmark.h>

#include "bireg/groups/matrix_group.hpp"
#include "bireg/groups/product.hpp"
#include "bireg/groups/rn.hpp"
#include "bireg/groups/se2.hpp"
#include "bireg/groups/se3.hpp"
#include "bireg/groups/sim3.hpp"
#include "bireg/groups/so3.hpp"
#include "bireg/regression.hpp"
#include "geodesic_problem.hpp"

namespace {

using bench::make_problem;
using bench::Problem;

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
// Orders of B1: -1 = exact, 0 = adaptive, then fixed M.
void cost_orders(benchmark::internal::Benchmark* benchmark) {
  for (int order : {-1, 0, 2, 4, 8, 16, 32})
    benchmark->Arg(order);
  benchmark->Unit(benchmark::kMillisecond);
}
BENCHMARK_TEMPLATE(BM_Cost, bireg::SO3<double>)->Apply(cost_orders);
BENCHMARK_TEMPLATE(BM_Cost, bireg::SE2<double>)->Apply(cost_orders);
BENCHMARK_TEMPLATE(BM_Cost, bireg::SE3<double>)->Apply(cost_orders);

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

// The long double reference fit of a problem (exact method, tolerance 1e-15).
template <class G, class GL>
std::pair<typename GL::Element, typename GL::Element> reference_fit(const Problem<G>& problem) {
  std::vector<typename GL::Element> f;
  std::vector<long double> t;
  for (std::size_t i = 0; i < problem.f.size(); ++i) {
    f.push_back(problem.f[i].template cast<long double>());
    t.push_back(problem.t[i]);
  }
  typename bireg::GeodesicRegression<GL>::Options options;
  options.tolerance = 1e-15L;
  const auto result = bireg::GeodesicRegression<GL>(options).fit(f, t);
  return {result.geodesic->start(), result.geodesic->end()};
}

template <class Element, class Reference>
double endpoint_error(const Element& g0, const Element& g1, const Reference& reference) {
  const double e0 = static_cast<double>(
      (g0.template cast<long double>() - reference.first).cwiseAbs().maxCoeff());
  const double e1 = static_cast<double>(
      (g1.template cast<long double>() - reference.second).cwiseAbs().maxCoeff());
  return std::max(e0, e1);
}

// B2: one (group, length, method, tolerance) cell of the trade table.
template <class G, class GL>
void register_tradeoff(const char* group, double length, bireg::Method method, int order,
                       double tolerance) {
  char name[128];
  const std::string method_name =
      method == bireg::Method::series ? "series" + std::to_string(order) : bireg::to_string(method);
  std::snprintf(name, sizeof name, "BM_Tradeoff/%s/len%.1f/%s/tol%.0e", group, length,
                method_name.c_str(), tolerance);
  benchmark::RegisterBenchmark(name, [=](benchmark::State& state) {
    const Problem<G> problem = make_problem<G>(100, length, 0.05, 13);
    const auto reference = reference_fit<G, GL>(problem);
    typename bireg::GeodesicRegression<G>::Options options;
    options.method = method;
    options.series_order = order;
    options.tolerance = tolerance;
    options.max_iterations = 200;
    const bireg::GeodesicRegression<G> regression(options);
    double error = 0;
    int iterations = 0;
    for (auto _ : state) {
      const auto result = regression.fit(problem.f, problem.t);
      benchmark::DoNotOptimize(result.geodesic);
      error = endpoint_error(result.geodesic->start(), result.geodesic->end(), reference);
      iterations = result.iterations;
    }
    state.counters["endpoint_error"] = error;
    state.counters["iterations"] = iterations;
  })->Unit(benchmark::kMicrosecond);
}

// B5: float against double on the same data.
template <class S>
void BM_Precision(benchmark::State& state) {
  using G = bireg::SE3<S>;
  const Problem<bireg::SE3<double>> data = make_problem<bireg::SE3<double>>(1000, 1.5, 0.05, 17);
  const auto reference = reference_fit<bireg::SE3<double>, bireg::SE3<long double>>(data);
  std::vector<typename G::Element> f;
  std::vector<S> t;
  for (std::size_t i = 0; i < data.f.size(); ++i) {
    f.push_back(data.f[i].template cast<S>());
    t.push_back(static_cast<S>(data.t[i]));
  }
  const bireg::GeodesicRegression<G> regression;
  double error = 0;
  int iterations = 0;
  for (auto _ : state) {
    const auto result = regression.fit(f, t);
    benchmark::DoNotOptimize(result.geodesic);
    error = endpoint_error(result.geodesic->start(), result.geodesic->end(), reference);
    iterations = result.iterations;
  }
  state.counters["endpoint_error"] = error;
  state.counters["iterations"] = iterations;
}
BENCHMARK_TEMPLATE(BM_Precision, float)->Unit(benchmark::kMicrosecond);
BENCHMARK_TEMPLATE(BM_Precision, double)->Unit(benchmark::kMicrosecond);

// B6: the loop's cost on every scene group at the default method (closed
// form where the group has one, the adaptive series elsewhere), as B1.
template <class G>
void BM_Scene(benchmark::State& state) {
  static const Problem<G> problem = make_problem<G>(1000, 1.0, 0.1, 5);
  typename bireg::GeodesicRegression<G>::Options options;
  options.solver = bireg::Solver::paper;
  options.tolerance = 0;
  options.max_iterations = 20;
  state.SetLabel(G::name);
  run_fits(state, problem, options);
}
BENCHMARK_TEMPLATE(BM_Scene, bireg::SE3<double>)->Unit(benchmark::kMillisecond);
BENCHMARK_TEMPLATE(BM_Scene, bireg::Sim3<double>)->Unit(benchmark::kMillisecond);
BENCHMARK_TEMPLATE(BM_Scene, bireg::Product<bireg::SO3<double>, bireg::Rn<3, double>>)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_TEMPLATE(BM_Scene, bireg::Heisenberg<double>)->Unit(benchmark::kMillisecond);
BENCHMARK_TEMPLATE(BM_Scene, bireg::SL3<double>)->Unit(benchmark::kMillisecond);
BENCHMARK_TEMPLATE(BM_Scene, bireg::GLp<3, double>)->Unit(benchmark::kMillisecond);

}  // namespace

int main(int argc, char** argv) {
  for (double length : {0.5, 1.5, 3.0}) {
    for (double tolerance : {1e-4, 1e-8, 1e-12}) {
      for (int order : {2, 4, 8, 16}) {
        register_tradeoff<bireg::SO3<double>, bireg::SO3<long double>>(
            "SO3", length, bireg::Method::series, order, tolerance);
        register_tradeoff<bireg::SE3<double>, bireg::SE3<long double>>(
            "SE3", length, bireg::Method::series, order, tolerance);
      }
      for (bireg::Method method : {bireg::Method::series_adaptive, bireg::Method::exact}) {
        register_tradeoff<bireg::SO3<double>, bireg::SO3<long double>>("SO3", length, method, 0,
                                                                       tolerance);
        register_tradeoff<bireg::SE3<double>, bireg::SE3<long double>>("SE3", length, method, 0,
                                                                       tolerance);
      }
    }
  }
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
