// Cost of the group primitives: one exp, one log and two compositions, the
// floor every inverse-differential method pays per observation and
// iteration.
#include <random>
#include <vector>

#include <benchmark/benchmark.h>

#include "bireg/groups/se2.hpp"
#include "bireg/groups/se3.hpp"
#include "bireg/groups/so2.hpp"
#include "bireg/groups/so3.hpp"

namespace {

template <class G>
std::vector<typename G::Tangent> sample_tangents(int count) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  std::vector<typename G::Tangent> xs(count);
  for (auto& x : xs) {
    for (int i = 0; i < G::dof; ++i)
      x[i] = uniform(rng);
  }
  return xs;
}

// exp + log + 2 compositions on varying inputs (no constant folding).
template <class G>
void BM_ExpLogTwoCompositions(benchmark::State& state) {
  const auto xs = sample_tangents<G>(256);
  const typename G::Element a = G::exp(xs[0]);
  std::size_t i = 0;
  for (auto _ : state) {
    const typename G::Element b = G::compose(a, G::exp(xs[i % xs.size()]));
    const typename G::Tangent y = G::log(G::compose(b, a));
    benchmark::DoNotOptimize(y);
    ++i;
  }
}

BENCHMARK_TEMPLATE(BM_ExpLogTwoCompositions, bireg::SO2<double>);
BENCHMARK_TEMPLATE(BM_ExpLogTwoCompositions, bireg::SO3<double>);
BENCHMARK_TEMPLATE(BM_ExpLogTwoCompositions, bireg::SE2<double>);
BENCHMARK_TEMPLATE(BM_ExpLogTwoCompositions, bireg::SE3<double>);

}  // namespace

BENCHMARK_MAIN();
