// GeodesicRegression: commutative exactness, equivariance of the estimator
// and of the iterates, the linear rate of the paper's theorem, recovery of
// noise-free geodesics, the estimating equations at the solution, and every
// documented input error.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "bireg/geodesic.hpp"
#include "bireg/groups/rn.hpp"
#include "bireg/groups/se2.hpp"
#include "bireg/groups/se3.hpp"
#include "bireg/groups/so2.hpp"
#include "bireg/groups/so3.hpp"
#include "bireg/math/small_angle.hpp"
#include "bireg/regression.hpp"
#include "catch.hpp"
#include "test_support.hpp"

using bireg_test::random_tangent;
using bireg_test::relative_error;

namespace {

template <class G>
struct Data {
  std::vector<typename G::Element> f;
  std::vector<double> t;  // user units
};

// N observations of g0 exp(s X) exp(noise) at s evenly spread over [0, 1],
// reported at covariates 10 + 4 s ("seconds"), noise entries uniform in
// [-noise, noise].
template <class G>
Data<G> geodesic_data(const typename G::Element& g0, const typename G::Tangent& x, int n,
                      double noise, std::mt19937& rng) {
  Data<G> data;
  for (int i = 0; i < n; ++i) {
    const double s = static_cast<double>(i) / (n - 1);
    typename G::Element f = bireg::exp_at<G>(g0, s * x);
    if (noise > 0) f = bireg::exp_at<G>(f, random_tangent<typename G::Tangent>(rng, noise));
    data.f.push_back(f);
    data.t.push_back(10 + 4 * s);
  }
  return data;
}

// The paper's iteration with step `step_size` from (start0, start1), every
// iterate recorded, for exactly `iterations` steps (tolerance 0).
template <class G>
typename bireg::GeodesicRegression<G>::Result recorded_paper_run(
    const std::vector<typename G::Element>& f, const std::vector<double>& t, double step_size,
    const typename G::Element& start0, const typename G::Element& start1, int iterations) {
  typename bireg::GeodesicRegression<G>::Options options;
  options.solver = bireg::Solver::paper;
  options.step_size = step_size;
  options.record_iterates = true;
  options.max_iterations = iterations;
  options.tolerance = 0;
  return bireg::GeodesicRegression<G>(options).fit_from({start0, start1}, f, t);
}

// Unit eigenvector of H = [a b; b c] (unit covariate interval, unit
// weights) for its smaller eigenvalue: (b, mu_min - a) solves the first row
// of (H - mu_min I) e = 0.
Eigen::Vector2d slow_eigenvector(const std::vector<double>& t, double mu_min) {
  const double t_min = *std::min_element(t.begin(), t.end());
  const double t_max = *std::max_element(t.begin(), t.end());
  double a = 0, b = 0;
  for (double ti : t) {
    const double s = (ti - t_min) / (t_max - t_min);
    a += (1 - s) * (1 - s);
    b += s * (1 - s);
  }
  return Eigen::Vector2d(b, mu_min - a).normalized();
}

template <class G>
bool all_finite(const typename bireg::GeodesicRegression<G>::Result& result) {
  // A refused fit has no geodesic; what it has must still be finite.
  const bool geodesic_finite = !result.geodesic || (result.geodesic->start().allFinite() &&
                                                    result.geodesic->end().allFinite());
  return geodesic_finite && std::isfinite(result.diagnostics.residual_rms) &&
         std::isfinite(result.diagnostics.explained_variance);
}

// ---------------------------------------------------------------------------
// 2. Commutative exactness
// ---------------------------------------------------------------------------

// On R^n the estimating equations are the normal equations of weighted least
// squares, so the fit is the closed-form line. Both sides solve a 2x2 system
// with O(1) data; 1e-10 relative leaves six orders of margin over rounding.
TEST_CASE("on Rn the fit is the weighted least-squares line", "[regression][commutative]") {
  using G = bireg::Rn<3, double>;
  std::mt19937 rng(21);
  std::uniform_real_distribution<double> uniform(-1, 1);
  std::vector<G::Element> f;
  std::vector<double> t, w;
  const G::Element alpha(1.0, -2.0, 0.5), beta(0.3, 0.7, -1.1);
  for (int i = 0; i < 30; ++i) {
    const double ti = 100 + 50 * (uniform(rng) + 1);  // unsorted, user units
    t.push_back(ti);
    f.push_back(alpha + beta * ti + bireg::testing::draw_vector<G::Element>(rng, uniform));
    w.push_back(0.5 + (uniform(rng) + 1));
  }
  // Closed form, in the user's units.
  double sw = 0, st = 0, stt = 0;
  G::Element sy = G::Element::Zero(), sty = G::Element::Zero();
  for (std::size_t i = 0; i < t.size(); ++i) {
    sw += w[i];
    st += w[i] * t[i];
    stt += w[i] * t[i] * t[i];
    sy += w[i] * f[i];
    sty += w[i] * t[i] * f[i];
  }
  const double det = sw * stt - st * st;
  const G::Element intercept = (stt * sy - st * sty) / det;
  const G::Element slope = (sw * sty - st * sy) / det;
  const double t_min = *std::min_element(t.begin(), t.end());
  const double t_max = *std::max_element(t.begin(), t.end());

  typename bireg::GeodesicRegression<G>::Options options;
  std::optional<typename bireg::GeodesicRegression<G>::Endpoints> start;
  SECTION("from the default initial guess") {}
  SECTION("from a poor initial guess") {
    start.emplace(G::Element(5, 5, 5), G::Element(-5, 0, 5));
    // The data reach |f| ~ 200, so steps bottom out at ~200 eps ~ 4e-14;
    // 1e-12 is reachable and leaves the endpoints ~1e-12 from the solution.
    options.tolerance = 1e-12;
  }
  const bireg::GeodesicRegression<G> regression(options);
  const auto result = start ? regression.fit_from(*start, f, t, w) : regression.fit(f, t, w);
  REQUIRE(result.ok());
  REQUIRE(relative_error(result.geodesic->start(), intercept + slope * t_min) <= 1e-10);
  REQUIRE(relative_error(result.geodesic->end(), intercept + slope * t_max) <= 1e-10);
  REQUIRE(relative_error(result.geodesic->body_velocity(), slope) <= 1e-10);
  // R^2 of ordinary regression, computed the textbook way.
  double ss_res = 0, ss_tot = 0;
  const G::Element mean = sy / sw;
  for (std::size_t i = 0; i < t.size(); ++i) {
    ss_res += w[i] * (f[i] - intercept - slope * t[i]).squaredNorm();
    ss_tot += w[i] * (f[i] - mean).squaredNorm();
  }
  REQUIRE(std::abs(result.diagnostics.explained_variance - (1 - ss_res / ss_tot)) <= 1e-10);
}

// With the start displaced from the solution along the mu_min eigenvector of
// H, the iteration on a commutative group is exactly x_n - x^ =
// (1 - lambda mu_min)^n (x_0 - x^) (Lemma 3.7 with R = 0). The error
// is measured while it is at least 1e-3 of its start (0.14), i.e. >= 1e-4,
// where the iterates' rounding (~5 eps ~ 1e-15 on entries up to 5) is below
// 1e-11 of it: relative 1e-10 holds with a margin of 10.
template <class G>
void check_commutative_rate(const std::vector<typename G::Element>& f, const std::vector<double>& t,
                            double lambda_fraction) {
  using Tangent = typename G::Tangent;
  typename bireg::GeodesicRegression<G>::Options exact_options;
  exact_options.tolerance = 1e-15;
  const auto exact = bireg::GeodesicRegression<G>(exact_options).fit(f, t);
  REQUIRE(exact.ok());
  const double mu_min = exact.diagnostics.mu_min, mu_max = exact.diagnostics.mu_max;

  const Eigen::Vector2d e_min = slow_eigenvector(t, mu_min);
  const Tangent u = Tangent::Constant(0.1);
  const typename G::Element g0 = G::compose(exact.geodesic->start(), G::exp(e_min[0] * u));
  const typename G::Element g1 = G::compose(exact.geodesic->end(), G::exp(e_min[1] * u));

  const double step_size = lambda_fraction / mu_max;
  const auto run = recorded_paper_run<G>(f, t, step_size, g0, g1, 40);
  const auto error = [&](const typename G::Element& x0, const typename G::Element& x1) {
    return std::sqrt(bireg::log_at<G>(exact.geodesic->start(), x0).squaredNorm() +
                     bireg::log_at<G>(exact.geodesic->end(), x1).squaredNorm());
  };
  const double error0 = error(g0, g1);
  const double factor = 1 - step_size * mu_min;
  int checked = 0;
  for (std::size_t n = 1; n <= run.iterates.size(); ++n) {
    const double predicted = std::pow(factor, static_cast<double>(n)) * error0;
    if (predicted < 1e-3 * error0) break;
    const double measured = error(run.iterates[n - 1].first, run.iterates[n - 1].second);
    CAPTURE(n, measured, predicted);
    REQUIRE(std::abs(measured / predicted - 1) <= 1e-10);
    ++checked;
  }
  REQUIRE(checked >= 5);  // (1 - lambda mu_min) <= 0.75 reaches 1e-3 within ~25 steps
}

TEST_CASE("on Rn and SO2 the error contracts exactly by (1 - lambda mu_min)^n",
          "[regression][commutative]") {
  std::mt19937 rng(22);
  std::uniform_real_distribution<double> uniform(-1, 1);
  std::vector<double> t;
  for (int i = 0; i < 25; ++i)
    t.push_back(3 + 2 * uniform(rng));
  for (double lambda_fraction : {1.0, 0.5, 0.2}) {
    CAPTURE(lambda_fraction);
    {
      using G = bireg::Rn<2, double>;
      std::vector<G::Element> f;
      for (double ti : t) {
        const Eigen::Vector2d e = bireg::testing::draw_vector<Eigen::Vector2d>(rng, uniform);
        f.push_back(G::Element(0.5 * ti + 0.1 * e[0], -ti + 0.1 * e[1]));
      }
      check_commutative_rate<G>(f, t, lambda_fraction);
    }
    {
      using G = bireg::SO2<double>;
      std::vector<G::Element> f;
      for (double ti : t)
        f.push_back(G::exp(G::Tangent(0.2 * ti - 0.5 + 0.1 * uniform(rng))));
      check_commutative_rate<G>(f, t, lambda_fraction);
    }
  }
}

// ---------------------------------------------------------------------------
// 3. Equivariance
// ---------------------------------------------------------------------------

// The estimator's equivariance (paper, Theorem 2.4; inversion in
// DESIGN.md section 1), on data far from the identity and h far from the
// identity. Each fit runs to tolerance 1e-13, i.e. to within ~1e-12 of its
// fixed point, so the two fits must agree to 1e-10.
constexpr bireg::Solver kAllSolvers[] = {bireg::Solver::paper, bireg::Solver::optimal_linear,
                                         bireg::Solver::preconditioned,
                                         bireg::Solver::gauss_newton};

constexpr bireg::Method kAllMethods[] = {bireg::Method::series, bireg::Method::series_adaptive,
                                         bireg::Method::exact};

// Options for one solver and method; Method::series at order 8.
template <class G>
typename bireg::GeodesicRegression<G>::Options options_for(bireg::Solver solver,
                                                           bireg::Method method) {
  typename bireg::GeodesicRegression<G>::Options options;
  options.solver = solver;
  options.method = method;
  options.series_order = method == bireg::Method::series ? 8 : 0;
  return options;
}

template <class G>
void check_estimator_equivariance(std::mt19937& rng, bireg::Solver solver, bireg::Method method) {
  using Element = typename G::Element;
  using Tangent = typename G::Tangent;
  const Element g0 = G::exp(random_tangent<Tangent>(rng, 1.5));
  const Tangent x = random_tangent<Tangent>(rng, 0.8);
  const Data<G> data = geodesic_data<G>(g0, x, 40, 0.1, rng);
  const Element h = G::exp(random_tangent<Tangent>(rng, 1.6));

  auto options = options_for<G>(solver, method);
  options.tolerance = 1e-13;
  const bireg::GeodesicRegression<G> regression(options);
  const auto base = regression.fit(data.f, data.t);
  REQUIRE(base.ok());
  const Element fit0 = base.geodesic->start(), fit1 = base.geodesic->end();

  std::vector<Element> left, right, inverted;
  for (const Element& f : data.f) {
    left.push_back(G::compose(h, f));
    right.push_back(G::compose(f, h));
    inverted.push_back(G::inverse(f));
  }
  const auto left_fit = regression.fit(left, data.t);
  const auto right_fit = regression.fit(right, data.t);
  const auto inverse_fit = regression.fit(inverted, data.t);
  REQUIRE(left_fit.ok());
  REQUIRE(right_fit.ok());
  REQUIRE(inverse_fit.ok());
  constexpr double kTolerance = 1e-10;
  // A series cut at a fixed order is a polynomial in ad_X, which commutes
  // with every Ad: left and right equivariance stay exact. Inverse
  // equivariance rests on identities of the whole function psi (relating
  // psi_s(z) and psi_s(-z)), which the truncation breaks by its own size:
  // (rho / 2 pi)^9 <= 1e-4 for order 8 and rho <= 2.3 here.
  const double inverse_tolerance = method == bireg::Method::series ? 1e-4 : kTolerance;
  REQUIRE(relative_error(left_fit.geodesic->start(), G::compose(h, fit0)) <= kTolerance);
  REQUIRE(relative_error(left_fit.geodesic->end(), G::compose(h, fit1)) <= kTolerance);
  REQUIRE(relative_error(right_fit.geodesic->start(), G::compose(fit0, h)) <= kTolerance);
  REQUIRE(relative_error(right_fit.geodesic->end(), G::compose(fit1, h)) <= kTolerance);
  REQUIRE(relative_error(inverse_fit.geodesic->start(), G::inverse(fit0)) <= inverse_tolerance);
  REQUIRE(relative_error(inverse_fit.geodesic->end(), G::inverse(fit1)) <= inverse_tolerance);
}

TEST_CASE("the estimator is left, right and inverse equivariant", "[regression][equivariance]") {
  std::mt19937 rng(31);
  for (bireg::Solver solver : kAllSolvers) {
    for (bireg::Method method : kAllMethods) {
      for (int trial = 0; trial < 2; ++trial) {
        CAPTURE(bireg::to_string(solver), bireg::to_string(method), trial);
        check_estimator_equivariance<bireg::SO3<double>>(rng, solver, method);
        check_estimator_equivariance<bireg::SE3<double>>(rng, solver, method);
        check_estimator_equivariance<bireg::SE2<double>>(rng, solver, method);
      }
    }
  }
}

// The iterates themselves are equivariant when the start is transformed too
// (paper, Proposition 2.3): iterate by iterate, for a
// start that is not the default one. Rounding differences between the two
// runs are damped by the contraction, so 1e-10 holds at every step.
template <class G>
void check_iterate_equivariance(std::mt19937& rng, bireg::Solver solver, bireg::Method method) {
  using Element = typename G::Element;
  using Tangent = typename G::Tangent;
  const Element g0 = G::exp(random_tangent<Tangent>(rng, 1.5));
  const Data<G> data = geodesic_data<G>(g0, random_tangent<Tangent>(rng, 0.8), 30, 0.1, rng);
  const Element h = G::exp(random_tangent<Tangent>(rng, 1.6));
  const Element start0 = bireg::exp_at<G>(data.f.front(), random_tangent<Tangent>(rng, 0.2));
  const Element start1 = bireg::exp_at<G>(data.f.back(), random_tangent<Tangent>(rng, 0.2));

  const auto run = [&](const std::vector<Element>& f, const Element& a, const Element& b) {
    auto options = options_for<G>(solver, method);
    options.record_iterates = true;
    options.max_iterations = 25;
    options.tolerance = 1e-12;
    return bireg::GeodesicRegression<G>(options).fit_from({a, b}, f, data.t);
  };
  std::vector<Element> left, right, inverted;
  for (const Element& f : data.f) {
    left.push_back(G::compose(h, f));
    right.push_back(G::compose(f, h));
    inverted.push_back(G::inverse(f));
  }
  const auto base = run(data.f, start0, start1);
  const auto left_run = run(left, G::compose(h, start0), G::compose(h, start1));
  const auto right_run = run(right, G::compose(start0, h), G::compose(start1, h));
  const auto inverse_run = run(inverted, G::inverse(start0), G::inverse(start1));
  // The slow solvers run all 25 steps, the fast ones stop at 1e-12; either
  // way the transformed runs take the same number of steps.
  REQUIRE(base.iterates.size() >= 3);
  REQUIRE(left_run.iterates.size() == base.iterates.size());
  REQUIRE(right_run.iterates.size() == base.iterates.size());
  REQUIRE(inverse_run.iterates.size() == base.iterates.size());
  const double inverse_tolerance = method == bireg::Method::series ? 1e-4 : 1e-10;  // see above
  for (std::size_t n = 0; n < base.iterates.size(); ++n) {
    CAPTURE(n);
    const auto& [a, b] = base.iterates[n];
    REQUIRE(relative_error(left_run.iterates[n].first, G::compose(h, a)) <= 1e-10);
    REQUIRE(relative_error(left_run.iterates[n].second, G::compose(h, b)) <= 1e-10);
    REQUIRE(relative_error(right_run.iterates[n].first, G::compose(a, h)) <= 1e-10);
    REQUIRE(relative_error(right_run.iterates[n].second, G::compose(b, h)) <= 1e-10);
    REQUIRE(relative_error(inverse_run.iterates[n].first, G::inverse(a)) <= inverse_tolerance);
    REQUIRE(relative_error(inverse_run.iterates[n].second, G::inverse(b)) <= inverse_tolerance);
  }
}

TEST_CASE("the iterates are left, right and inverse equivariant", "[regression][equivariance]") {
  std::mt19937 rng(32);
  for (bireg::Solver solver : kAllSolvers) {
    for (bireg::Method method : kAllMethods) {
      CAPTURE(bireg::to_string(solver), bireg::to_string(method));
      check_iterate_equivariance<bireg::SO3<double>>(rng, solver, method);
      check_iterate_equivariance<bireg::SE3<double>>(rng, solver, method);
      check_iterate_equivariance<bireg::SE2<double>>(rng, solver, method);
    }
  }
}

// ---------------------------------------------------------------------------
// 4. The rate theorem
// ---------------------------------------------------------------------------

// Data of radius r about the identity on SO(3): the error in logarithmic
// coordinates after n steps obeys ||x_n - x^|| <= (1 - lambda eta)^n
// ||x_0 - x^|| with eta = mu_min - C r (paper, Theorem
// "existance_and_uniquness", Remark 4.6). The start is displaced from x^
// along the slow eigenvector of H (by r), where the linear part contracts by
// exactly 1 - lambda mu_min, so the measured eta isolates the curvature term.
//
// Measured: eta(r, lambda) = min_n (1 - (e_n / e_0)^{1/n}) / lambda over the
// steps where e_n is above 1e-12 (rounding). Asserted:
//  * one C serves every r and lambda: C is taken from the largest r, and
//    every smaller r must satisfy mu_min - eta <= C r (a deficit that did
//    not shrink with r would fail at r = 1e-3 by a factor 300);
//  * eta -> mu_min: at r = 1e-3 eta is within 1% of mu_min;
//  * iterations to a tolerance scale like 1/lambda: halving lambda
//    multiplies them by ln(1 - lambda mu_min) / ln(1 - lambda mu_min / 2)
//    (-> 2 as lambda -> 0), to within 15% (the count is an integer of ~10-80).
TEST_CASE("the iteration contracts at the rate of the theorem", "[regression][rate]") {
  using G = bireg::SO3<double>;
  using Element = G::Element;
  using Tangent = G::Tangent;
  const std::vector<double> radii = {0.3, 0.1, 0.03, 0.01, 0.003, 0.001};
  const std::vector<double> lambda_fractions = {1.0, 0.5, 0.25};
  constexpr int kN = 20;
  std::mt19937 rng(41);
  std::uniform_real_distribution<double> unit(0, 1);
  std::vector<Tangent> directions;
  for (int i = 0; i < kN; ++i) {
    const double length = unit(rng);
    directions.push_back(length * bireg_test::random_unit<3>(rng).cast<double>());
  }
  std::vector<double> t;
  for (int i = 0; i < kN; ++i)
    t.push_back(static_cast<double>(i) / (kN - 1));

  std::vector<std::vector<double>> deficits(radii.size());
  std::vector<std::vector<double>> etas(radii.size());
  double mu_min = 0;
  for (std::size_t ri = 0; ri < radii.size(); ++ri) {
    const double r = radii[ri];
    std::vector<Element> f;
    for (const Tangent& y : directions)
      f.push_back(G::exp(r * y));
    bireg::GeodesicRegression<G>::Options exact_options;
    exact_options.tolerance = 1e-16;
    exact_options.max_iterations = 5000;
    const auto exact = bireg::GeodesicRegression<G>(exact_options).fit(f, t);
    REQUIRE(exact.status != bireg::Status::invalid_input);
    mu_min = exact.diagnostics.mu_min;
    const double mu_max = exact.diagnostics.mu_max;
    const Eigen::Vector2d e_min = slow_eigenvector(t, mu_min);
    const Tangent u = r * Tangent(0.6, -0.8, 0.0);
    const Element start0 = G::compose(exact.geodesic->start(), G::exp(e_min[0] * u));
    const Element start1 = G::compose(exact.geodesic->end(), G::exp(e_min[1] * u));
    const Tangent x0_hat = G::log(exact.geodesic->start()), x1_hat = G::log(exact.geodesic->end());
    const auto error = [&](const Element& g0, const Element& g1) {
      return std::sqrt((G::log(g0) - x0_hat).squaredNorm() + (G::log(g1) - x1_hat).squaredNorm());
    };

    std::vector<int> iterations_to_tolerance;
    for (double fraction : lambda_fractions) {
      const double step_size = fraction / mu_max;
      const auto run = recorded_paper_run<G>(f, t, step_size, start0, start1, 400);
      const double e0 = error(start0, start1);
      double eta = std::numeric_limits<double>::infinity();
      int reached = -1;
      for (std::size_t n = 1; n <= run.iterates.size(); ++n) {
        const double en = error(run.iterates[n - 1].first, run.iterates[n - 1].second);
        if (reached < 0 && en <= 1e-8 * e0) reached = static_cast<int>(n);
        if (en <= 1e-12) break;
        eta = std::min(eta, (1 - std::pow(en / e0, 1.0 / static_cast<double>(n))) / step_size);
      }
      REQUIRE(reached > 0);
      iterations_to_tolerance.push_back(reached);
      deficits[ri].push_back(mu_min - eta);
      etas[ri].push_back(eta);
    }
    for (std::size_t li = 0; li + 1 < lambda_fractions.size(); ++li) {
      const double x = lambda_fractions[li] * mu_min / mu_max;
      const double predicted = std::log(1 - x) / std::log(1 - x / 2);
      const double measured =
          static_cast<double>(iterations_to_tolerance[li + 1]) / iterations_to_tolerance[li];
      CAPTURE(r, li, predicted, measured);
      REQUIRE(std::abs(measured / predicted - 1) <= 0.15);
    }
  }

  const double c =
      std::max(0.0, *std::max_element(deficits[0].begin(), deficits[0].end())) / radii[0];
  for (std::size_t ri = 0; ri < radii.size(); ++ri) {
    for (double deficit : deficits[ri]) {
      CAPTURE(radii[ri], deficit, c);
      REQUIRE(deficit <= c * radii[ri] + 1e-9 * mu_min);
    }
  }
  for (double eta : etas.back())
    REQUIRE(std::abs(eta / mu_min - 1) <= 0.01);

  if (std::getenv("BIREG_RATE_REPORT")) {
    std::printf("mu_min = %.6f, C = %.4f\n  r        eta(lambda = 1, 1/2, 1/4 of 1/mu_max)\n",
                mu_min, c);
    for (std::size_t ri = 0; ri < radii.size(); ++ri) {
      std::printf("  %-7g", radii[ri]);
      for (double eta : etas[ri])
        std::printf("  %.6f", eta);
      std::printf("\n");
    }
  }
}

// ---------------------------------------------------------------------------
// 5. Noise-free recovery and the estimating equations
// ---------------------------------------------------------------------------

// Data exactly on a geodesic (to rounding): the estimator is that geodesic.
// With tolerance 1e-14 on the step, the endpoints are within ~1e-14 of the
// fixed point; the data themselves carry ~1e-16 rounding, so 1e-12 holds
// with two orders of margin. At the returned endpoints the estimating
// equations hold: lambda ||v|| is the next step, below the tolerance.
template <class G>
void check_noise_free_recovery(std::mt19937& rng, double length, bireg::Solver solver) {
  using Tangent = typename G::Tangent;
  const typename G::Element g0 = G::exp(random_tangent<Tangent>(rng, 1.2));
  Tangent x = random_tangent<Tangent>(rng, 1.0);
  x *= length / x.norm();
  const Data<G> data = geodesic_data<G>(g0, x, 50, 0.0, rng);
  typename bireg::GeodesicRegression<G>::Options options;
  options.solver = solver;
  options.tolerance = 1e-14;
  const auto result = bireg::GeodesicRegression<G>(options).fit(data.f, data.t);
  REQUIRE(result.ok());
  REQUIRE(relative_error(result.geodesic->start(), g0) <= 1e-12);
  REQUIRE(relative_error(result.geodesic->end(), bireg::exp_at<G>(g0, x)) <= 1e-12);
  REQUIRE(result.diagnostics.residual_rms <= 1e-12);
  REQUIRE(std::abs(result.diagnostics.explained_variance - 1) <= 1e-12);
}

TEST_CASE("noise-free geodesics are recovered to 1e-12", "[regression]") {
  std::mt19937 rng(51);
  for (bireg::Solver solver : kAllSolvers) {
    for (double length : {1e-3, 0.5, 2.0, 3.0}) {
      CAPTURE(bireg::to_string(solver), length);
      check_noise_free_recovery<bireg::SO3<double>>(rng, length, solver);
      check_noise_free_recovery<bireg::SE3<double>>(rng, length, solver);
      check_noise_free_recovery<bireg::SE2<double>>(rng, length, solver);
    }
  }
}

// The weighted net force of Definition 2.1 (Section 2.2) at the endpoints
// (g0, g1), computed independently of the library's moment form and closed
// forms: residuals and psi in long double, psi by its series to order 64
// (below 2^-64 relative at these angles).
template <class G>
long double reference_force_norm(const Data<G>& data, const std::vector<double>& w,
                                 const typename G::Element& g0, const typename G::Element& g1) {
  using GL = bireg::SE3<long double>;
  const GL::Element h0 = g0.template cast<long double>(), h1 = g1.template cast<long double>();
  const GL::Tangent x = GL::log(GL::compose(GL::inverse(h0), h1));
  const GL::AdMatrix a = GL::ad(x);
  const auto [t_min, t_max] = std::minmax_element(data.t.begin(), data.t.end());
  GL::Tangent v0 = GL::Tangent::Zero(), v1 = GL::Tangent::Zero();
  for (std::size_t i = 0; i < data.f.size(); ++i) {
    const long double t = (data.t[i] - *t_min) / (long double)(*t_max - *t_min);
    const GL::Element b = GL::compose(h0, GL::exp(t * x));
    const GL::Tangent r =
        GL::log(GL::compose(GL::inverse(b), data.f[i].template cast<long double>()));
    v0 += w[i] * bireg::apply_psi_series<long double, 6>(GL::AdMatrix(-a), 1 - t, r, 64);
    v1 += w[i] * bireg::apply_psi_series<long double, 6>(a, t, r, 64);
  }
  return std::sqrt(v0.squaredNorm() + v1.squaredNorm());
}

// With noise and unequal weights, at the returned solution, the
// independently computed force is as small as the stopping rule promises:
// for the paper's step ||v|| <= tolerance mu_max (v / mu_max is what the
// tolerance bounds); for Gauss-Newton ||v|| <= ||K|| tolerance, ||K|| <=
// 2 mu_max here. Rounding of the sums adds ~N eps = 2e-14. A fit that drops
// the weights from one term of the force, or mixes up psi's argument, misses
// the weighted equations by ~1e-2 (found by planting those bugs).
TEST_CASE("the estimating equations hold at the solution", "[regression]") {
  using G = bireg::SE3<double>;
  std::mt19937 rng(52);
  const G::Element g0 = G::exp(random_tangent<G::Tangent>(rng, 1.0));
  const Data<G> data = geodesic_data<G>(g0, random_tangent<G::Tangent>(rng, 1.0), 100, 0.1, rng);
  std::uniform_real_distribution<double> weight(0.2, 2.0);
  std::vector<double> w(data.f.size());
  for (double& wi : w)
    wi = weight(rng);
  for (bireg::Method method : {bireg::Method::exact, bireg::Method::series_adaptive}) {
    for (bireg::Solver solver : {bireg::Solver::paper, bireg::Solver::gauss_newton}) {
      CAPTURE(bireg::to_string(method), bireg::to_string(solver));
      const auto options = options_for<G>(solver, method);
      const auto fitted = bireg::GeodesicRegression<G>(options).fit(data.f, data.t, w);
      REQUIRE(fitted.ok());
      const long double force =
          reference_force_norm<G>(data, w, fitted.geodesic->start(), fitted.geodesic->end());
      // Weights enter divided by the largest (problem.hpp): the force is too.
      const double w_max = *std::max_element(w.begin(), w.end());
      REQUIRE(force / w_max <= 2 * options.tolerance * fitted.diagnostics.mu_max + 2e-14);
    }
  }
  bireg::GeodesicRegression<G>::Options options;
  options.solver = bireg::Solver::paper;
  const auto result = bireg::GeodesicRegression<G>(options).fit(data.f, data.t);
  REQUIRE(result.ok());
  REQUIRE(result.residuals.size() == data.f.size());
  // Residual RMS of uniform noise on [-0.1, 0.1] in 6 coordinates is
  // sqrt(6 * 0.1^2 / 3) = 0.141; the fit absorbs 12 of 600 degrees of
  // freedom, so the RMS lies within a few percent of that.
  REQUIRE(std::abs(result.diagnostics.residual_rms / std::sqrt(0.02) - 1) <= 0.1);
}

// The adaptive series and the closed form evaluate the same estimating
// equations to rounding, so their fixed points agree to the fits' own
// tolerance (1e-13 -> 1e-10 on the endpoints), on long geodesics too.
TEST_CASE("exact and adaptive-series methods give the same estimator", "[regression]") {
  std::mt19937 rng(54);
  for (double length : {0.1, 1.0, 2.5, 3.1}) {
    using G = bireg::SE3<double>;
    G::Tangent x = random_tangent<G::Tangent>(rng, 1.0);
    x.tail<3>() *= length / x.tail<3>().norm();
    const Data<G> data =
        geodesic_data<G>(G::exp(random_tangent<G::Tangent>(rng, 1.0)), x, 60, 0.05, rng);
    auto exact_options = options_for<G>(bireg::Solver::gauss_newton, bireg::Method::exact);
    auto series_options =
        options_for<G>(bireg::Solver::gauss_newton, bireg::Method::series_adaptive);
    exact_options.tolerance = series_options.tolerance = 1e-13;
    const auto exact = bireg::GeodesicRegression<G>(exact_options).fit(data.f, data.t);
    const auto series = bireg::GeodesicRegression<G>(series_options).fit(data.f, data.t);
    CAPTURE(length);
    REQUIRE(exact.ok());
    REQUIRE(series.ok());
    REQUIRE(relative_error(exact.geodesic->start(), series.geodesic->start()) <= 1e-10);
    REQUIRE(relative_error(exact.geodesic->end(), series.geodesic->end()) <= 1e-10);
  }
}

// Every solver has the same fixed point: run to tolerance 1e-13 (within
// ~1e-12 of it), they agree to 1e-10 on long, noisy geodesics, and the
// fast ones need far fewer steps.
TEST_CASE("every solver converges to the same estimator", "[regression]") {
  using G = bireg::SE3<double>;
  std::mt19937 rng(53);
  for (double length : {0.3, 1.0, 2.5}) {
    G::Tangent x = random_tangent<G::Tangent>(rng, 1.0);
    x.tail<3>() *= length / x.tail<3>().norm();
    const Data<G> data =
        geodesic_data<G>(G::exp(random_tangent<G::Tangent>(rng, 1.0)), x, 100, 0.1, rng);
    std::vector<bireg::GeodesicRegression<G>::Result> results;
    for (bireg::Solver solver : kAllSolvers) {
      bireg::GeodesicRegression<G>::Options options;
      options.solver = solver;
      options.tolerance = 1e-13;
      results.push_back(bireg::GeodesicRegression<G>(options).fit(data.f, data.t));
      CAPTURE(length, bireg::to_string(solver));
      REQUIRE(results.back().ok());
      REQUIRE(relative_error(results.back().geodesic->start(), results.front().geodesic->start()) <=
              1e-10);
      REQUIRE(relative_error(results.back().geodesic->end(), results.front().geodesic->end()) <=
              1e-10);
    }
    CAPTURE(length, results[0].iterations, results[3].iterations);
    REQUIRE(8 * results[3].iterations <= results[0].iterations);  // gauss_newton vs paper
    REQUIRE(results[2].iterations < results[0].iterations);       // preconditioned vs paper
  }
}

// The iteration limit and a geodesic too long for the series are reported
// in the status, with finite endpoints.
// The universal cover of SE(2): the angle is a real number, not an angle
// modulo 2 pi, so the logarithm is unbounded and ad_X can reach spectral
// radius 2 pi. Only a test group: it shows what the regression does when a
// group's data leave the series' disc of convergence.
struct CoverSE2 {
  using Scalar = double;
  static constexpr int dof = 3;
  static constexpr const char* name = "CoverSE2";
  using Element = Eigen::Vector3d;  // (x, y, theta), theta unbounded
  using Tangent = Eigen::Vector3d;
  using AdMatrix = Eigen::Matrix3d;
  using Algebra = Eigen::Matrix3d;
  using Planar = bireg::SE2<double>;
  static Eigen::Matrix3d matrix(const Element& g) {
    Eigen::Matrix3d m = Planar::exp(Tangent(0, 0, g[2]));
    m.topRightCorner<2, 1>() = g.head<2>();
    return m;
  }
  static Element element(const Eigen::Matrix3d& m, double theta) {
    return Element(m(0, 2), m(1, 2), theta);
  }
  static Element identity() { return Element::Zero(); }
  static Element compose(const Element& a, const Element& b) {
    return element(matrix(a) * matrix(b), a[2] + b[2]);
  }
  static Element inverse(const Element& g) { return element(Planar::inverse(matrix(g)), -g[2]); }
  static Element exp(const Tangent& x) { return element(Planar::exp(x), x[2]); }
  static Tangent log(const Element& g) {
    const double diagonal = bireg::small_angle::half_x_cot_half_x(g[2]);
    const double half = g[2] / 2;
    return Tangent(diagonal * g[0] + half * g[1], -half * g[0] + diagonal * g[1], g[2]);
  }
  static Algebra hat(const Tangent& x) { return Planar::hat(x); }
  static Tangent vee(const Algebra& m) { return Planar::vee(m); }
  static AdMatrix ad(const Tangent& x) { return Planar::ad(x); }
  static AdMatrix Ad(const Element& g) { return Planar::Ad(matrix(g)); }
  static bool is_element(const Element& g, double) { return g.allFinite(); }
};
}  // namespace

