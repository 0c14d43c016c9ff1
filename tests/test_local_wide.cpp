// Wide windows for fast rotation (statistics/smoothing/local_wide.hpp): the wide fit
// is fit() in other coordinates where both apply, recovers a geodesic that
// turns by more than pi, keeps left and right equivariance; the windows
// that feed it (local_window.hpp: path_radius, the turn cut looking past
// the kernel's reach) and the velocity's cross-validation target
// (five_point_target, velocity_target).
#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Core>

#include "bireg/groups/se2.hpp"
#include "bireg/groups/se3.hpp"
#include "bireg/groups/so3.hpp"
#include "bireg/regression.hpp"
#include "bireg/statistics/inference/covariance.hpp"
#include "bireg/statistics/smoothing/local_regression.hpp"
#include "bireg/testing/fast_motion.hpp"
#include "catch.hpp"
#include "test_support.hpp"

namespace {

using SO3 = bireg::SO3d;
using SE2 = bireg::SE2d;
using SE3 = bireg::SE3d;
namespace motion = bireg::testing;

// A window of m observations at spacing dt about tau = 0 along the
// geodesic g exp(t v), each perturbed by exp(noise * e), Gaussian weights
// of bandwidth h.
template <class G>
bireg::LocalWindow<G> geodesic_window(const typename G::Element& g, const typename G::Tangent& v,
                                      int m, double dt, double h, double noise, unsigned seed) {
  std::mt19937 rng(seed);
  bireg::LocalWindow<G> window;
  for (int k = 0; k < m; ++k) {
    const double t = (k - (m - 1) / 2.0) * dt;
    const typename G::Tangent e = bireg_test::normal_tangent<typename G::Tangent>(rng, noise);
    window.observations.push_back(G::compose(G::compose(g, G::exp(t * v)), G::exp(e)));
    window.covariates.push_back(t);
    window.weights.push_back(bireg::kernel_weight(bireg::Kernel::gaussian, t / h));
  }
  return window;
}

template <class G>
void check_against_fit(const typename G::Tangent& v, unsigned seed) {
  std::mt19937 rng(seed);
  const typename G::Element g = G::exp(bireg_test::normal_tangent<typename G::Tangent>(rng, 1.0));
  // 21 samples over 1 s, turning by |omega| <= 2 rad in all: inside the
  // principal log, where fit() applies too.
  const auto window = geodesic_window<G>(g, v, 21, 0.05, 0.3, 0.05, seed + 1);
  bireg::RegressionOptions<double> options;
  options.interval = std::make_pair(window.covariates.front(), window.covariates.back());
  const auto fit = bireg::GeodesicRegression<G>(options).fit(window.observations, window.covariates,
                                                             window.weights);
  REQUIRE(fit.ok());
  const bireg::Geodesic<G>& reference = *fit.geodesic;
  // Start away from the solution: 0.1 in the pose, 10 % in the velocity.
  const typename G::Element start_pose =
      G::compose(reference(0.0), G::exp(bireg_test::normal_tangent<typename G::Tangent>(rng, 0.1)));
  const typename G::Tangent start_velocity = 1.1 * reference.body_velocity();
  const bireg::WideFit<G> wide =
      bireg::wide_fit<G>(window, 0.0, start_pose, start_velocity, 1e-12, 50, true);
  REQUIRE(wide.converged);
  // Both solve v = 0 to a step of 1e-10 (fit) and 1e-12; the Gauss-Newton
  // contraction near the solution is ~ the noise (0.05), so the solutions
  // agree to ~1e-11.
  CHECK(bireg::log_at<G>(wide(0.0), reference(0.0)).norm() < 1e-9);
  CHECK((wide.body_velocity() - reference.body_velocity()).norm() < 1e-9);
  // The sandwich in (g0, X) is covariance.hpp's in (g0, g1): the same
  // linearisation, so the same numbers up to rounding.
  const auto covariance = bireg::covariance(fit, window.covariates, window.weights);
  REQUIRE(covariance.defined());
  REQUIRE(wide.velocity_error_defined);
  const typename G::Tangent reference_errors =
      bireg::standard_errors(bireg::velocity_covariance(covariance));
  CHECK((wide.velocity_error - reference_errors).norm() < 1e-8 * reference_errors.norm());
}

}  // namespace

TEST_CASE("The wide fit is fit() in other coordinates where both apply", "[wide]") {
  check_against_fit<SO3>(SO3::Tangent(1.0, -1.2, 0.5), 3);
  SE3::Tangent v;
  v << 0.4, -0.3, 1.0, 1.1, 0.8, -0.9;
  check_against_fit<SE3>(v, 5);
}

