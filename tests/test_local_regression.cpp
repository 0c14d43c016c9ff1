// Local geodesic regression (statistics/smoothing/local_regression.hpp): textbook
// local-linear regression on R^n, exact recovery of noise-free geodesics,
// the global fit as the bandwidth grows, left and right equivariance,
// independence of the queries' order, real IMU data turning through more
// than pi, and the reported failure of an empty window.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <random>
#include <vector>

#include <Eigen/Core>
#include <Eigen/LU>

#include "bireg/groups/rn.hpp"
#include "bireg/groups/so3.hpp"
#include "bireg/io/formats.hpp"
#include "bireg/regression.hpp"
#include "bireg/statistics/smoothing/local_regression.hpp"
#include "catch.hpp"
#include "test_support.hpp"

namespace {

using R2 = bireg::Rnd<2>;
using SO3 = bireg::SO3d;

const bireg::Kernel kKernels[] = {bireg::Kernel::gaussian, bireg::Kernel::epanechnikov,
                                  bireg::Kernel::tricube};

template <class G>
bireg::LocalRegressionOptions<double> local_options(bireg::Kernel kernel, double bandwidth) {
  bireg::LocalRegressionOptions<double> options;
  options.kernel = kernel;
  options.bandwidth = bandwidth;
  return options;
}

// Irregular covariates on [0, 1].
std::vector<double> irregular_covariates(std::mt19937& rng, int n) {
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::vector<double> t(static_cast<std::size_t>(n));
  for (double& value : t)
    value = uniform(rng);
  return t;
}

}  // namespace

// The pose is the local line's value; the velocity is the slope of the
// local polynomial of degree velocity_degree (1, the line; 2, the default
// quadratic; 3, the cubic), exactly, as DESIGN.md section 5 derives.
TEST_CASE("On R^2 the local fit is local-linear, its velocity local-polynomial, least squares") {
  std::mt19937 rng(14);
  const std::vector<double> t = irregular_covariates(rng, 60);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<R2::Element> f;
  for (const double ti : t)
    f.push_back(R2::Element(std::sin(6 * ti) + 0.1 * normal(rng), ti * ti));
  constexpr double kBandwidth = 0.15;
  for (const bireg::Kernel kernel : kKernels) {
    for (const int degree : {1, 2, 3}) {
      bireg::LocalRegressionOptions<double> options = local_options<R2>(kernel, kBandwidth);
      options.velocity_degree = degree;
      const auto estimates = bireg::LocalGeodesicRegression<R2>(options).smooth(f, t);
      for (std::size_t q = 0; q < t.size(); ++q) {
        // min sum w_i |f_i - sum_k c_k v_i^k|^2, v_i = (t_i - tau) / h,
        // k = 0..degree: the normal equations of the line and of the
        // polynomial, in v for conditioning (the slope is c_1 / h).
        const double tau = t[q];
        const int size = degree + 1;
        Eigen::MatrixXd normal_matrix = Eigen::MatrixXd::Zero(size, size);
        Eigen::MatrixXd right = Eigen::MatrixXd::Zero(size, 2);
        for (std::size_t i = 0; i < t.size(); ++i) {
          const double w = bireg::kernel_weight(kernel, (t[i] - tau) / kBandwidth);
          const double v = (t[i] - tau) / kBandwidth;
          Eigen::VectorXd design(size);
          for (int k = 0; k < size; ++k)
            design[k] = std::pow(v, k);
          normal_matrix += w * design * design.transpose();
          right += w * design * f[i].transpose();
        }
        const Eigen::Matrix2d line = normal_matrix.topLeftCorner(2, 2).lu().solve(right.topRows(2));
        const Eigen::MatrixXd polynomial = normal_matrix.lu().solve(right);
        const Eigen::Vector2d slope = polynomial.row(1).transpose() / kBandwidth;
        INFO("kernel " << bireg::to_string(kernel) << " degree " << degree << " query " << q);
        REQUIRE(estimates[q].ok());
        // Values O(1), N = 60 sums: the solutions differ by rounding,
        // ~1e-14 for the line; bireg scales u by the window's half-width
        // (up to 4h), so its normal matrix has moments down to 4^-6 ~ 2e-4
        // and a condition up to ~1e6, hence 1e-9 for the polynomials' slope.
        CHECK((estimates[q].pose - line.row(0).transpose()).norm() < 1e-12);
        CHECK((estimates[q].velocity - slope).norm() < (degree > 1 ? 1e-9 : 1e-11));
      }
    }
  }
}

