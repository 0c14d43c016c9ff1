// bireg's cohort benchmark: BM_TwoSample/<statistic>/<threads>, the
// bi-invariant two-sample test (statistics/cohorts/two_sample.hpp) of two
// SE(3) samples of 58 elements each (the size of the knee study the issue
// "Cohorts" cites), 9,999 relabellings, both means recomputed for each (the
// exact mode); statistic 0 Hotelling, 1 Bhattacharyya. Wall time
// (UseRealTime): the speed-up is the ratio of the /1 and /2 rows within one
// run.
// BM_Elementwise/<mode>/<K>: element-wise maps
// (statistics/cohorts/elementwise.hpp) of GL+(3) deformation gradients, 20
// + 20 subjects of K elements (noise 0.1 per coordinate), 999 relabellings,
// Hotelling, one thread; mode 0 exact, 1 linearised.
// BM_FitMany/<threads>: fit_many (statistics/cohorts/trends.hpp) of 10,000
// subjects of 20 SE(3) poses each; BM_FitOneByOne: the same fits by
// GeodesicRegression::fit in a loop, the cost fit_many adds to.
#include <random>
#include <vector>

#include <benchmark/benchmark.h>

#include "bireg/groups/matrix_group.hpp"
#include "bireg/groups/se3.hpp"
#include "bireg/statistics/cohorts/elementwise.hpp"
#include "bireg/statistics/cohorts/trends.hpp"
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

using GL3 = bireg::GLp<3, double>;

std::vector<GL3::Element> subjects(std::mt19937& rng, int count, int elements) {
  std::normal_distribution<double> normal(0.0, 0.1);
  std::vector<GL3::Element> out;
  for (int i = 0; i < count; ++i) {
    for (int k = 0; k < elements; ++k)
      out.push_back(GL3::exp(bireg::testing::draw_vector<GL3::Tangent>(rng, normal)));
  }
  return out;
}

void BM_Elementwise(benchmark::State& state) {
  const int elements = static_cast<int>(state.range(1));
  std::mt19937 rng(2000);
  const auto a = subjects(rng, 20, elements);
  const auto b = subjects(rng, 20, elements);
  bireg::ElementwiseOptions<double> options;
  options.mode = static_cast<bireg::ElementwiseMode>(state.range(0));
  options.test.permutations = 999;
  for (auto _ : state) {
    const auto result = bireg::elementwise_two_sample_test<GL3>(
        a, 20, b, 20, static_cast<std::size_t>(elements), options);
    if (!result.ok()) state.SkipWithError(result.message.c_str());
    benchmark::DoNotOptimize(result.p_value.data());
  }
}
BENCHMARK(BM_Elementwise)
    ->Args({1, 2000})
    ->Args({0, 20})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

std::vector<bireg::SubjectData<G>> study() {
  std::mt19937 rng(10000);
  std::normal_distribution<double> spread(0.0, 0.3), noise(0.0, 0.05);
  std::vector<bireg::SubjectData<G>> subjects(10000);
  for (auto& subject : subjects) {
    const G::Element start = G::exp(bireg::testing::draw_vector<G::Tangent>(rng, spread));
    const G::Element end =
        G::compose(start, G::exp(G::Tangent(0.5, 0, 0, 1.0, 0, 0) +
                                 bireg::testing::draw_vector<G::Tangent>(rng, spread)));
    const bireg::Geodesic<G> truth(start, end);
    for (int k = 0; k < 20; ++k) {
      const double t = k / 19.0;
      subject.observations.push_back(
          G::compose(truth(t), G::exp(bireg::testing::draw_vector<G::Tangent>(rng, noise))));
      subject.covariates.push_back(t);
    }
  }
  return subjects;
}

void BM_FitMany(benchmark::State& state) {
  const auto subjects = study();
  bireg::FitManyOptions<double> options;
  options.threads = static_cast<int>(state.range(0));
  for (auto _ : state) {
    const auto fits = bireg::fit_many(bireg::GeodesicRegression<G>(), subjects, options);
    if (!fits.ok()) state.SkipWithError(fits.message.c_str());
    benchmark::DoNotOptimize(fits.trends.data());
  }
}
BENCHMARK(BM_FitMany)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_FitOneByOne(benchmark::State& state) {
  const auto subjects = study();
  const bireg::GeodesicRegression<G> regression;
  for (auto _ : state) {
    for (const auto& subject : subjects) {
      const auto fit = regression.fit(subject.observations, subject.covariates);
      benchmark::DoNotOptimize(fit.iterations);
    }
  }
}
BENCHMARK(BM_FitOneByOne)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