// beyond_domain is documented as "the largest residual angle exceeds
// 3 pi / 4" (regression/diagnostics.hpp). An exact geodesic of 41 rotations
// turning by 1 rad, with the middle one turned away from it by `offset`
// about a perpendicular axis: a least-squares line moves towards an outlier
// by its leverage, 1/41 in the middle, so the outlier's residual is about
// offset (1 - 1/41) and every other residual is far smaller. Offsets
// 0.70 pi and 0.85 pi put that residual at 0.683 pi and 0.829 pi (measured;
// the bands below only check it landed there), so a threshold moved out of
// (0.683 pi, 0.829 pi), to 0.95 pi say, or pi/2, fails one of the flags.
TEST_CASE("beyond_domain flags a residual angle beyond 3 pi / 4, not below",
          "[regression][diagnostics]") {
  using G = bireg::SO3<double>;
  const double pi = 3.14159265358979323846;
  const auto fit_with_outlier = [](double offset) {
    std::vector<G::Element> f;
    std::vector<double> t;
    for (int i = 0; i <= 40; ++i) {
      const double s = i / 40.0;
      G::Element g = G::exp(G::Tangent(0, 0, s));
      if (i == 20) g = G::compose(g, G::exp(G::Tangent(offset, 0, 0)));
      f.push_back(g);
      t.push_back(s);
    }
    return bireg::GeodesicRegression<G>().fit(f, t);
  };
  const auto inside = fit_with_outlier(0.70 * pi);
  REQUIRE(inside.ok());
  CAPTURE(inside.diagnostics.largest_residual_angle / pi);
  REQUIRE(inside.diagnostics.largest_residual_observation == 20);
  REQUIRE(inside.diagnostics.largest_residual_angle > 0.60 * pi);
  REQUIRE(inside.diagnostics.largest_residual_angle < 0.72 * pi);
  REQUIRE_FALSE(inside.diagnostics.beyond_domain);

  const auto beyond = fit_with_outlier(0.85 * pi);
  REQUIRE(beyond.ok());
  CAPTURE(beyond.diagnostics.largest_residual_angle / pi);
  REQUIRE(beyond.diagnostics.largest_residual_observation == 20);
  REQUIRE(beyond.diagnostics.largest_residual_angle > 0.78 * pi);
  REQUIRE(beyond.diagnostics.largest_residual_angle < 0.90 * pi);
  REQUIRE(beyond.diagnostics.beyond_domain);
}