// The cubic removes the interior bias that the quadratic leaves: on a
// rotation about a fixed axis whose angle is a cubic in t, noise-free, the
// residuals of the local line are exactly cubic, so the local cubic's
// slope is the rate (to rounding), where the quadratic's is off by the
// angle's third derivative times h^2 / 2 in the interior (the Gaussian's
// E s^4 / E s^2 = 3 h^2, divided by 3!).
TEST_CASE("A cubic angle's rate: exact with the local cubic, biased with the quadratic") {
  const double a = 0.4, b = -0.6, c = 1.5;  // theta(t) = a t + b t^2 + c t^3
  const SO3::Tangent axis = SO3::Tangent(1, 2, 2) / 3;
  std::vector<double> t;
  std::vector<SO3::Element> f;
  for (int i = 0; i <= 100; ++i) {
    t.push_back(i / 100.0);
    const double theta = a * t.back() + b * t.back() * t.back() + c * std::pow(t.back(), 3);
    f.push_back(SO3::exp(theta * axis));
  }
  constexpr double kBandwidth = 0.05;
  const double interior_bias = 6 * c * kBandwidth * kBandwidth / 2;  // 0.011 rad/s
  for (const int degree : {2, 3}) {
    bireg::LocalRegressionOptions<double> options =
        local_options<SO3>(bireg::Kernel::gaussian, kBandwidth);
    options.velocity_degree = degree;
    const auto estimates = bireg::LocalGeodesicRegression<SO3>(options).smooth(f, t);
    for (std::size_t q = 0; q < t.size(); ++q) {
      REQUIRE(estimates[q].ok());
      const double rate = a + 2 * b * t[q] + 3 * c * t[q] * t[q];
      const double off = (estimates[q].velocity - rate * axis).norm();
      INFO("degree " << degree << " query " << q << ": off by " << off);
      if (degree == 3) {
        // Rounding: the residuals are ~1e-4 rad, their slope's rounding
        // ~1e-16 / h times the design's condition ~1e6.
        CHECK(off < 1e-8);
      } else if (q >= 20 && q <= 80) {  // the interior: 4 bandwidths in
        CHECK(std::abs(off - interior_bias) < 0.1 * interior_bias);
      }
    }
  }
}