TEST_CASE("The wide fit recovers a noise-free geodesic that turns by 4.5 rad", "[wide]") {
  std::mt19937 rng(8);
  const SO3::Element g = SO3::exp(bireg_test::normal_tangent<SO3::Tangent>(rng, 1.0));
  const SO3::Tangent v(3.0, -2.0, 2.5);  // |v| = 4.39 rad/s over 1.05 s: 4.6 rad
  const auto window = geodesic_window<SO3>(g, v, 22, 0.05, 1.0, 0.0, 9);
  const bireg::WideFit<SO3> wide = bireg::wide_fit<SO3>(
      window, 0.0, SO3::compose(g, SO3::exp(SO3::Tangent(0.05, 0, 0))), 0.9 * v, 1e-12, 50, true);
  REQUIRE(wide.converged);
  CHECK(wide.displacement.norm() > 4.5);
  CHECK(bireg::log_at<SO3>(wide(0.0), g).norm() < 1e-10);
  CHECK((wide.body_velocity() - v).norm() < 1e-10);
  // Noise-free: no noise to build standard errors on.
  CHECK_FALSE(wide.velocity_error_defined);
}

TEST_CASE("The wide fit is left and right equivariant on SE(3) past pi", "[wide]") {
  std::mt19937 rng(12);
  SE3::Tangent v;
  v << 0.5, 0.2, -0.4, 2.0, -2.5, 1.5;  // 3.5 rad/s over 1.2 s: 4.2 rad
  const SE3::Element g = SE3::exp(bireg_test::normal_tangent<SE3::Tangent>(rng, 1.0));
  const auto window = geodesic_window<SE3>(g, v, 25, 0.05, 0.4, 0.03, 13);
  const SE3::Element left = SE3::exp(bireg_test::normal_tangent<SE3::Tangent>(rng, 1.0));
  const SE3::Element right = SE3::exp(bireg_test::normal_tangent<SE3::Tangent>(rng, 1.0));
  bireg::LocalWindow<SE3> moved = window;
  for (auto& f : moved.observations)
    f = SE3::compose(SE3::compose(left, f), right);
  const auto base = bireg::wide_fit<SE3>(window, 0.0, g, v, 1e-12, 50, true);
  const auto mapped = bireg::wide_fit<SE3>(moved, 0.0, SE3::compose(SE3::compose(left, g), right),
                                           SE3::Ad(SE3::inverse(right)) * v, 1e-12, 50, true);
  REQUIRE(base.converged);
  REQUIRE(mapped.converged);
  CHECK(base.displacement.tail<3>().norm() > 3.5);  // the rotation, tail (se3.hpp)
  const SE3::Element expected = SE3::compose(SE3::compose(left, base(0.0)), right);
  CHECK(bireg::log_at<SE3>(mapped(0.0), expected).norm() < 1e-9);
  CHECK((mapped.body_velocity() - SE3::Ad(SE3::inverse(right)) * base.body_velocity()).norm() <
        1e-9);
}

// The net force at the wide fit's solution, evaluated independently by
// capabilities.hpp's apply_psi (the closed form of psi, or its series),
// against the residuals' scale sum w |r|.
template <class G>
std::pair<double, double> force_at(const bireg::WideFit<G>& fit,
                                   const bireg::LocalWindow<G>& window) {
  typename G::Tangent v0 = G::Tangent::Zero(), v1 = G::Tangent::Zero();
  double scale = 0;
  for (std::size_t i = 0; i < window.covariates.size(); ++i) {
    const double t = (window.covariates[i] - fit.t_first) / (fit.t_last - fit.t_first);
    const typename G::Tangent r = G::log(G::compose(
        G::exp(-t * fit.displacement), G::compose(G::inverse(fit.start), window.observations[i])));
    const typename G::Tangent minus_x = -fit.displacement;
    v0 += window.weights[i] * bireg::apply_psi<G>(minus_x, 1 - t, r);
    v1 += window.weights[i] * bireg::apply_psi<G>(fit.displacement, t, r);
    scale += window.weights[i] * r.norm();
  }
  return {std::max(v0.norm(), v1.norm()), scale};
}

// SE(2) has no closed-form J_r^{-1}: its Bernoulli series is off by 0.3 at
// 5 rad (|J J^{-1} - I|), so the wide fit inverts J_r's own series there.
TEST_CASE("On SE(2) past 5 rad the wide fit solves the estimating equations", "[wide]") {
  // Over 1.2 s: 4.8 and 5.3 rad, and 6.0, past the domain (0.9 of 2 pi).
  for (const double rate : {4.0, 4.4, 5.0}) {
    SE2::Tangent v;
    v << 1.0, -0.5, rate;
    std::mt19937 rng(2);
    const SE2::Element g = SE2::exp(bireg_test::normal_tangent<SE2::Tangent>(rng, 1.0));
    const auto window = geodesic_window<SE2>(g, v, 25, 0.05, 0.4, 0.03, 4);
    const bireg::WideFit<SE2> fit = bireg::wide_fit<SE2>(window, 0.0, g, v, 1e-12, 50, true);
    INFO("rate " << rate << ", turn " << std::abs(fit.displacement[2]));
    if (std::abs(rate * 1.2) >= 0.9 * 2 * 3.141592653589793) {
      CHECK_FALSE(fit.converged);  // outside the domain: refused, not solved
      continue;
    }
    REQUIRE(fit.converged);
    const auto [force, scale] = force_at(fit, window);
    // The step tolerance 1e-12 bounds the force by ~1e-12 K; the
    // evaluations differ by rounding in psi (1e-13 relative).
    CHECK(force < 1e-9 * scale);
    // Noise 0.03 per coordinate over 25 samples: the velocity's error is
    // a few 0.03 / (1.2 s sqrt(25 / 12)) = 0.017; 0.15 is 9 of those.
    CHECK((fit.body_velocity() - v).norm() < 0.15);
  }
}

