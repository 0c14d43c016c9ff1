// The batched SO(3) and SE(3) forces (regression/batched_force.hpp) against
// the scalar loop, in one binary per instruction set (bench/CMakeLists.txt builds this
// file with -march=haswell for AVX2 and -march=skylake-avx512 for AVX-512),
// so that the two are timed in the same run.
//
//   BM_Cost<G>/batched:B/n:N  bench_regression's B1 (20 paper iterations,
//       tolerance 0, a geodesic of length 1 whose rotation angle is in the
//       closed form's range, noise 0.1) with options.batched_kernels = B,
//       on N observations; time_per_obs_iter = fit time / (N x iterations).
//       The fit's once-per-fit passes (the membership check, the chart
//       start, the Gauss-Newton moments, the diagnostics) stay scalar and
//       are included.
//   BM_Trade<G>/source:S/float:F/batched:B  float against double: one fit
//       at the default options (Gauss-Newton to the default tolerance) of
//       S = 0, simulated IMU-like data (1,000 samples over 1 s turning at
//       2 rad/s, noise 0.01 rad and 1 cm), or S = 1, the shipped recording
//       (examples/data: the x-IMU window for SO(3), the DeepMimic walk for
//       SE(3)), in float (F = 1) or double; endpoint_error is the float
//       fit's largest endpoint distance |log(g_double^{-1} g_float)| from
//       the double fit (scalar loop), in the group's tangent norm.
//   BM_Million/threads:T/batched:B  one SE(3) fit at the default options
//       (Gauss-Newton, 4 iterations) of 1e6 poses in memory, on T threads.
//   BM_Force<G>/batched:B/n:N  one evaluation of the force alone (the
//       iteration's per-observation work: residuals and their sums) at the
//       fit's answer; time_per_obs = time / N.
//
// The label names the instruction set the kernel was compiled for.
#include <algorithm>
#include <cstdio>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "bireg/groups/se3.hpp"
#include "bireg/groups/so3.hpp"
#include "bireg/io/formats.hpp"
#include "bireg/regression.hpp"
#include "bireg/regression/batched_force.hpp"
#include "geodesic_problem.hpp"