// select_bandwidth's cubic curve comes from the quadratic's held-out fits
// (held_out with `cubic`): the same errors and c_i as separate passes of a
// quadratic and of a cubic smoother. Both regress the same local
// geodesic's residuals; the shared pass rebuilds that geodesic from its
// pose and velocity, which moves the residuals by rounding (~1e-15 rad),
// their slopes by that over the window's half-width (~1e-13 rad/s), far
// below 1e-9.
TEST_CASE("The cubic's held-out velocities from the shared fits equal a cubic smoother's") {
  const bireg_test::So3Trajectory data = bireg_test::dense_so3_trajectory(300, 0.01, 17);
  for (const bireg::HoldOut mode : {bireg::HoldOut::chords, bireg::HoldOut::derivatives}) {
    auto options = local_options<SO3>(bireg::Kernel::gaussian, 0.03);
    options.standard_errors = false;
    bireg::HeldOut<SO3> cubic;
    const auto shared =
        bireg::LocalGeodesicRegression<SO3>(options).held_out(data.f, data.t, mode, &cubic);
    const auto quadratic =
        bireg::LocalGeodesicRegression<SO3>(options).held_out(data.f, data.t, mode);
    options.velocity_degree = 3;
    const auto separate =
        bireg::LocalGeodesicRegression<SO3>(options).held_out(data.f, data.t, mode);
    REQUIRE(shared.problem.empty());
    REQUIRE(cubic.problem.empty());
    REQUIRE(shared.ok == quadratic.ok);
    REQUIRE(cubic.ok == separate.ok);
    CHECK(cubic.failures == separate.failures);
    std::size_t compared = 0;
    for (std::size_t i = 0; i < data.t.size(); ++i) {
      if (!cubic.ok[i]) continue;
      ++compared;
      CHECK((shared.errors[i] - quadratic.errors[i]).norm() < 1e-9);
      CHECK((cubic.errors[i] - separate.errors[i]).norm() < 1e-9);
      CHECK(std::abs(shared.cross[i] - quadratic.cross[i]) <
            1e-9 * std::abs(quadratic.cross[i]) + 1e-12);
      CHECK(std::abs(cubic.cross[i] - separate.cross[i]) <
            1e-9 * std::abs(separate.cross[i]) + 1e-12);
      // The two degrees differ: the comparison is not of one curve with itself.
      if (i == data.t.size() / 2) CHECK((cubic.errors[i] - shared.errors[i]).norm() > 1e-6);
    }
    CHECK(compared > data.t.size() - 10);
  }
}

TEST_CASE("Noise-free geodesic data are recovered at every bandwidth") {
  std::mt19937 rng(7);
  const std::vector<double> t = irregular_covariates(rng, 80);
  const SO3::Element g0 = SO3::exp(SO3::Tangent(0.3, -1.2, 0.5));
  // 2.8 rad over the range: below pi, so every window's displacement is a
  // principal logarithm (a geodesic turning further is not one Geodesic).
  const SO3::Tangent velocity(1.5, 1.0, -2.2);
  std::vector<SO3::Element> f;
  for (const double ti : t)
    f.push_back(SO3::compose(g0, SO3::exp(ti * velocity)));
  for (const bireg::Kernel kernel : kKernels) {
    for (const double bandwidth : {0.05, 0.2, 1.0, 10.0}) {
      const bireg::LocalGeodesicRegression<SO3> smoother(local_options<SO3>(kernel, bandwidth));
      const auto estimates = smoother.smooth(f, t);
      for (std::size_t q = 0; q < t.size(); ++q) {
        INFO("kernel " << bireg::to_string(kernel) << " h " << bandwidth << " query " << q);
        if (!estimates[q].ok()) {
          // Only a window with a single covariate may fail, and says so.
          CHECK(estimates[q].window < 2);
          CHECK(!estimates[q].message.empty());
          continue;
        }
        const SO3::Element truth = SO3::compose(g0, SO3::exp(t[q] * velocity));
        // Zero residuals: the fit stops at the tolerance 1e-10 with a
        // quadratically converging step, so its error is rounding, ~1e-14
        // times the window's condition (range / spread, at most ~1e3 for
        // the narrowest windows).
        CHECK(SO3::log(SO3::compose(SO3::inverse(truth), estimates[q].pose)).norm() < 1e-10);
        CHECK((estimates[q].velocity - velocity).norm() < 1e-10);
      }
    }
  }
}

