// Deterministic threads: the same fit with 1, 2 and 7 threads returns
// bit-identical endpoints, residuals, step norms and diagnostics, for a
// fit spanning several chunks (parallel.hpp) and for a small one, on both
// evaluations of the force (closed form and series). The trend test's
// permutations and the local regression's queries (with its
// leave-one-out errors) give identical results for 1, 2 and 7 threads. A
// thread count below 1 is refused with a message, by each.
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <cmath>

#include "bireg/groups/se3.hpp"
#include "bireg/groups/so3.hpp"
#include "bireg/regression.hpp"
#include "bireg/statistics/inference/trend_test.hpp"
#include "bireg/statistics/selection/model_selection.hpp"
#include "bireg/statistics/smoothing/local_regression.hpp"
#include "catch.hpp"
#include "test_support.hpp"

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
  REQUIRE(a.diagnostics.residual_rms_about_mean == b.diagnostics.residual_rms_about_mean);
  REQUIRE(a.diagnostics.largest_residual_angle == b.diagnostics.largest_residual_angle);
  REQUIRE(a.diagnostics.largest_residual_observation == b.diagnostics.largest_residual_observation);
  REQUIRE(a.diagnostics.beyond_domain == b.diagnostics.beyond_domain);
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

// The observation check and the chart pass run by chunks of 4096 on the
// pool: with bad observations in two chunks, the fit names the first, as a
// serial scan would, whatever the thread count.
TEST_CASE("the first bad observation is named for 1, 2 and 7 threads", "[threads]") {
  std::vector<G::Element> good;
  std::vector<double> t;
  make_observations(20000, good, t);
  const auto first_failure = [&](const std::vector<G::Element>& f, const std::string& problem) {
    for (const int threads : {1, 2, 7}) {
      CAPTURE(threads, problem);
      Regression::Options options;
      options.threads = threads;
      const auto result = Regression(options).fit(f, t);
      REQUIRE(result.status == bireg::Status::invalid_input);
      REQUIRE(result.bad_index == 9000);
      REQUIRE(result.message.rfind("observation 9000 " + problem, 0) == 0);
    }
  };
  std::vector<G::Element> f = good;
  f[9000].topLeftCorner<3, 3>() *= 1.5;  // not a rotation
  f[15000](0, 3) = std::nan("");
  first_failure(f, "is not an element of SE3");
  f = good;
  f[9000](1, 3) = std::numeric_limits<double>::infinity();
  f[15000].topLeftCorner<3, 3>() *= 1.5;
  first_failure(f, "has non-finite entries");
  f = good;  // elements, but 1e200 away from the middle observation: the chart's check
  f[9000](2, 3) = 1e200;
  f[15000](2, 3) = 1e200;
  first_failure(f, "lies too far from the middle observation");
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

// A weak trend (0.3 rad over the interval against noise 0.2 rad), so that
// the permuted statistics straddle the observed one and a change in any
// verdict moves the p-value.
TEST_CASE("the trend test is identical for 1, 2 and 7 threads", "[threads]") {
  std::mt19937 rng(23);
  std::normal_distribution<double> normal(0.0, 0.2);
  std::vector<G::Element> f;
  std::vector<double> t;
  for (int i = 0; i < 40; ++i) {
    G::Tangent noise;
    for (int k = 0; k < G::dof; ++k)
      noise[k] = normal(rng);
    t.push_back(i / 39.0);
    f.push_back(G::exp(t.back() * 0.3 * G::Tangent::Ones() / std::sqrt(6.0) + noise));
  }
  const Regression regression;
  bireg::TrendTestOptions options;
  options.permutations = 199;
  options.seed = 11;
  const auto serial = bireg::trend_test(regression, f, t, {}, options);
  REQUIRE(serial.ok());
  REQUIRE(serial.p_value > 0.01);  // the verdicts are mixed
  REQUIRE(serial.p_value < 0.99);
  for (const int threads : {2, 7}) {
    CAPTURE(threads);
    options.threads = threads;
    const auto parallel = bireg::trend_test(regression, f, t, {}, options);
    REQUIRE(parallel.ok());
    REQUIRE(parallel.statistic == serial.statistic);
    REQUIRE(parallel.at_least_as_extreme == serial.at_least_as_extreme);
    REQUIRE(parallel.failed_permutations == serial.failed_permutations);
    REQUIRE(parallel.p_value == serial.p_value);
  }
  options.threads = 0;
  const auto refused = bireg::trend_test(regression, f, t, {}, options);
  REQUIRE(refused.status == bireg::Status::invalid_input);
  REQUIRE(refused.message == "threads must be at least 1, got 0");
}

// 2500 SO(3) samples (test_support.hpp): three blocks of queries (1024 each), so the threads
// share them out.
TEST_CASE("the local regression is identical for 1, 2 and 7 threads", "[threads]") {
  using SO3 = bireg::SO3<double>;
  const bireg_test::So3Trajectory data = bireg_test::dense_so3_trajectory(2500, 0.01, 29);
  const std::vector<SO3::Element>& f = data.f;
  const std::vector<double>& t = data.t;
  bireg::LocalRegressionOptions<double> options;
  options.bandwidth = 2.5e-3;
  const auto serial = bireg::LocalGeodesicRegression<SO3>(options).smooth(f, t);
  std::string serial_problem;
  const auto serial_errors =
      bireg::LocalGeodesicRegression<SO3>(options).leave_one_out(f, t, serial_problem);
  REQUIRE(serial_problem.empty());
  for (const int threads : {2, 7}) {
    CAPTURE(threads);
    options.threads = threads;
    const bireg::LocalGeodesicRegression<SO3> smoother(options);
    const auto parallel = smoother.smooth(f, t);
    REQUIRE(parallel.size() == serial.size());
    for (std::size_t q = 0; q < serial.size(); ++q) {
      REQUIRE(parallel[q].ok());
      REQUIRE(parallel[q].pose == serial[q].pose);
      REQUIRE(parallel[q].velocity == serial[q].velocity);
      REQUIRE(parallel[q].velocity_error == serial[q].velocity_error);
      REQUIRE(parallel[q].iterations == serial[q].iterations);
    }
    std::string problem;
    const auto errors = smoother.leave_one_out(f, t, problem);
    REQUIRE(problem.empty());
    REQUIRE(errors == serial_errors);
  }
  options.threads = 0;
  const auto refused = bireg::LocalGeodesicRegression<SO3>(options).smooth(f, t);
  REQUIRE(refused[0].message == "threads must be at least 1, got 0");
}

// The motion-model candidates and their (candidate, fold) cross-validation
// fits run as tasks: every number of the selection must be the serial one,
// and the static-or-geodesic selection likewise.
TEST_CASE("model selection is identical for 1, 2 and 7 threads", "[threads]") {
  std::vector<G::Element> f;
  std::vector<double> t;
  make_observations(120, f, t);
  bireg::ModelSelectionOptions options;
  const bireg::ModelSelection serial = bireg::select_motion_model(f, t, options);
  REQUIRE(serial.recommended);
  const auto trend_serial = bireg::select_static_or_geodesic<G>(f, t, options);
  REQUIRE(trend_serial.recommended);
  for (const int threads : {2, 7}) {
    CAPTURE(threads);
    options.threads = threads;
    const bireg::ModelSelection parallel = bireg::select_motion_model(f, t, options);
    REQUIRE(parallel.recommended == serial.recommended);
    REQUIRE(parallel.ambiguous == serial.ambiguous);
    REQUIRE(parallel.candidates.size() == serial.candidates.size());
    for (std::size_t c = 0; c < serial.candidates.size(); ++c) {
      const bireg::CandidateReport& a = parallel.candidates[c];
      const bireg::CandidateReport& b = serial.candidates[c];
      REQUIRE(a.model == b.model);
      REQUIRE(a.fitted == b.fitted);
      REQUIRE(a.note == b.note);
      REQUIRE(a.log_det == b.log_det);
      REQUIRE(a.criterion == b.criterion);
      REQUIRE(a.rotation_rms_degrees == b.rotation_rms_degrees);
      REQUIRE(a.translation_rms == b.translation_rms);
      REQUIRE(a.cv_error.has_value());
      REQUIRE(a.cv_error == b.cv_error);
    }
    const auto trend_parallel = bireg::select_static_or_geodesic<G>(f, t, options);
    REQUIRE(trend_parallel.recommended == trend_serial.recommended);
    for (std::size_t c = 0; c < trend_serial.candidates.size(); ++c) {
      REQUIRE(trend_parallel.candidates[c].criterion == trend_serial.candidates[c].criterion);
      REQUIRE(trend_parallel.candidates[c].cv_error == trend_serial.candidates[c].cv_error);
    }
  }
  options.threads = 0;
  REQUIRE(bireg::select_motion_model(f, t, options).message == "threads must be at least 1, got 0");
  REQUIRE(bireg::select_static_or_geodesic<G>(f, t, options).message ==
          "threads must be at least 1, got 0");
}