namespace {

using bench::InDouble;
using bench::make_problem;
using bench::Problem;

// The label of a case: the instruction set the kernel was compiled for, or
// the scalar loop.
void label(benchmark::State& state, bool batched) {
#if BIREG_HAS_BATCHED_FORCE
  state.SetLabel(batched ? bireg::batched::target_name() : "scalar");
#else
  static_cast<void>(batched);
  state.SetLabel("scalar (no batched kernel in this build)");
#endif
}

template <class G>
void BM_Cost(benchmark::State& state) {
  const bool batched = state.range(0) != 0;
  const Problem<G> problem = make_problem<G>(static_cast<int>(state.range(1)), 1.0, 0.1, 3);
  typename bireg::GeodesicRegression<G>::Options options;
  options.solver = bireg::Solver::paper;
  options.tolerance = 0;
  options.max_iterations = 20;
  options.batched_kernels = batched;
  const bireg::GeodesicRegression<G> regression(options);
  int iterations = 0;
  for (auto _ : state) {
    const auto result = regression.fit(problem.f, problem.t);
    iterations = result.iterations;
    benchmark::DoNotOptimize(result.geodesic);
  }
  label(state, batched);
  state.counters["iterations"] = iterations;
  state.counters["time_per_obs_iter"] = benchmark::Counter(
      static_cast<double>(problem.f.size()) * iterations,
      benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
void cost_arguments(benchmark::internal::Benchmark* benchmark) {
  benchmark->ArgNames({"batched", "n"})
      ->ArgsProduct({{0, 1}, {1000, 100000}})
      ->Unit(benchmark::kMillisecond);
}
BENCHMARK_TEMPLATE(BM_Cost, bireg::SO3d)->Apply(cost_arguments);
BENCHMARK_TEMPLATE(BM_Cost, bireg::SE3d)->Apply(cost_arguments);
BENCHMARK_TEMPLATE(BM_Cost, bireg::SO3f)->Apply(cost_arguments);
BENCHMARK_TEMPLATE(BM_Cost, bireg::SE3f)->Apply(cost_arguments);

// The data of BM_Trade in double.
template <class D>
Problem<D> trade_data(int source) {
  Problem<D> problem;
  if (source == 1) {
    const bool rotations = D::dof == 3;
    const std::string path = std::string(BIREG_BENCH_DATA_DIR) +
                             (rotations ? "/so3_xio_imu_window.csv" : "/se3_deepmimic_walk.tum");
    std::ifstream in(path);
    bireg::io::Trajectory<D> trajectory;
    if (!in ||
        bireg::io::read_trajectory<D>(
            in, rotations ? bireg::io::Format::matrix : bireg::io::Format::tum, trajectory)) {
      std::fprintf(stderr, "bench_batched: cannot read %s\n", path.c_str());
      return problem;
    }
    problem.f = trajectory.observations;
    problem.t = trajectory.covariates;
    return problem;
  }
  std::mt19937 rng(17);
  std::normal_distribution<double> normal(0, 1);
  const typename D::Element g0 = D::exp(D::Tangent::Constant(0.4));
  typename D::Tangent velocity = D::Tangent::Constant(0.5);
  velocity.template tail<3>() = Eigen::Vector3d(1.2, -1.4, 0.8);  // 2 rad/s
  for (int i = 0; i < 1000; ++i) {
    const double s = i / 1000.0;
    typename D::Tangent e;
    for (int k = 0; k < D::dof; ++k)
      e[k] = 0.01 * normal(rng);
    problem.f.push_back(D::compose(D::compose(g0, D::exp(s * velocity)), D::exp(e)));
    problem.t.push_back(s);
  }
  return problem;
}

template <class G>
void BM_Trade(benchmark::State& state) {
  using D = typename InDouble<G>::type;
  using Scalar = typename G::Scalar;
  const int source = static_cast<int>(state.range(0));
  const Problem<D> data = trade_data<D>(source);
  bireg::RegressionOptions<double> reference_options;
  reference_options.batched_kernels = false;
  const auto reference = bireg::GeodesicRegression<D>(reference_options).fit(data.f, data.t);
  std::vector<typename G::Element> f;
  for (const auto& pose : data.f)
    f.push_back(pose.template cast<Scalar>());
  typename bireg::GeodesicRegression<G>::Options options;
  options.batched_kernels = state.range(1) != 0;
  const bireg::GeodesicRegression<G> regression(options);
  auto result = regression.fit(f, data.t);
  if (data.f.empty() || !reference.ok() || !result.ok()) {
    state.SkipWithError("a fit failed");
    return;
  }
  for (auto _ : state) {
    result = regression.fit(f, data.t);
    benchmark::DoNotOptimize(result.geodesic);
  }
  const auto distance = [](const typename D::Element& a, const typename G::Element& b) {
    return D::log(D::compose(D::inverse(a), b.template cast<double>())).norm();
  };
  state.counters["n"] = static_cast<double>(f.size());
  state.counters["endpoint_error"] =
      std::max(distance(reference.geodesic->start(), result.geodesic->start()),
               distance(reference.geodesic->end(), result.geodesic->end()));
  label(state, options.batched_kernels);
}
void trade_arguments(benchmark::internal::Benchmark* benchmark) {
  benchmark->ArgNames({"source", "batched"})->ArgsProduct({{0, 1}, {0, 1}});
  benchmark->Unit(benchmark::kMicrosecond);
}
BENCHMARK_TEMPLATE(BM_Trade, bireg::SO3d)->Apply(trade_arguments);
BENCHMARK_TEMPLATE(BM_Trade, bireg::SO3f)->Apply(trade_arguments);
BENCHMARK_TEMPLATE(BM_Trade, bireg::SE3d)->Apply(trade_arguments);
BENCHMARK_TEMPLATE(BM_Trade, bireg::SE3f)->Apply(trade_arguments);

void BM_Million(benchmark::State& state) {
  using G = bireg::SE3d;
  static const Problem<G> problem = make_problem<G>(1000000, 1.0, 0.1, 3);
  bireg::RegressionOptions<double> options;
  options.threads = static_cast<int>(state.range(0));
  options.batched_kernels = state.range(1) != 0;
  const bireg::GeodesicRegression<G> regression(options);
  int iterations = 0;
  for (auto _ : state) {
    const auto result = regression.fit(problem.f, problem.t);
    iterations = result.iterations;
    benchmark::DoNotOptimize(result.geodesic);
  }
  state.counters["iterations"] = iterations;
}
BENCHMARK(BM_Million)
    ->ArgNames({"threads", "batched"})
    ->ArgsProduct({{1, 2}, {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

template <class G>
void BM_Force(benchmark::State& state) {
  const bool batched = state.range(0) != 0;
  const Problem<G> data = make_problem<G>(static_cast<int>(state.range(1)), 1.0, 0.1, 3);
  const auto fit = bireg::GeodesicRegression<G>().fit(data.f, data.t);
  if (!fit.ok()) {
    state.SkipWithError("the fit failed");
    return;
  }
  bireg::Problem<double> problem;
  problem.t = data.t;  // already on [0, 1]
  problem.w.assign(data.t.size(), 1.0);
  const typename G::Element g0 = fit.geodesic->start(), g1 = fit.geodesic->end();
  const typename G::Tangent x = G::log(G::compose(G::inverse(g0), g1));
  if (!bireg::uses_closed_form_psi<G>(x)) {
    state.SkipWithError("not in the closed form's range");
    return;
  }
  std::vector<typename G::Tangent> residuals(data.f.size());
  for (auto _ : state) {
    const auto force = bireg::estimating_detail::closed_form_force<G>(data.f, problem, g0, x,
                                                                      residuals, nullptr, batched);
    benchmark::DoNotOptimize(force);
  }
  label(state, batched);
  state.counters["time_per_obs"] = benchmark::Counter(
      static_cast<double>(data.f.size()),
      benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
void force_arguments(benchmark::internal::Benchmark* benchmark) {
  benchmark->ArgNames({"batched", "n"})
      ->ArgsProduct({{0, 1}, {1000, 100000}})
      ->Unit(benchmark::kMicrosecond);
}
BENCHMARK_TEMPLATE(BM_Force, bireg::SO3d)->Apply(force_arguments);
BENCHMARK_TEMPLATE(BM_Force, bireg::SE3d)->Apply(force_arguments);

}  // namespace

BENCHMARK_MAIN();