TEST_CASE("A bandwidth far past the range gives the global fit") {
  std::mt19937 rng(3);
  const std::vector<double> t = irregular_covariates(rng, 50);
  std::vector<SO3::Element> f;
  for (const double ti : t) {
    f.push_back(SO3::exp(SO3::Tangent(ti, 0.5 * ti * ti, -ti) +
                         bireg_test::random_tangent<SO3::Tangent>(rng, 0.1)));
  }
  const bireg::GeodesicRegression<SO3> global_regression;
  const auto global = global_regression.fit(f, t);
  REQUIRE(global.ok());
  // h = 1e8 ranges: 1 - K(u) <= 1e-16 / 2 for the Gaussian, 1e-16 for the
  // others, below the weights' rounding, so the local fit is the global one
  // up to the convergence tolerance (1e-10 on the step, quadratically: ~0).
  for (const bireg::Kernel kernel : kKernels) {
    bireg::LocalRegressionOptions<double> options = local_options<SO3>(kernel, 1e8);
    options.velocity_degree = 1;  // the geodesic's own velocity
    const bireg::LocalGeodesicRegression<SO3> smoother(options);
    const std::vector<double> middle{0.5};
    const auto estimates = smoother.smooth_at(f, t, middle);
    REQUIRE(estimates[0].ok());
    const SO3::Element expected = (*global.geodesic)(0.5);
    CHECK(SO3::log(SO3::compose(SO3::inverse(expected), estimates[0].pose)).norm() < 1e-12);
    CHECK((estimates[0].velocity - global.geodesic->body_velocity()).norm() < 1e-11);
  }
}

TEST_CASE("Left and right translation move poses and map velocities by Ad") {
  std::mt19937 rng(21);
  const std::vector<double> t = irregular_covariates(rng, 70);
  std::vector<SO3::Element> f;
  for (const double ti : t) {
    f.push_back(SO3::exp(SO3::Tangent(3 * ti, std::sin(5 * ti), -ti) +
                         bireg_test::random_tangent<SO3::Tangent>(rng, 0.05)));
  }
  const SO3::Element left = SO3::exp(SO3::Tangent(1.0, -2.0, 0.7));
  const SO3::Element right = SO3::exp(SO3::Tangent(-0.4, 0.9, 2.2));
  std::vector<SO3::Element> moved;
  for (const auto& fi : f)
    moved.push_back(SO3::compose(SO3::compose(left, fi), right));
  const bireg::LocalGeodesicRegression<SO3> smoother(
      local_options<SO3>(bireg::Kernel::tricube, 0.12));
  const auto original = smoother.smooth(f, t);
  const auto translated = smoother.smooth(moved, t);
  const SO3::AdMatrix ad_right_inverse = SO3::Ad(SO3::inverse(right));
  for (std::size_t q = 0; q < t.size(); ++q) {
    INFO("query " << q);
    REQUIRE(original[q].ok());
    REQUIRE(translated[q].ok());
    const SO3::Element expected = SO3::compose(SO3::compose(left, original[q].pose), right);
    // Rounding of the translated data (~1e-16) amplified by the windows'
    // conditioning and Gauss-Newton stopping at 1e-10: 1e-10.
    CHECK(SO3::log(SO3::compose(SO3::inverse(expected), translated[q].pose)).norm() < 1e-10);
    CHECK((translated[q].velocity - ad_right_inverse * original[q].velocity).norm() < 1e-10);
    CHECK(translated[q].iterations <= 6);
  }
}

TEST_CASE("The result does not depend on the queries' order") {
  std::mt19937 rng(5);
  const std::vector<double> t = irregular_covariates(rng, 60);
  std::vector<SO3::Element> f;
  for (const double ti : t) {
    f.push_back(SO3::exp(SO3::Tangent(4 * ti, std::cos(3 * ti), 0.2) +
                         bireg_test::random_tangent<SO3::Tangent>(rng, 0.05)));
  }
  std::vector<double> queries;
  for (int k = 0; k <= 40; ++k)
    queries.push_back(k / 40.0);
  std::vector<double> shuffled = queries;
  std::shuffle(shuffled.begin(), shuffled.end(), rng);
  const bireg::LocalGeodesicRegression<SO3> smoother(
      local_options<SO3>(bireg::Kernel::gaussian, 0.05));
  const auto in_order = smoother.smooth_at(f, t, queries);
  const auto out_of_order = smoother.smooth_at(f, t, shuffled);
  for (std::size_t k = 0; k < shuffled.size(); ++k) {
    const std::size_t q = static_cast<std::size_t>(std::lround(shuffled[k] * 40.0));
    REQUIRE(in_order[q].ok());
    REQUIRE(out_of_order[k].covariate == in_order[q].covariate);
    CHECK(SO3::log(SO3::compose(SO3::inverse(in_order[q].pose), out_of_order[k].pose)).norm() <
          1e-12);
    CHECK((in_order[q].velocity - out_of_order[k].velocity).norm() < 1e-12);
  }
}

