// Deterministic threads: the same fit with 1, 2 and 7 threads returns
// bit-identical endpoints, residuals, step norms and diagnostics, for a
// fit spanning several chunks (parallel.hpp) and for a small one, on both
// evaluations of the force (closed form and series). A thread count below
// 1 is refused with a message.
#include <random>
#include <string>
#include <vector>

#include "bireg/groups/se3.hpp"
#include "bireg/regression.hpp"
#include "catch.hpp"

namespace {

using G = bireg::SE3<double>;
using Regression = bireg::GeodesicRegression<G>;

// n poses scattered about a geodesic: exp(t x + noise), t in [0, 1].
void make_observations(std::size_t n, std::vector<G::Element>& f, std::vector<double>& t) {
  std::mt19937 rng(16);
  std::uniform_real_distribution<double> uniform(-1, 1);
  G::Tangent x;
  for (int k = 0; k < G::dof; ++k)
    x[k] = uniform(rng);
  for (std::size_t i = 0; i < n; ++i) {
    G::Tangent noise;
    for (int k = 0; k < G::dof; ++k)
      noise[k] = 0.2 * uniform(rng);
    const double covariate = static_cast<double>(i) / static_cast<double>(n - 1);
    f.push_back(G::exp(covariate * x + noise));
    t.push_back(covariate);
  }
}

Regression::Result fit_with(int threads, bireg::Method method, const std::vector<G::Element>& f,
                            const std::vector<double>& t) {
  Regression::Options options;
  options.threads = threads;
  options.method = method;
  const auto result = Regression(options).fit(f, t);
  REQUIRE(result.ok());
  return result;
}

void require_identical(const Regression::Result& a, const Regression::Result& b) {
  REQUIRE(a.status == b.status);
  REQUIRE(a.iterations == b.iterations);
  REQUIRE(a.geodesic->start() == b.geodesic->start());
  REQUIRE(a.geodesic->end() == b.geodesic->end());
  REQUIRE(a.step_norms == b.step_norms);
  REQUIRE(a.residuals.size() == b.residuals.size());
  for (std::size_t i = 0; i < a.residuals.size(); ++i)
    REQUIRE(a.residuals[i] == b.residuals[i]);
  REQUIRE(a.diagnostics.force_norm == b.diagnostics.force_norm);
  REQUIRE(a.diagnostics.residual_rms == b.diagnostics.residual_rms);
  REQUIRE(a.diagnostics.explained_variance == b.diagnostics.explained_variance);
  REQUIRE(a.diagnostics.contraction_factor == b.diagnostics.contraction_factor);
  REQUIRE(a.diagnostics.backtracks == b.diagnostics.backtracks);
  REQUIRE(a.diagnostics.series_order == b.diagnostics.series_order);
}

}  // namespace

TEST_CASE("fits are bit-identical for 1, 2 and 7 threads", "[threads]") {
  for (const std::size_t n : {std::size_t(20000), std::size_t(50)}) {
    CAPTURE(n);
    std::vector<G::Element> f;
    std::vector<double> t;
    make_observations(n, f, t);
    for (const bireg::Method method : {bireg::Method::exact, bireg::Method::series_adaptive}) {
      CAPTURE(bireg::to_string(method));
      const auto serial = fit_with(1, method, f, t);
      require_identical(serial, fit_with(2, method, f, t));
      require_identical(serial, fit_with(7, method, f, t));
    }
  }
}

TEST_CASE("a thread count below 1 is refused", "[threads]") {
  std::vector<G::Element> f;
  std::vector<double> t;
  make_observations(10, f, t);
  for (const int threads : {0, -3}) {
    Regression::Options options;
    options.threads = threads;
    const auto result = Regression(options).fit(f, t);
    REQUIRE(result.status == bireg::Status::invalid_input);
    REQUIRE(result.message == "threads must be at least 1, got " + std::to_string(threads));
  }
}
