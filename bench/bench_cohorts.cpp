// bireg's cohort benchmark: BM_TwoSample/<statistic>/<threads>, the
// bi-invariant two-sample test (statistics/cohorts/two_sample.hpp) of two
// SE(3) samples of 58 elements each (the size of the knee study the issue
// "Cohorts" cites), 9,999 relabellings, both means recomputed for each (the
// exact mode); statistic 0 Hotelling, 1 Bhattacharyya. Wall time
// (UseRealTime): the speed-up is the ratio of the /1 and /2 rows within one
// run.
#include <random>
#include <vector>

#include <benchmark/benchmark.h>

#include "bireg/groups/se3.hpp"
#include "bireg/statistics/cohorts/two_sample.hpp"
#include "bireg/testing/random.hpp"

namespace {

using G = bireg::SE3<double>;

std::vector<G::Element> sample(std::mt19937& rng, const G::Element& centre, int n) {
  std::normal_distribution<double> normal(0.0, 0.2);
  std::vector<G::Element> out;
  for (int i = 0; i < n; ++i)
    out.push_back(G::compose(centre, G::exp(bireg::testing::draw_vector<G::Tangent>(rng, normal))));
  return out;
}

void BM_TwoSample(benchmark::State& state) {
  std::mt19937 rng(58);
  const auto a = sample(rng, G::identity(), 58);
  const auto b = sample(rng, G::exp(G::Tangent(0.05, 0, 0, 0.02, 0, 0)), 58);
  bireg::TwoSampleOptions<double> options;
  options.statistic = static_cast<bireg::TwoSampleStatistic>(state.range(0));
  options.permutations = 9999;
  options.threads = static_cast<int>(state.range(1));
  for (auto _ : state) {
    const auto result = bireg::two_sample_test<G>(a, b, options);
    if (!result.ok()) state.SkipWithError(result.message.c_str());
    benchmark::DoNotOptimize(result.p_value);
  }
}
BENCHMARK(BM_TwoSample)
    ->ArgsProduct({{0, 1}, {1, 2}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