// The warm queries stop on the contraction their steps show
// (Stopping::predicted): two evaluations of the estimating equations per
// query on smooth data, at the endpoints a certified cold fit of the same
// window reaches. Data as bench/bench_local_regression.cpp: a smooth SO3
// curve at 1 kHz with noise 0.01 rad per axis, Gaussian h = 2.5 samples
// (windows of 19-20 samples, 0.019 s wide). Both fits are within about
// the tolerance, 1e-10, of the window's estimator: endpoints within
// 2e-10 of each other, so poses within 4e-10 (twice that, for rounding)
// and velocities (the endpoints' difference over the window's width)
// within 4e-10 / 0.019 s = 2.1e-8 rad/s. The standard errors use the
// residuals at the returned endpoints: relative agreement to 1e-6 (the
// residuals, 0.01 rad, move by 1e-10 at most).
TEST_CASE("Warm queries take two evaluations and reach the certified fit's endpoints") {
  constexpr double kBandwidth = 2.5e-3;
  const bireg_test::So3Trajectory data = bireg_test::dense_so3_trajectory(600, 0.01, 7);
  const std::vector<SO3::Element>& f = data.f;
  const std::vector<double>& t = data.t;
  auto options = local_options<SO3>(bireg::Kernel::gaussian, kBandwidth);
  options.velocity_degree = 1;  // the geodesic's own velocity and errors
  const auto estimates = bireg::LocalGeodesicRegression<SO3>(options).smooth(f, t);
  int more_than_two = 0;
  for (std::size_t q = 0; q < estimates.size(); ++q) {
    const auto& estimate = estimates[q];
    REQUIRE(estimate.ok());
    if (q > 0 && estimate.iterations > 2) ++more_than_two;
    // The window, as the smoother forms it: support 4 h each side.
    std::vector<SO3::Element> window_f;
    std::vector<double> window_t, window_w;
    for (std::size_t i = 0; i < t.size(); ++i) {
      const double u = (t[i] - t[q]) / kBandwidth;
      if (std::abs(u) < 4) {
        window_f.push_back(f[i]);
        window_t.push_back(t[i]);
        window_w.push_back(std::exp(-u * u / 2));
      }
    }
    REQUIRE(estimate.window == window_t.size());
    bireg::RegressionOptions<double> fit_options;
    fit_options.interval = std::make_pair(window_t.front(), window_t.back());
    const auto fit = bireg::GeodesicRegression<SO3>(fit_options).fit(window_f, window_t, window_w);
    REQUIRE(fit.ok());
    CHECK(SO3::log(SO3::compose(SO3::inverse((*fit.geodesic)(t[q])), estimate.pose)).norm() <
          4e-10);
    CHECK((fit.geodesic->body_velocity() - estimate.velocity).norm() < 2.1e-8);
    const auto c = bireg::covariance(fit, window_t, window_w);
    REQUIRE(c.defined());
    REQUIRE(estimate.velocity_error_defined);
    const SO3::Tangent errors = bireg::standard_errors(bireg::velocity_covariance(c));
    CHECK((errors - estimate.velocity_error).norm() < 1e-6 * errors.norm());
  }
  // Every warm query in two evaluations: the first step from the previous
  // window's geodesic (about 0.01 rad, one sample entering and one
  // leaving), the second about 1e-7, whose contraction factor ~1e-5
  // predicts an error ~1e-12 after it.
  CHECK(more_than_two == 0);
}

