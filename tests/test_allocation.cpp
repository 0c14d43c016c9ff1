// The solver loop performs no heap allocation: a fit that runs 40 iterations
// allocates exactly as often as one that runs 1, for every solver. Counted
// with a replacement global operator new (this test is its own executable).
#include <atomic>
#include <cstdlib>
#include <new>
#include <random>
#include <vector>

#include "bireg/groups/se3.hpp"
#include "bireg/regression.hpp"
#include "catch.hpp"

namespace {
std::atomic<long> allocations{0};
}

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

TEST_CASE("the solver loop does not allocate", "[allocation]") {
  using G = bireg::SE3<double>;
  std::mt19937 rng(71);
  std::uniform_real_distribution<double> uniform(-1, 1);
  G::Tangent x;
  for (int k = 0; k < 6; ++k)
    x[k] = uniform(rng);
  std::vector<G::Element> f;
  std::vector<double> t;
  for (int i = 0; i < 50; ++i) {
    G::Tangent noise;
    for (int k = 0; k < 6; ++k)
      noise[k] = 0.1 * uniform(rng);
    f.push_back(G::exp(i / 49.0 * x + noise));
    t.push_back(i);
  }
  for (bireg::Solver solver : {bireg::Solver::paper, bireg::Solver::optimal_linear,
                               bireg::Solver::preconditioned, bireg::Solver::gauss_newton}) {
    CAPTURE(bireg::to_string(solver));
    const auto count = [&](int iterations) {
      bireg::GeodesicRegression<G>::Options options;
      options.solver = solver;
      options.max_iterations = iterations;
      options.tolerance = 0;  // run every iteration
      const bireg::GeodesicRegression<G> regression(options);
      const long before = allocations.load();
      const auto result = regression.fit(f, t);
      const long used = allocations.load() - before;
      REQUIRE(result.iterations == iterations);
      return used;
    };
    REQUIRE(count(40) == count(1));
  }
}
