// Benchmarks of the statistics layer (issue 13's targets):
//   * the covariance against one Gauss-Newton iteration, SE(3), N = 1e4
//     (target: at most 2x);
//   * the permutation test, B = 999, SE(3), N = 100, against 1000 warm
//     fits; a warm fit against a cold one (target: warm at most 60%);
//   * the bi-invariant mean by Newton against the fixed-point iteration,
//     SE(3) data of spread 1 rad (target: at least 3x fewer iterations).
#include <random>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "bireg/groups/se3.hpp"
#include "bireg/regression.hpp"
#include "bireg/statistics/inference/covariance.hpp"
#include "bireg/statistics/inference/mean.hpp"
#include "bireg/statistics/inference/permutation.hpp"
#include "bireg/statistics/inference/trend_test.hpp"

namespace {

using G = bireg::SE3d;
using Tangent = G::Tangent;

Tangent normal_tangent(std::mt19937& rng, double sd) {
  std::normal_distribution<double> normal(0.0, sd);
  Tangent x;
  for (int i = 0; i < 6; ++i)
    x[i] = normal(rng);
  return x;
}

struct Data {
  std::vector<G::Element> f;
  std::vector<double> t;
};

// N observations along a 1 rad SE(3) geodesic, noise 0.05, covariates 0..N-1.
Data line(int n, unsigned seed) {
  std::mt19937 rng(seed);
  Tangent x;
  x << 0.8, -0.3, 0.5, 0.6, 0.0, 0.8;  // rotation angle 1 rad
  const G::Element g0 = G::exp(normal_tangent(rng, 0.5));
  Data data;
  for (int i = 0; i < n; ++i) {
    const double s = double(i) / (n - 1);
    data.f.push_back(bireg::exp_at<G>(bireg::exp_at<G>(g0, s * x), normal_tangent(rng, 0.05)));
    data.t.push_back(i);
  }
  return data;
}

// One Gauss-Newton iteration at the solution: the pass over the data that
// evaluates the residuals and the force, and the step K^{-1} v.
void BM_GaussNewtonIteration(benchmark::State& state) {
  const Data data = line(static_cast<int>(state.range(0)), 1);
  const auto fit = bireg::GeodesicRegression<G>().fit(data.f, data.t);
  bireg::Problem<double> problem;
  bireg::make_problem(data.t, std::vector<double>{}, {}, problem);
  const bireg::GaussNewtonStep<G> rule(problem, 0);
  std::vector<Tangent> residuals(data.f.size());
  for (auto _ : state) {
    const auto evaluated =
        bireg::evaluate<G>(data.f, problem, bireg::PsiEvaluation{}, fit.geodesic->start(),
                           fit.geodesic->end(), residuals);
    benchmark::DoNotOptimize(rule(evaluated));
  }
}
BENCHMARK(BM_GaussNewtonIteration)->Arg(10000)->Unit(benchmark::kMillisecond);

void BM_Covariance(benchmark::State& state) {
  const Data data = line(static_cast<int>(state.range(0)), 1);
  const auto fit = bireg::GeodesicRegression<G>().fit(data.f, data.t);
  const auto flavour =
      state.range(1) ? bireg::CovarianceFlavour::robust : bireg::CovarianceFlavour::homoscedastic;
  for (auto _ : state)
    benchmark::DoNotOptimize(bireg::covariance(fit, data.t, {}, flavour).endpoints);
}
BENCHMARK(BM_Covariance)->Args({10000, 0})->Args({10000, 1})->Unit(benchmark::kMillisecond);

// Fits of permutation 0 of N = 100: cold (chart start), warm from the
// unpermuted fit's endpoints, warm from the mean (the H0 fit).
void BM_PermutedFit(benchmark::State& state) {
  const Data data = line(100, 2);
  const bireg::GeodesicRegression<G> regression;
  const auto fit = regression.fit(data.f, data.t);
  const auto m = bireg::mean<G>(data.f);
  std::vector<std::size_t> order;
  bireg::permutation(0, 0, data.t.size(), order);
  std::vector<double> permuted(data.t.size());
  for (std::size_t i = 0; i < order.size(); ++i)
    permuted[i] = data.t[order[i]];
  const std::pair<G::Element, G::Element> fitted(fit.geodesic->start(), fit.geodesic->end());
  const std::pair<G::Element, G::Element> at_mean(*m.mean, *m.mean);
  int iterations = 0;
  for (auto _ : state) {
    const auto refit = state.range(0) == 0   ? regression.fit(data.f, permuted)
                       : state.range(0) == 1 ? regression.fit_from(fitted, data.f, permuted)
                                             : regression.fit_from(at_mean, data.f, permuted);
    iterations = refit.iterations;
    benchmark::DoNotOptimize(refit.residuals.data());
  }
  state.counters["iterations"] = iterations;
  state.SetLabel(state.range(0) == 0   ? "cold"
                 : state.range(0) == 1 ? "warm: fitted"
                                       : "warm: mean");
}
BENCHMARK(BM_PermutedFit)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMicrosecond);

// The whole test, B = 999: per start, with each permuted fit stopped once
// its verdict is certain (the default) or run to convergence. The
// "per_permutation" counter divides the test's time by B (an upper bound:
// it includes the unpermuted fit and the mean), "decided" counts the fits
// that stopped early.
void BM_TrendTest(benchmark::State& state) {
  const Data data = line(100, 2);
  const bireg::GeodesicRegression<G> regression;
  bireg::TrendTestOptions options;
  options.permutations = 999;
  const bireg::PermutationStart starts[] = {bireg::PermutationStart::fitted,
                                            bireg::PermutationStart::mean,
                                            bireg::PermutationStart::chart};
  const char* names[] = {"start: fitted", "start: mean", "start: chart"};
  options.start = starts[state.range(0)];
  options.decide_early = state.range(1) != 0;
  int decided = 0;
  for (auto _ : state) {
    const auto test = bireg::trend_test(regression, data.f, data.t, {}, options);
    decided = test.decided_permutations;
    benchmark::DoNotOptimize(test.p_value);
  }
  state.counters["decided"] = decided;
  state.counters["per_permutation"] = benchmark::Counter(
      double(options.permutations),
      benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  state.SetLabel(std::string(names[state.range(0)]) +
                 (options.decide_early ? ", early verdicts" : ", converged"));
}
BENCHMARK(BM_TrendTest)->ArgsProduct({{0, 1, 2}, {1, 0}})->Unit(benchmark::kMillisecond);

// N = 1000 SE(3) elements about a centre, tangent noise with rotation rms
// 1 rad (sd 1/sqrt(3) per coordinate, translation likewise), both
// iterations to the same tolerance 1e-12.
void BM_Mean(benchmark::State& state) {
  std::mt19937 rng(3);
  const G::Element centre = G::exp(normal_tangent(rng, 1));
  std::vector<G::Element> f;
  for (int i = 0; i < 1000; ++i)
    f.push_back(bireg::exp_at<G>(centre, normal_tangent(rng, 1 / std::sqrt(3.0))));
  bireg::MeanOptions<double> options;
  options.tolerance = 1e-12;
  options.max_iterations = 10000;
  options.newton = state.range(0) == 1;
  int iterations = 0;
  for (auto _ : state) {
    const auto m = bireg::mean<G>(f, {}, options);
    iterations = m.iterations;
    benchmark::DoNotOptimize(m.mean);
  }
  state.counters["iterations"] = iterations;
  state.SetLabel(options.newton ? "newton" : "fixed point");
}
BENCHMARK(BM_Mean)->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