TEST_CASE("x-IMU orientation turning through more than pi is smoothed without failure") {
  std::ifstream in(BIREG_TEST_DATA_DIR "/xio_imu_orientation_slice.csv");
  REQUIRE(in);
  bireg::io::Trajectory<SO3> data;
  REQUIRE(!bireg::io::read_trajectory<SO3>(in, bireg::io::Format::matrix, data));
  REQUIRE(data.observations.size() == 400);
  double turned = 0;
  for (std::size_t i = 1; i < data.observations.size(); ++i) {
    turned +=
        SO3::log(SO3::compose(SO3::inverse(data.observations[i - 1]), data.observations[i])).norm();
  }
  REQUIRE(turned > 3.1416);
  for (const bireg::Kernel kernel : kKernels) {
    // 3 samples at 128 Hz.
    const bireg::LocalGeodesicRegression<SO3> smoother(local_options<SO3>(kernel, 3.0 / 128));
    const auto estimates = smoother.smooth(data.observations, data.covariates);
    int iterations = 0;
    for (const auto& estimate : estimates) {
      INFO(estimate.message);
      REQUIRE(estimate.ok());
      CHECK(estimate.velocity_error_defined);
      iterations += estimate.iterations;
    }
    // Warm starts on smooth data: a few Gauss-Newton iterations per query.
    CHECK(iterations <= 4 * static_cast<int>(estimates.size()));
  }
}

TEST_CASE("A window with fewer than two covariates is reported, never NaN") {
  const std::vector<double> t{0.0, 0.1, 5.0};
  const std::vector<SO3::Element> f{SO3::identity(), SO3::exp(SO3::Tangent(0.1, 0, 0)),
                                    SO3::exp(SO3::Tangent(0, 0.1, 0))};
  const bireg::LocalGeodesicRegression<SO3> smoother(
      local_options<SO3>(bireg::Kernel::epanechnikov, 0.5));
  const auto estimates = smoother.smooth(f, t);
  CHECK(estimates[0].ok());
  CHECK(estimates[1].ok());
  CHECK(!estimates[2].ok());
  CHECK(estimates[2].status == bireg::Status::invalid_input);
  CHECK(estimates[2].message.find("fewer than two distinct covariates") != std::string::npos);
  CHECK(estimates[2].velocity.allFinite());
  const bireg::LocalGeodesicRegression<SO3> bad(local_options<SO3>(bireg::Kernel::gaussian, -1));
  CHECK(bad.smooth(f, t)[0].message.find("bandwidth") != std::string::npos);
}

