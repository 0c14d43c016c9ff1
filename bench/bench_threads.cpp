// bireg's thread benchmark: BM_Threads/<N>/<threads>, one SE(3) fit with
// default options (exact method, Gauss-Newton, tolerance 1e-10) of N
// observations along a geodesic with tangent of norm 1 with noise 0.1, on 1 or 2 threads.
// Wall time (UseRealTime): the speed-up is the ratio of the /1 and /2 rows
// of the same N within one run. Below kParallelMinimum observations (N =
// 100) the fit stays serial whatever the thread count.
// BM_TrendTestThreads/<threads>: the permutation test, SE(3), N = 100
// (the same data), B = 999; BM_SmoothThreads/<threads>: the local
// regression of bench_local_regression.cpp (SO(3), 1e5 samples at 1 kHz,
// noise 0.01 rad, Gaussian h = 2.5 samples, no standard errors);
// BM_ModelSelectionThreads/<threads>: select_motion_model on 1000 poses of
// the SE(3) data, its candidates' and cross-validation folds' fits.
#include <random>
#include <vector>

#include <benchmark/benchmark.h>

#include <cmath>

#include "bireg/groups/se3.hpp"
#include "bireg/groups/so3.hpp"
#include "bireg/regression.hpp"
#include "bireg/statistics/inference/trend_test.hpp"
#include "bireg/statistics/selection/model_selection.hpp"
#include "bireg/statistics/smoothing/local_regression.hpp"
#include "bireg/testing/random.hpp"

namespace {

using G = bireg::SE3<double>;

struct Data {
  std::vector<G::Element> f;
  std::vector<double> t;
};

Data make_data(int n) {
  std::mt19937 rng(2026);
  std::uniform_real_distribution<double> uniform(-1, 1);
  G::Tangent x;
  for (int k = 0; k < G::dof; ++k)
    x[k] = uniform(rng);
  x *= 1.0 / x.norm();
  Data data;
  for (int i = 0; i < n; ++i) {
    G::Tangent noise;
    for (int k = 0; k < G::dof; ++k)
      noise[k] = 0.1 * uniform(rng);
    const double covariate = i / (n - 1.0);
    data.f.push_back(G::exp(covariate * x + noise));
    data.t.push_back(covariate);
  }
  return data;
}

void BM_Threads(benchmark::State& state) {
  const Data data = make_data(static_cast<int>(state.range(0)));
  bireg::GeodesicRegression<G>::Options options;
  options.threads = static_cast<int>(state.range(1));
  const bireg::GeodesicRegression<G> regression(options);
  int iterations = 0;
  for (auto _ : state) {
    const auto result = regression.fit(data.f, data.t);
    iterations = result.iterations;
    benchmark::DoNotOptimize(result.geodesic);
  }
  state.counters["iterations"] = iterations;
}
BENCHMARK(BM_Threads)
    ->ArgsProduct({{100, 10000, 100000}, {1, 2}})
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);

void BM_TrendTestThreads(benchmark::State& state) {
  const Data data = make_data(100);
  const bireg::GeodesicRegression<G> regression;
  bireg::TrendTestOptions options;
  options.permutations = 999;
  options.threads = static_cast<int>(state.range(0));
  for (auto _ : state)
    benchmark::DoNotOptimize(bireg::trend_test(regression, data.f, data.t, {}, options).p_value);
}
BENCHMARK(BM_TrendTestThreads)->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond);

void BM_SmoothThreads(benchmark::State& state) {
  using SO3 = bireg::SO3<double>;
  std::mt19937 rng(7);
  std::normal_distribution<double> normal(0.0, 0.01);
  const double w = 2 * M_PI / 10;
  std::vector<SO3::Element> f;
  std::vector<double> t;
  for (int i = 0; i < 100000; ++i) {
    const double ti = i * 1e-3;
    const SO3::Tangent curve =
        0.5 * SO3::Tangent(std::sin(w * ti), std::cos(w * ti) - 1, std::sin(2 * w * ti));
    f.push_back(SO3::compose(SO3::exp(curve),
                             SO3::exp(bireg::testing::draw_vector<SO3::Tangent>(rng, normal))));
    t.push_back(ti);
  }
  bireg::LocalRegressionOptions<double> options;
  options.bandwidth = 2.5e-3;
  options.standard_errors = false;
  options.threads = static_cast<int>(state.range(0));
  const bireg::LocalGeodesicRegression<SO3> smoother(options);
  for (auto _ : state)
    benchmark::DoNotOptimize(smoother.smooth(f, t).data());
}
BENCHMARK(BM_SmoothThreads)->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond);

// Motion-model selection of 1000 SE(3) poses (the same generator): five
// candidates and their 5-fold cross-validation, 30 fits in all.
void BM_ModelSelectionThreads(benchmark::State& state) {
  const Data data = make_data(1000);
  bireg::ModelSelectionOptions options;
  options.threads = static_cast<int>(state.range(0));
  for (auto _ : state)
    benchmark::DoNotOptimize(bireg::select_motion_model(data.f, data.t, options).recommended);
}
BENCHMARK(BM_ModelSelectionThreads)->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
