// Inputs a hostile or careless user gives fit(): magnitudes at the ends of
// double's range, weights that only scale, float groups with large
// covariates, absurd iteration limits and step sizes. Each gets a status and
// a message, finite diagnostics, and no exception.
#include <climits>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "bireg/groups/product.hpp"
#include "bireg/groups/rn.hpp"
#include "bireg/groups/se3.hpp"
#include "bireg/groups/so3.hpp"
#include "bireg/regression.hpp"
#include "catch.hpp"
#include "test_support.hpp"

using bireg_test::random_tangent;

namespace {

template <class G>
struct Data {
  std::vector<typename G::Element> f;
  std::vector<double> t;
};

// A geodesic of length ~1 through noise 0.05, n observations at 0..n-1.
template <class G>
Data<G> noisy_geodesic(std::mt19937& rng, int n = 30) {
  using Tangent = typename G::Tangent;
  const Tangent x = random_tangent<Tangent>(rng, 0.5);
  Data<G> data;
  for (int i = 0; i < n; ++i) {
    const double s = i / double(n - 1);
    const Tangent noise = random_tangent<Tangent>(rng, 0.05);
    data.f.push_back(G::exp(s * x + noise));
    data.t.push_back(i);
  }
  return data;
}

template <class Result>
void require_rejected(const Result& result, const std::string& words, std::ptrdiff_t index) {
  CAPTURE(result.message);
  REQUIRE(result.status == bireg::Status::invalid_input);
  REQUIRE_FALSE(result.ok());
  REQUIRE_FALSE(result.geodesic.has_value());
  REQUIRE(result.message.find(words) != std::string::npos);
  REQUIRE(result.bad_index == index);
}

}  // namespace

TEST_CASE("translations beyond what the fit can square are refused, not inf", "[hostile]") {
  using G = bireg::SE3d;
  std::mt19937 rng(1);
  Data<G> data = noisy_geodesic<G>(rng);
  // 1.12486854893e227, as a fuzzer found it in a TUM file: one pose far away.
  data.f[3](0, 3) = 1.12486854893e227;
  require_rejected(bireg::GeodesicRegression<G>().fit(data.f, data.t), "too far", 3);
  // Just inside the bound the fit is carried out and reports finite numbers.
  Data<G> large = noisy_geodesic<G>(rng);
  for (auto& f : large.f)
    f.topRightCorner<3, 1>() *= 1e140;
  const auto result = bireg::GeodesicRegression<G>().fit(large.f, large.t);
  REQUIRE(result.status != bireg::Status::invalid_input);
  REQUIRE(std::isfinite(result.diagnostics.residual_rms));
  REQUIRE(std::isfinite(result.diagnostics.explained_variance));
  REQUIRE(std::isfinite(result.diagnostics.force_norm));
}

TEMPLATE_TEST_CASE("vector groups at 1e300 are refused with the observation", "[hostile]",
                   (bireg::Rn<3, double>), (bireg::Product<bireg::SO3d, bireg::Rn<3, double>>)) {
  using G = TestType;
  std::mt19937 rng(2);
  Data<G> data = noisy_geodesic<G>(rng);
  typename G::Tangent huge = G::Tangent::Zero();
  huge[G::dof - 1] = 1e300;
  data.f[7] = G::compose(data.f[7], G::exp(huge));
  const auto result = bireg::GeodesicRegression<G>().fit(data.f, data.t);
  require_rejected(result, "too far", 7);
}

TEST_CASE("uniform weights of any size give the unweighted fit exactly", "[hostile]") {
  using G = bireg::SE3d;
  std::mt19937 rng(3);
  const Data<G> data = noisy_geodesic<G>(rng);
  const auto plain = bireg::GeodesicRegression<G>().fit(data.f, data.t);
  REQUIRE(plain.ok());
  for (double w : {1e300, 1e-300, 3.0, std::numeric_limits<double>::denorm_min()}) {
    CAPTURE(w);
    const std::vector<double> weights(data.f.size(), w);
    const auto weighted = bireg::GeodesicRegression<G>().fit(data.f, data.t, weights);
    REQUIRE(weighted.ok());
    // Weights are divided by the largest before any sum: exactly 1 here.
    REQUIRE(weighted.geodesic->start() == plain.geodesic->start());
    REQUIRE(weighted.geodesic->end() == plain.geodesic->end());
  }
}