// One observation rotated by pi/2 in the middle of a 61-point noisy SO3
// geodesic (noise 0.02 rad per axis, seed 8), Epanechnikov windows of
// about 20 observations. The plain local fit gives the outlier about 1/15
// of its window's weight, so it moves by roughly (pi/2) / 15 = 0.1 rad; a
// redescending loss gives it weight 0, so the robust estimate moves only by
// what dropping one of ~20 observations changes, about 0.02 / sqrt(20)
// = 0.0045 rad at most. The bounds: the plain estimate moves by more than
// 0.03 rad, the robust one by less than 0.01 rad.
TEST_CASE("A gross outlier in the window moves the plain local fit, not the robust one") {
  std::mt19937 rng(8);
  const int n = 61;
  std::vector<double> t;
  std::vector<SO3::Element> clean;
  const SO3::Element g0 = SO3::exp(SO3::Tangent(0.2, -0.5, 0.9));
  const SO3::Tangent x(1.2, 0.6, -0.8);
  for (int i = 0; i < n; ++i) {
    t.push_back(i / double(n - 1));
    clean.push_back(SO3::compose(SO3::compose(g0, SO3::exp(t.back() * x)),
                                 SO3::exp(bireg_test::random_tangent<SO3::Tangent>(rng, 0.02))));
  }
  const std::size_t middle = 30;
  std::vector<SO3::Element> contaminated = clean;
  contaminated[middle] = SO3::compose(
      contaminated[middle], SO3::exp(SO3::Tangent(1.0, 1.0, 0.0).normalized() * (M_PI / 2)));

  auto options = local_options<SO3>(bireg::Kernel::epanechnikov, 0.17);
  const bireg::LocalGeodesicRegression<SO3> plain(options);
  bireg::RobustOptions<double> robust_options;
  robust_options.loss = bireg::Loss::tukey;
  options.robust = robust_options;
  const bireg::LocalGeodesicRegression<SO3> robust(options);

  const std::vector<double> queries = {0.45, 0.5, 0.55};
  const auto plain_clean = plain.smooth_at(clean, t, queries);
  const auto plain_dirty = plain.smooth_at(contaminated, t, queries);
  const auto robust_clean = robust.smooth_at(clean, t, queries);
  const auto robust_dirty = robust.smooth_at(contaminated, t, queries);
  const auto distance = [](const SO3::Element& a, const SO3::Element& b) {
    return SO3::log(SO3::compose(SO3::inverse(a), b)).norm();
  };
  for (std::size_t q = 0; q < queries.size(); ++q) {
    INFO("query " << queries[q]);
    REQUIRE(plain_dirty[q].ok());
    REQUIRE(robust_dirty[q].ok());
    REQUIRE(robust_clean[q].ok());
    const double plain_moved = distance(plain_clean[q].pose, plain_dirty[q].pose);
    const double robust_moved = distance(plain_clean[q].pose, robust_dirty[q].pose);
    INFO("plain moved " << plain_moved << ", robust moved " << robust_moved);
    CHECK(plain_moved > 0.03);
    CHECK(robust_moved < 0.01);
    // The outlier, and only it, is flagged.
    REQUIRE(robust_dirty[q].outlier_covariates.size() == 1);
    CHECK(robust_dirty[q].outlier_covariates[0] == t[middle]);
  }

  // Equivariance survives the reweighting: the Mahalanobis distances are
  // invariant, so translating the data moves every robust estimate.
  const SO3::Element left = SO3::exp(SO3::Tangent(1.0, -2.0, 0.7));
  const SO3::Element right = SO3::exp(SO3::Tangent(-0.4, 0.9, 2.2));
  std::vector<SO3::Element> moved;
  for (const auto& fi : contaminated)
    moved.push_back(SO3::compose(SO3::compose(left, fi), right));
  const auto robust_moved = robust.smooth_at(moved, t, queries);
  const SO3::AdMatrix ad_right_inverse = SO3::Ad(SO3::inverse(right));
  for (std::size_t q = 0; q < queries.size(); ++q) {
    REQUIRE(robust_moved[q].ok());
    const SO3::Element expected = SO3::compose(SO3::compose(left, robust_dirty[q].pose), right);
    // As the plain equivariance test, with the robust weights settled to
    // 1e-6: the weights move the estimate by 1e-6 times the residual scale
    // only if they differ between the two runs, which they do not beyond
    // rounding (the distances are invariant); 1e-9.
    CHECK(distance(expected, robust_moved[q].pose) < 1e-9);
    CHECK((robust_moved[q].velocity - ad_right_inverse * robust_dirty[q].velocity).norm() < 1e-9);
  }
}

