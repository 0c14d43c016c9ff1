// The solver loop performs no heap allocation: a fit that runs 40 iterations
// allocates exactly as often as one that runs 1, for every solver, on SE(3)
// and on the matrix groups (whose exp and log are fixed-size: no Schur
// decomposition). The local regression allocates nothing per query:
// smoothing 4x more observations allocates exactly as often. A result keeps
// little unused history. Counted with a replacement global operator new
// (this test is its own executable).
#include <atomic>
#include <cstdlib>
#include <new>
#include <random>
#include <vector>

#include "bireg/groups/matrix_group.hpp"
#include "bireg/groups/se3.hpp"
#include "bireg/groups/so3.hpp"
#include "bireg/regression.hpp"
#include "bireg/statistics/smoothing/local_regression.hpp"
#include "catch.hpp"
#include "test_support.hpp"

namespace {
std::atomic<long> allocations{0};
}

// The replacements pair malloc with free, as the standard allows. GCC 12
// -O3 sees the library's new-expressions inlined next to these deletes and
// warns that free() meets memory from operator new: a false positive here.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
#endif
void* operator new(std::size_t size) {
  ++allocations;
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
  std::free(p);
}
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif

namespace {

// Observations scattered about a geodesic: exp(i/(n - 1) x + noise), x and the
// noise uniform in [-1, 1] and [-0.1, 0.1] per coordinate.
template <class G>
void make_observations(std::vector<typename G::Element>& f, std::vector<double>& t, int n = 50) {
  std::mt19937 rng(71);
  std::uniform_real_distribution<double> uniform(-1, 1);
  typename G::Tangent x;
  for (int k = 0; k < G::dof; ++k)
    x[k] = uniform(rng);
  for (int i = 0; i < n; ++i) {
    typename G::Tangent noise;
    for (int k = 0; k < G::dof; ++k)
      noise[k] = 0.1 * uniform(rng);
    f.push_back(G::exp(i / (n - 1.0) * x + noise));
    t.push_back(i);
  }
}

// Allocations of a fit that runs exactly `iterations` iterations.
template <class G>
long fit_allocations(const std::vector<typename G::Element>& f, const std::vector<double>& t,
                     bireg::Solver solver, int iterations, int threads = 1) {
  typename bireg::GeodesicRegression<G>::Options options;
  options.threads = threads;
  options.solver = solver;
  options.max_iterations = iterations;
  options.tolerance = 0;  // run every iteration
  const bireg::GeodesicRegression<G> regression(options);
  const long before = allocations.load();
  const auto result = regression.fit(f, t);
  const long used = allocations.load() - before;
  REQUIRE(result.iterations == iterations);
  return used;
}

}  // namespace

TEMPLATE_TEST_CASE("the solver loop does not allocate", "[allocation]", bireg::SE3<double>,
                   bireg::SL3<double>, (bireg::GLp<3, double>), bireg::Heisenberg<double>) {
  using G = TestType;
  std::vector<typename G::Element> f;
  std::vector<double> t;
  make_observations<G>(f, t);
  for (bireg::Solver solver : {bireg::Solver::paper, bireg::Solver::optimal_linear,
                               bireg::Solver::preconditioned, bireg::Solver::gauss_newton}) {
    CAPTURE(bireg::to_string(solver));
    const long one = fit_allocations<G>(f, t, solver, 1);
    const long forty = fit_allocations<G>(f, t, solver, 40);
    REQUIRE(forty == one);
  }
}

// With threads, the pool and the chunk partials are made once per fit: a
// fit spanning several chunks on 2 threads also allocates as often for 40
// iterations as for 1.
TEST_CASE("the threaded solver loop does not allocate", "[allocation]") {
  using G = bireg::SE3<double>;
  std::vector<typename G::Element> f;
  std::vector<double> t;
  make_observations<G>(f, t, 3 * static_cast<int>(bireg::kChunkSize));
  for (const int threads : {1, 2}) {
    CAPTURE(threads);
    const long one = fit_allocations<G>(f, t, bireg::Solver::gauss_newton, 1, threads);
    const long forty = fit_allocations<G>(f, t, bireg::Solver::gauss_newton, 40, threads);
    REQUIRE(forty == one);
  }
}

// A result is kept (fit_many keeps one per subject, 10,000 in its
// benchmark), so the history reserved before the loop must not outweigh
// it: a fit converging in a few iterations keeps at most 512 bytes of
// unused step norms and 64 unused SE(3) iterates (8 KB and 256 KB when
// 1,024 iterations were reserved). A fit of 200 iterations, beyond the
// reservation, still records every step.
TEST_CASE("a result keeps a small history reservation", "[allocation]") {
  using G = bireg::SE3<double>;
  std::vector<typename G::Element> f;
  std::vector<double> t;
  make_observations<G>(f, t);
  typename bireg::GeodesicRegression<G>::Options options;
  options.record_iterates = true;
  const auto converged = bireg::GeodesicRegression<G>(options).fit(f, t);
  REQUIRE(converged.ok());
  REQUIRE(converged.iterations < 20);
  CHECK((converged.step_norms.capacity() - converged.step_norms.size()) * sizeof(double) <= 512);
  CHECK(converged.iterates.capacity() - converged.iterates.size() <= 64);

  options.max_iterations = 200;
  options.tolerance = 0;  // run every iteration
  const auto long_run = bireg::GeodesicRegression<G>(options).fit(f, t);
  REQUIRE(long_run.iterations == 200);
  CHECK(long_run.step_norms.size() == 200);
  CHECK(long_run.iterates.size() > 64);
}

// Smoothing n observations of a smooth SO(3) curve (noise 0.01 rad, 1 kHz,
// test_support.hpp; Gaussian h = 2.5 samples), with standard errors: the buffers grow to the
// largest window in the first queries, and no query after them allocates.
// Allocations per call, not per query: 4x the queries, the same count.
TEST_CASE("the local regression allocates nothing per query", "[allocation]") {
  using G = bireg::SO3<double>;
  const auto smooth_allocations = [](int n) {
    const bireg_test::So3Trajectory data = bireg_test::dense_so3_trajectory(n, 0.01, 7);
    const std::vector<G::Element>& f = data.f;
    const std::vector<double>& t = data.t;
    bireg::LocalRegressionOptions<double> options;
    options.bandwidth = 2.5e-3;
    const bireg::LocalGeodesicRegression<G> smoother(options);
    const long before = allocations.load();
    const auto estimates = smoother.smooth(f, t);
    const long used = allocations.load() - before;
    for (const auto& estimate : estimates) {
      REQUIRE(estimate.ok());
      REQUIRE(estimate.velocity_error_defined);
    }
    return used;
  };
  const long small = smooth_allocations(250);
  const long large = smooth_allocations(1000);
  CHECK(large == small);
}
