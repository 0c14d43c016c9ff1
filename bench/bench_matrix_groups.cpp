// Cost of exp and log on the matrix groups (Heisenberg by its polynomial
// closed forms; SL(3) and GL+(3) by bireg/math/matrix_functions.hpp), on
// tangents with entries uniform in [-0.5, 0.5], the range of the accuracy
// tests, and on the elements they exponentiate to. Varying inputs, so nothing
// is constant-folded.
//
//   ./build/bench/bench_matrix_groups --benchmark_repetitions=5
//       --benchmark_report_aggregates_only=true
#include <random>
#include <vector>

#include <benchmark/benchmark.h>

#include "bireg/groups/matrix_group.hpp"

namespace {

template <class G>
std::vector<typename G::Tangent> sample_tangents(int count) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> uniform(-0.5, 0.5);
  std::vector<typename G::Tangent> xs(count);
  for (auto& x : xs) {
    for (int i = 0; i < G::dof; ++i)
      x[i] = uniform(rng);
  }
  return xs;
}

template <class G>
void BM_Exp(benchmark::State& state) {
  const auto xs = sample_tangents<G>(256);
  std::size_t i = 0;
  for (auto _ : state) {
    const typename G::Element g = G::exp(xs[i % xs.size()]);
    benchmark::DoNotOptimize(g);
    ++i;
  }
}

template <class G>
void BM_Log(benchmark::State& state) {
  const auto xs = sample_tangents<G>(256);
  std::vector<typename G::Element> gs;
  for (const auto& x : xs)
    gs.push_back(G::exp(x));
  std::size_t i = 0;
  for (auto _ : state) {
    const typename G::Tangent y = G::log(gs[i % gs.size()]);
    benchmark::DoNotOptimize(y);
    ++i;
  }
}

BENCHMARK_TEMPLATE(BM_Exp, bireg::Heisenberg<double>);
BENCHMARK_TEMPLATE(BM_Log, bireg::Heisenberg<double>);
BENCHMARK_TEMPLATE(BM_Exp, bireg::SL3<double>);
BENCHMARK_TEMPLATE(BM_Log, bireg::SL3<double>);
BENCHMARK_TEMPLATE(BM_Exp, bireg::GLp<3, double>);
BENCHMARK_TEMPLATE(BM_Log, bireg::GLp<3, double>);

}  // namespace

BENCHMARK_MAIN();