// Cross-validated bandwidth on simulated data with a known smooth curve:
// f_i = exp(c(t_i)) exp(e_i), c(t) = 0.5 (sin 2 pi t, cos 2 pi t - 1, sin 4 pi t),
// t_i = i / 199, e_i Gaussian 0.03 rad per axis, seed 13. The target is the
// bandwidth minimising the true error (mean squared distance of the smoothed
// poses to exp(c(t_i))), which only a simulation knows. Cross-validation
// estimates that error plus the noise's variance, so its minimiser should
// be close: asserted within a factor 2 on the grid (which steps by a factor
// 1.37), with a true error at most 1.5 times the smallest. The curve is U
// shaped: it falls to a minimum inside the grid and rises after it, both
// ends at least 20% above it (too small a bandwidth fits the noise, too
// large one the curve's chord). Measured: both choose h = 0.035 (about 7
// sample spacings), CV 3.4e-4 there, 3.8e-4 and 0.072 at the grid's finite
// ends.
TEST_CASE("Leave-one-out cross-validation picks a bandwidth near the true error's minimiser") {
  std::mt19937 rng(13);
  const int n = 200;
  const auto curve = [](double t) {
    const double turn = 2 * M_PI * t;
    return SO3::exp(0.5 * SO3::Tangent(std::sin(turn), std::cos(turn) - 1, std::sin(2 * turn)));
  };
  std::vector<double> t;
  std::vector<SO3::Element> f;
  for (int i = 0; i < n; ++i) {
    t.push_back(i / double(n - 1));
    f.push_back(SO3::compose(curve(t.back()),
                             SO3::exp(bireg_test::random_tangent<SO3::Tangent>(rng, 0.03))));
  }
  const std::vector<double> grid = bireg::bandwidth_grid(t, 12);
  REQUIRE(grid.size() == 12);
  const auto options = local_options<SO3>(bireg::Kernel::epanechnikov, 1.0);
  const bireg::BandwidthSelection<double> selection =
      bireg::select_bandwidth<SO3>(f, t, options, grid);
  REQUIRE(selection.ok());

  std::vector<double> true_error;
  for (const double h : grid) {
    const auto estimates =
        bireg::LocalGeodesicRegression<SO3>(local_options<SO3>(bireg::Kernel::epanechnikov, h))
            .smooth(f, t);
    double sum = 0;
    for (std::size_t i = 0; i < estimates.size(); ++i) {
      const bool ok = estimates[i].ok();
      sum += ok ? SO3::log(SO3::compose(SO3::inverse(curve(t[i])), estimates[i].pose)).squaredNorm()
                : std::numeric_limits<double>::infinity();
    }
    true_error.push_back(sum / n);
  }
  const std::size_t best_true = static_cast<std::size_t>(
      std::min_element(true_error.begin(), true_error.end()) - true_error.begin());
  const std::size_t chosen = static_cast<std::size_t>(
      std::find(grid.begin(), grid.end(), selection.bandwidth) - grid.begin());
  INFO("chosen h " << selection.bandwidth << ", true-error minimiser " << grid[best_true]);
  // Down to the minimum and up after it (the smallest bandwidth's windows
  // at the ends hold one observation once it is left out: infinite), the
  // widest values skipped once neither curve has improved for 4 values.
  std::size_t evaluated_after = 0;
  for (std::size_t k = 1; k < grid.size(); ++k) {
    INFO("h " << grid[k] << " cv " << selection.criterion[k] << " true " << true_error[k]);
    if (selection.refusals[k].rfind("not evaluated", 0) == 0) {
      CHECK(k > chosen + 4);
      continue;
    }
    if (k > chosen) ++evaluated_after;
    if (k <= chosen) {
      CHECK(selection.criterion[k] <= selection.criterion[k - 1]);
    } else {
      CHECK(selection.criterion[k] > selection.criterion[k - 1]);
    }
  }
  CHECK(selection.bandwidth <= 2 * grid[best_true]);
  CHECK(selection.bandwidth >= grid[best_true] / 2);
  CHECK(true_error[chosen] <= 1.5 * true_error[best_true]);
  const double cv_min = selection.criterion[chosen];
  CHECK(chosen > 0);
  CHECK(chosen + 1 < grid.size());
  CHECK(selection.criterion.front() > 1.2 * cv_min);
  CHECK(selection.criterion[chosen + evaluated_after] > 1.2 * cv_min);
  CHECK((evaluated_after >= 4 || chosen + evaluated_after + 1 == grid.size()));
}