TEST_CASE("non-convergence is reported in the status, with finite endpoints",
          "[regression][errors]") {
  SECTION("iteration limit") {
    using G = bireg::SE3<double>;
    std::mt19937 rng(62);
    const Data<G> data =
        geodesic_data<G>(G::identity(), random_tangent<G::Tangent>(rng, 1.0), 20, 0.1, rng);
    bireg::GeodesicRegression<G>::Options options;
    options.max_iterations = 3;
    const auto result = bireg::GeodesicRegression<G>(options).fit(data.f, data.t);
    REQUIRE(result.status == bireg::Status::max_iterations);
    REQUIRE(result.iterations == 3);
    REQUIRE(result.step_norms.size() == 3);
    REQUIRE(all_finite<G>(result));
  }
  SECTION("divergence of the paper's step") {
    // 6 rad of rotation on the universal cover (inside the series' disc),
    // noisy, with lambda = 1.9 / mu_max: the linear part contracts by
    // |1 - 1.9| = 0.9 in the fast direction, and the curvature term tips it
    // over; the steps grow and the fit stops with `diverged`.
    using G = CoverSE2;
    std::vector<G::Element> f;
    std::vector<double> t;
    for (int i = 0; i < 20; ++i) {
      const double s = i / 19.0, noise = (i % 3 - 1) * 0.5;
      f.push_back(G::exp(G::Tangent(3 * s, 3 * noise, 6.0 * s + noise)));
      t.push_back(s);
    }
    bireg::GeodesicRegression<G>::Options options;
    options.solver = bireg::Solver::paper;
    const double mu_max = bireg::GeodesicRegression<G>(options).fit(f, t).diagnostics.mu_max;
    options.step_size = 1.9 / mu_max;
    const auto result = bireg::GeodesicRegression<G>(options).fit(f, t);
    REQUIRE(result.status == bireg::Status::diverged);
    REQUIRE(result.geodesic->start().allFinite());
    REQUIRE(result.geodesic->end().allFinite());
    REQUIRE(std::isfinite(result.diagnostics.residual_rms));
  }
  SECTION("geodesic beyond the series' radius of convergence") {
    using G = CoverSE2;
    STATIC_REQUIRE(bireg::is_lie_group_v<G>);
    std::vector<G::Element> f;
    std::vector<double> t;
    for (int i = 0; i < 20; ++i) {
      const double s = i / 19.0;
      f.push_back(G::exp(G::Tangent(1.0 * s, 0.5, 8.0 * s)));  // 8 rad > 2 pi of rotation
      t.push_back(s);
    }
    // The least-squares start lies beyond the disc, so the fit restarts
    // from the middle observation. The paper's unguarded step then walks
    // out of the disc and stops with series_diverged; Gauss-Newton's
    // safeguard refuses every step that would leave it and stops with
    // no_descent. Both return the last endpoints inside the disc.
    bireg::GeodesicRegression<G>::Options paper;
    paper.solver = bireg::Solver::paper;
    const auto unguarded = bireg::GeodesicRegression<G>(paper).fit(f, t);
    const auto guarded = bireg::GeodesicRegression<G>().fit(f, t);
    REQUIRE(unguarded.status == bireg::Status::series_diverged);
    REQUIRE(guarded.status == bireg::Status::no_descent);
    for (const auto* result : {&unguarded, &guarded}) {
      REQUIRE(result->geodesic->start().allFinite());
      REQUIRE(result->geodesic->end().allFinite());
      REQUIRE(bireg::ad_spectral_radius<G>(G::log(
                  G::compose(G::inverse(result->geodesic->start()), result->geodesic->end()))) <
              2 * 3.141592653589793);
      REQUIRE(std::isfinite(result->diagnostics.residual_rms));
    }
  }
}