TEST_CASE("The five-point target is exact on a geodesic and fourth order on a spin", "[wide]") {
  // A geodesic at uneven spacing: log(f_i^{-1} f_j) = (t_j - t_i) v exactly.
  const SO3::Tangent v(1.5, -0.5, 2.0);
  const std::vector<double> t = {0.0, 0.11, 0.19, 0.32, 0.40, 0.52};
  std::vector<SO3::Element> f;
  for (const double ti : t)
    f.push_back(SO3::exp(ti * v));
  for (std::size_t i = 2; i + 2 < t.size(); ++i) {
    const auto target = bireg::five_point_target<SO3>(f, t, i, 2.5);
    REQUIRE(target.defined);
    CHECK((target.velocity - v).norm() < 1e-12);
  }
  CHECK_FALSE(bireg::five_point_target<SO3>(f, t, 1, 2.5).defined);
  // A 10 rad/s spin sampled at 50 and 100 Hz (noise-free): the target's
  // error falls like dt^4, so halving dt divides it by ~16 (at least 10
  // here, the next order's share at 50 Hz included).
  double error[2] = {0, 0};
  for (int k = 0; k < 2; ++k) {
    const auto track =
        motion::sample_rotation(motion::spin(10.0), 1.0, k == 0 ? 50.0 : 100.0, 0.0, 1);
    const std::size_t middle = track.t.size() / 2;
    const auto target = bireg::five_point_target<SO3>(track.f, track.t, middle, 2.5);
    REQUIRE(target.defined);
    error[k] = (target.velocity - track.velocity[middle]).norm();
  }
  INFO("50 Hz " << error[0] << ", 100 Hz " << error[1]);
  CHECK(error[1] < error[0] / 10);
}

TEST_CASE("The velocity's target: derivatives where chords are biased, chords where noisy",
          "[wide]") {
  using bireg::local_regression_detail::noise_scatter;
  using bireg::local_regression_detail::velocity_target;
  // 20 rad/s at 25 Hz without noise: chords 0.22 rad/s off.
  const auto fast = motion::sample_rotation(motion::spin(20.0), 4.0, 25.0, 0.0, 11);
  CHECK(velocity_target<SO3>(fast.f, fast.t, noise_scatter<SO3>(fast.f, fast.t), 2.5) ==
        bireg::HoldOut::derivatives);
  // 5 rad/s at 100 Hz with 0.02 rad: unbiased chords, the five points'
  // extra noise would cost more.
  const auto slow = motion::sample_rotation(motion::spin(5.0), 4.0, 100.0, 0.02, 11);
  CHECK(velocity_target<SO3>(slow.f, slow.t, noise_scatter<SO3>(slow.f, slow.t), 2.5) ==
        bireg::HoldOut::chords);
}

TEST_CASE("Wide windows: at most 2 max_turn of path, and cut where the reach ends past the ball",
          "[wide]") {
  // 20 rad/s (+-25 %) at 25 Hz: 0.6-1.0 rad between samples.
  const auto track = motion::sample_rotation(motion::spin(20.0), 4.0, 25.0, 0.0, 11);
  for (const double h : {0.0264, 0.1, 1.0}) {
    bireg::LocalRegressionOptions<double> options;
    options.bandwidth = h;
    options.standard_errors = false;
    const auto estimates = bireg::LocalGeodesicRegression<SO3>(options).smooth(track.f, track.t);
    std::size_t widened = 0;
    for (const auto& e : estimates)
      widened += e.widened ? 1 : 0;
    // Past 0.66 spacings the cut binds everywhere and the wide fit takes over.
    if (h >= 0.1) CHECK(widened == estimates.size());
    for (std::size_t q = 0; q < estimates.size(); ++q) {
      INFO("bandwidth " << h << " query " << q);
      // Before the cut looked past the kernel's reach, h = 0.0264 (reach
      // 2.6 spacings) kept the samples two away on each side, 3.2 rad
      // apart: 48 of 101 fits failed.
      REQUIRE(estimates[q].ok());
      // At >= 0.6 rad between samples, 2.5 rad of path is at most 4
      // steps on each side.
      CHECK(estimates[q].window <= 9);
    }
  }
}
