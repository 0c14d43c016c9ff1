// bireg's thread benchmark: BM_Threads/<N>/<threads>, one SE(3) fit with
// default options (exact method, Gauss-Newton, tolerance 1e-10) of N
// observations along a geodesic with tangent of norm 1 with noise 0.1, on 1 or 2 threads.
// Wall time (UseRealTime): the speed-up is the ratio of the /1 and /2 rows
// of the same N within one run. Below kParallelMinimum observations (N =
// 100) the fit stays serial whatever the thread count.
#include <random>
#include <vector>

#include <benchmark/benchmark.h>

#include "bireg/groups/se3.hpp"
#include "bireg/regression.hpp"

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

}  // namespace

BENCHMARK_MAIN();