// Duplicated covariates are allowed (several observations at one time), and
// the order of the observations does not matter: a permutation changes only
// the order of the sums. Run to tolerance 1e-14 (the returned endpoints are
// then within ~1e-14 of the fixed point, not 1e-10), they agree to 1e-12.
TEST_CASE("duplicated covariates are allowed and the order of observations does not matter",
          "[regression]") {
  using G = bireg::SE3<double>;
  std::mt19937 rng(55);
  Data<G> data = geodesic_data<G>(G::exp(random_tangent<G::Tangent>(rng, 1.0)),
                                  random_tangent<G::Tangent>(rng, 0.8), 30, 0.05, rng);
  for (int i = 0; i < 10; ++i)
    data.t[i + 10] = data.t[10];  // ten observations share one time
  bireg::GeodesicRegression<G>::Options options;
  options.tolerance = 1e-14;
  const bireg::GeodesicRegression<G> regression(options);
  const auto base = regression.fit(data.f, data.t);
  REQUIRE(base.ok());
  std::vector<std::size_t> order(data.f.size());
  for (std::size_t i = 0; i < order.size(); ++i)
    order[i] = i;
  std::shuffle(order.begin(), order.end(), rng);
  Data<G> shuffled;
  for (std::size_t i : order) {
    shuffled.f.push_back(data.f[i]);
    shuffled.t.push_back(data.t[i]);
  }
  const auto permuted = regression.fit(shuffled.f, shuffled.t);
  REQUIRE(permuted.ok());
  REQUIRE(relative_error(permuted.geodesic->start(), base.geodesic->start()) <= 1e-12);
  REQUIRE(relative_error(permuted.geodesic->end(), base.geodesic->end()) <= 1e-12);
  for (std::size_t k = 0; k < order.size(); ++k) {
    REQUIRE(relative_error(permuted.residuals[k], base.residuals[order[k]]) <= 1e-10);
  }
}