TEST_CASE("float groups map large covariates in double", "[hostile]") {
  using G = bireg::SO3f;
  std::vector<G::Element> f;
  std::vector<double> t;
  const G::Tangent w(0.03f, -0.02f, 0.01f);  // rad per 0.01 s step: 0.7 rad in all
  for (int i = 0; i < 20; ++i) {
    f.push_back(G::exp(float(i) * w));
    t.push_back(1.7e9 + 0.01 * i);  // distinct in double, equal in float
  }
  const auto result = bireg::GeodesicRegression<G>().fit(f, t);
  CAPTURE(result.message);
  REQUIRE(result.ok());
  // The slope over the range (19 steps) is recovered to float rounding.
  REQUIRE((result.geodesic->displacement() - 19.0f * w).norm() <= 1e-5f);
}

TEST_CASE("an absurd iteration limit reserves nothing absurd", "[hostile]") {
  using G = bireg::SE3d;
  std::mt19937 rng(4);
  const Data<G> data = noisy_geodesic<G>(rng);
  bireg::GeodesicRegression<G>::Options options;
  options.max_iterations = INT_MAX;
  options.record_iterates = true;
  const auto result = bireg::GeodesicRegression<G>(options).fit(data.f, data.t);
  REQUIRE(result.ok());
  REQUIRE(result.iterations < 20);
  REQUIRE(result.step_norms.capacity() <= std::size_t(bireg::kReservedHistory));
}

// Convergence of the paper's step is judged on ||v|| / mu_max, not on the
// step lambda v, so a tiny lambda cannot fake it.
TEST_CASE("a tiny paper step size does not fake convergence", "[hostile]") {
  using G = bireg::SE3d;
  std::mt19937 rng(5);
  const Data<G> data = noisy_geodesic<G>(rng);
  bireg::GeodesicRegression<G>::Options options;
  options.solver = bireg::Solver::paper;
  options.step_size = 1e-300;
  options.max_iterations = 5;
  const auto result = bireg::GeodesicRegression<G>(options).fit(data.f, data.t);
  REQUIRE(result.status == bireg::Status::max_iterations);
  REQUIRE(result.diagnostics.force_norm > 1e-6);
}

TEST_CASE("options that do not apply are refused, all by one rule", "[hostile]") {
  using G = bireg::SO3d;
  std::mt19937 rng(6);
  const Data<G> data = noisy_geodesic<G>(rng);
  bireg::GeodesicRegression<G>::Options options;
  options.series_order = 8;  // method exact
  require_rejected(bireg::GeodesicRegression<G>(options).fit(data.f, data.t),
                   "series_order applies to method series only", -1);
  options.method = bireg::Method::series;
  REQUIRE(bireg::GeodesicRegression<G>(options).fit(data.f, data.t).ok());
  options = {};
  options.step_size = 0.01;  // solver gauss_newton
  require_rejected(bireg::GeodesicRegression<G>(options).fit(data.f, data.t),
                   "step_size applies to the paper solver only", -1);
  options = {};
  options.interval = std::make_pair(0.0, 10.0);  // covariates reach 29
  require_rejected(bireg::GeodesicRegression<G>(options).fit(data.f, data.t),
                   "outside the covariate interval", 11);
}

// The covariate interval fixes the unit interval: a fit over [0, 29] with an
// explicit interval [-10, 40] is the same geodesic, parametrised there.
TEST_CASE("an explicit covariate interval changes the parametrisation, not the line",
          "[regression]") {
  using G = bireg::Rn<2, double>;
  std::mt19937 rng(7);
  const Data<G> data = noisy_geodesic<G>(rng);
  bireg::GeodesicRegression<G>::Options options;
  options.interval = std::make_pair(-10.0, 40.0);
  const auto wide = bireg::GeodesicRegression<G>(options).fit(data.f, data.t);
  const auto plain = bireg::GeodesicRegression<G>().fit(data.f, data.t);
  REQUIRE(wide.ok());
  REQUIRE(plain.ok());
  REQUIRE(wide.geodesic->t_min() == -10.0);
  REQUIRE(wide.geodesic->t_max() == 40.0);
  // On R^n both are the least-squares line: equal wherever evaluated.
  for (double t : {-10.0, 0.0, 13.5, 29.0, 40.0}) {
    CAPTURE(t);
    REQUIRE(((*wide.geodesic)(t) - (*plain.geodesic)(t)).norm() <= 1e-12);
  }
}