// ---------------------------------------------------------------------------
// 6. Bad input
// ---------------------------------------------------------------------------

TEST_CASE("bad input is rejected with a message naming the problem", "[regression][errors]") {
  using G = bireg::SO3<double>;
  using Regression = bireg::GeodesicRegression<G>;
  std::mt19937 rng(61);
  const Data<G> good = geodesic_data<G>(G::identity(), G::Tangent(0.3, 0.2, 0.1), 10, 0.05, rng);

  const auto expect_rejection = [](const Regression::Result& result, const std::string& words,
                                   std::ptrdiff_t index) {
    CAPTURE(result.message);
    REQUIRE(result.status == bireg::Status::invalid_input);
    REQUIRE_FALSE(result.ok());
    REQUIRE(result.message.find(words) != std::string::npos);
    REQUIRE(result.bad_index == index);
    REQUIRE(all_finite<G>(result));
    REQUIRE(result.iterations == 0);
  };

  SECTION("mismatched lengths") {
    std::vector<double> t = good.t;
    t.pop_back();
    expect_rejection(Regression().fit(good.f, t), "differ in length", -1);
  }
  SECTION("fewer than two observations") {
    const std::vector<G::Element> f = {good.f[0]};
    const std::vector<double> t = {1.0};
    expect_rejection(Regression().fit(f, t), "at least 2 observations", -1);
  }
  SECTION("all covariates equal") {
    const std::vector<double> t(good.f.size(), 3.0);
    expect_rejection(Regression().fit(good.f, t), "not identifiable", -1);
  }
  SECTION("non-finite covariate") {
    std::vector<double> t = good.t;
    t[4] = std::numeric_limits<double>::quiet_NaN();
    expect_rejection(Regression().fit(good.f, t), "covariate 4 is not finite", 4);
    t[4] = std::numeric_limits<double>::infinity();
    expect_rejection(Regression().fit(good.f, t), "covariate 4 is not finite", 4);
  }
  SECTION("non-finite matrix entry") {
    std::vector<G::Element> f = good.f;
    f[7](1, 2) = std::numeric_limits<double>::quiet_NaN();
    expect_rejection(Regression().fit(f, good.t), "observation 7 has non-finite entries", 7);
  }
  SECTION("element not in the group") {
    std::vector<G::Element> f = good.f;
    f[3] *= 1.01;
    expect_rejection(Regression().fit(f, good.t), "observation 3 is not an element of SO3", 3);
  }
  SECTION("negative weight") {
    std::vector<double> weights(good.f.size(), 1.0);
    weights[2] = -0.5;
    expect_rejection(Regression().fit(good.f, good.t, weights), "weight 2 is negative", 2);
  }
  SECTION("weights of the wrong length") {
    const std::vector<double> weights(good.f.size() + 1, 1.0);
    expect_rejection(Regression().fit(good.f, good.t, weights), "weights and observations", -1);
  }
  SECTION("weight only on one covariate") {
    std::vector<double> weights(good.f.size(), 0.0);
    weights[5] = 1.0;
    expect_rejection(Regression().fit(good.f, good.t, weights), "not identifiable", -1);
  }
  SECTION("step size at or above 2 / mu_max") {
    const auto probe = Regression().fit(good.f, good.t);
    REQUIRE(probe.ok());
    Regression::Options options;
    options.solver = bireg::Solver::paper;
    options.step_size = 2 / probe.diagnostics.mu_max;
    expect_rejection(Regression(options).fit(good.f, good.t), "no longer contracts", -1);
    options.step_size = -1;
    expect_rejection(Regression(options).fit(good.f, good.t), "step_size", -1);
    options.solver = bireg::Solver::gauss_newton;
    options.step_size = 0.5 / probe.diagnostics.mu_max;
    expect_rejection(Regression(options).fit(good.f, good.t), "paper solver only", -1);
  }
  SECTION("initial guess off the group") {
    const Regression::Endpoints start(G::Element(2 * G::identity()), G::identity());
    expect_rejection(Regression().fit_from(start, good.f, good.t), "the start is not", -1);
  }
  SECTION("invalid options") {
    Regression::Options options;
    options.max_iterations = 0;
    expect_rejection(Regression(options).fit(good.f, good.t), "max_iterations", -1);
    options = Regression::Options();
    options.series_order = bireg::kMaxSeriesOrder + 1;
    expect_rejection(Regression(options).fit(good.f, good.t), "series_order", -1);
    options = Regression::Options();
    options.tolerance = std::numeric_limits<double>::quiet_NaN();
    expect_rejection(Regression(options).fit(good.f, good.t), "tolerance", -1);
  }
}
