// The covariance of a spline fit and its pointwise bands
// (bireg/statistics/inference/spline_covariance.hpp, docs/splines.md §10):
// the velocity's differential (11) against differences of the curve, the
// sandwich against ordinary least squares in R^3 (computed here with a
// dense solve), its equivariance, its refusals, and by simulation on SO(3):
// bands that cover the truth at their level, and errors that shrink like
// N^{-1/2}; and the choice between geodesic, piecewise geodesic and cubic
// spline (bireg/statistics/selection/curve_selection.hpp).
#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <tuple>
#include <vector>

#include <Eigen/Dense>

#include "bireg/groups/rn.hpp"
#include "bireg/groups/se3.hpp"
#include "bireg/groups/so3.hpp"
#include "bireg/regression.hpp"
#include "bireg/spline_regression.hpp"
#include "bireg/statistics/inference/covariance.hpp"
#include "bireg/statistics/inference/spline_covariance.hpp"
#include "bireg/statistics/selection/curve_selection.hpp"
#include "catch.hpp"
#include "spline_samples.hpp"
#include "test_support.hpp"

namespace {

using SO3 = bireg::SO3d;
using SE3 = bireg::SE3d;
using R3 = bireg::Rnd<3>;
using bireg_test::random_points;
using bireg_test::sample;
using bireg_test::Samples;

template <class G>
bireg::SplineResult<G> fit_on_knots(const bireg::Spline<G>& truth, const Samples<G>& data,
                                    int degree = 3) {
  bireg::SplineOptions<double> options;
  options.degree = degree;
  options.knot_spacing = truth.knot_spacing();
  options.interval = std::make_pair(truth.t_min(), truth.t_max());
  return bireg::SplineRegression<G>(options).fit(data.f, data.t);
}

// The largest entry of a - b relative to b's largest.
template <class A, class B>
double relative(const A& a, const B& b) {
  return (a - b).cwiseAbs().maxCoeff() / b.cwiseAbs().maxCoeff();
}

}  // namespace

TEST_CASE("Spline velocity differential (11) against differences of the curve", "[spline]") {
  std::mt19937 rng(3);
  for (const int k : {1, 2, 3}) {
    const std::vector<SE3::Element> points = random_points<SE3>(rng, 7, 0.6);
    const bireg::Spline<SE3> curve(k, 0.5, 0.7, points);
    for (const double t : {0.5, 1.13, 2.2, 3.3 - 1e-9}) {
      bireg::SegmentAt<SE3> segment;
      bireg::segment_at(curve, t, segment);
      const auto& [at, basis, product, jacobians] = segment;
      std::array<SE3::AdMatrix, bireg::kMaxSplineDegree + 1> v;
      bireg::velocity_differentials<SE3>(k, curve.knot_spacing(), basis, product, jacobians.data(),
                                         v);
      constexpr double step = 1e-6;
      for (int j = 0; j <= k; ++j) {
        SE3::AdMatrix differences;
        for (int a = 0; a < SE3::dof; ++a) {
          std::vector<SE3::Element> plus = points, minus = points;
          const SE3::Tangent e = step * SE3::Tangent::Unit(a);
          plus[at.segment + j] = SE3::compose(plus[at.segment + j], SE3::exp(e));
          minus[at.segment + j] = SE3::compose(minus[at.segment + j], SE3::exp((-e).eval()));
          differences.col(a) = (bireg::Spline<SE3>(k, 0.5, 0.7, plus).body_velocity(t) -
                                bireg::Spline<SE3>(k, 0.5, 0.7, minus).body_velocity(t)) /
                               (2 * step);
        }
        INFO("degree " << k << ", t " << t << ", control point " << j);
        // Central differences at step 1e-6 of entries of size ~1: ~1e-10.
        CHECK((v[std::size_t(j)] - differences).cwiseAbs().maxCoeff() < 1e-8);
      }
    }
  }
}

TEST_CASE("Spline covariance in R^3 is the least-squares one", "[spline]") {
  std::mt19937 rng(5);
  const bireg::Spline<R3> truth(3, 0.0, 1.0, random_points<R3>(rng, 8, 0.5));
  const Samples<R3> data = sample(truth, 60, 0.1, rng);
  std::vector<double> weights;
  std::uniform_real_distribution<double> uniform(0.2, 2.0);
  for (std::size_t i = 0; i < data.t.size(); ++i)
    weights.push_back(uniform(rng));
  bireg::SplineOptions<double> options;
  options.knot_spacing = 1.0;
  options.interval = std::make_pair(0.0, 5.0);
  const auto fit = bireg::SplineRegression<R3>(options).fit(data.f, data.t, weights);
  REQUIRE(fit.ok());
  const auto c = bireg::spline_covariance(fit, data.f, data.t, weights);
  REQUIRE(c.defined());

  // Independently: the collocation matrix B, H = B^T W B, H_2 = B^T W^2 B,
  // the residuals of the weighted least-squares solution, S with
  // nu = W - tr(H^{-1} H_2), and Cov = H^{-1} H_2 H^{-1} kron S.
  const std::size_t n = data.t.size(), m = truth.control_points().size();
  const double largest = *std::max_element(weights.begin(), weights.end());
  const auto rows = static_cast<Eigen::Index>(n);
  Eigen::MatrixXd b = Eigen::MatrixXd::Zero(rows, Eigen::Index(m));
  Eigen::MatrixXd y(rows, 3);
  Eigen::VectorXd w(rows);
  for (std::size_t i = 0; i < n; ++i) {
    const auto at = truth.position(data.t[i]);
    const auto basis = bireg::spline_basis(3, at.u);
    for (std::size_t j = 0; j <= 3; ++j)
      b(Eigen::Index(i), Eigen::Index(at.segment + j)) = basis.ordinary[j];
    y.row(Eigen::Index(i)) = data.f[i].transpose();
    w[Eigen::Index(i)] = weights[i] / largest;
  }
  const Eigen::MatrixXd h = b.transpose() * w.asDiagonal() * b;
  const Eigen::MatrixXd h2 = b.transpose() * w.cwiseAbs2().asDiagonal() * b;
  const Eigen::MatrixXd coefficients = h.ldlt().solve(b.transpose() * w.asDiagonal() * y);
  const Eigen::MatrixXd r = y - b * coefficients;
  const double nu = w.sum() - h.ldlt().solve(h2).trace();
  const Eigen::Matrix3d s = r.transpose() * w.asDiagonal() * r / nu;
  const Eigen::MatrixXd hinv = h.inverse();
  const Eigen::MatrixXd coefficient_covariance = hinv * h2 * hinv;
  CHECK(std::abs(c.degrees_of_freedom - nu) < 1e-10 * nu);
  CHECK(relative(c.residual, s) < 1e-10);
  for (std::size_t p = 0; p < m; ++p) {
    for (std::size_t q = (p > 3 ? p - 3 : 0); q < std::min(m, p + 4); ++q) {
      const Eigen::Matrix3d expected = coefficient_covariance(Eigen::Index(p), Eigen::Index(q)) * s;
      CHECK((c.block(p, q) - expected).cwiseAbs().maxCoeff() < 1e-10 * s.norm());
    }
  }
  // The pose and the velocity at t: b(t)^T C b(t) S and b'(t)^T C b'(t) S / h^2.
  for (const double t : {0.0, 0.4, 2.0, 3.71, 5.0}) {
    const auto at = truth.position(t);
    const auto basis = bireg::spline_basis(3, at.u);
    Eigen::VectorXd value = Eigen::VectorXd::Zero(Eigen::Index(m));
    Eigen::VectorXd slope = Eigen::VectorXd::Zero(Eigen::Index(m));
    // B_c' from the cumulative derivatives: B_j' = b_j' - b_{j+1}'.
    for (std::size_t j = 0; j <= 3; ++j) {
      value[Eigen::Index(at.segment + j)] = basis.ordinary[j];
      slope[Eigen::Index(at.segment + j)] =
          (j == 0 ? 0.0 : basis.cumulative_d1[j]) - (j < 3 ? basis.cumulative_d1[j + 1] : 0.0);
    }
    INFO("t = " << t);
    CHECK(relative(bireg::pose_covariance(c, t),
                   (value.dot(coefficient_covariance * value) * s).eval()) < 1e-10);
    CHECK(relative(bireg::velocity_covariance(c, t),
                   (slope.dot(coefficient_covariance * slope) * s).eval()) < 1e-10);
    CHECK(relative(bireg::prediction_covariance(c, t),
                   ((value.dot(coefficient_covariance * value) + 1) * s).eval()) < 1e-10);
  }
  // Unit weights: the textbook N - M.
  const auto unweighted = bireg::spline_covariance(
      bireg::SplineRegression<R3>(options).fit(data.f, data.t), data.f, data.t);
  REQUIRE(unweighted.defined());
  CHECK(std::abs(unweighted.degrees_of_freedom - double(n - m)) < 1e-9);
}

// Degree 1 with one segment is the geodesic (test_spline.cpp), and its
// covariance the geodesic's homoscedastic one, up to the Gauss-Newton
// matrices' one difference: the spline's carries J_l(r_i)^{-1} = I + O(|r_i|)
// in each term (splines.md §9), the geodesic's takes the residuals as
// vanishing (DESIGN.md §2). Summed over the observations the O(|r|) parts
// are zero-mean, about sigma / sqrt(N) of K relative: bounded here by
// sigma = 0.01.
TEST_CASE("Spline covariance of degree 1 on one segment is the geodesic's", "[spline]") {
  std::mt19937 rng(4);
  const bireg::Spline<SE3> truth(1, 0.0, 2.0, random_points<SE3>(rng, 2, 0.8));
  const Samples<SE3> data = sample(truth, 50, 0.01, rng);
  bireg::SplineOptions<double> spline_options;
  spline_options.degree = 1;
  spline_options.tolerance = 1e-13;
  const auto spline_fit = bireg::SplineRegression<SE3>(spline_options).fit(data.f, data.t);
  const auto spline = bireg::spline_covariance(spline_fit, data.f, data.t);
  bireg::RegressionOptions<double> options;
  options.tolerance = 1e-13;
  const auto fit = bireg::GeodesicRegression<SE3>(options).fit(data.f, data.t);
  const auto geodesic = bireg::covariance(fit, data.t, {}, bireg::CovarianceFlavour::homoscedastic);
  REQUIRE(spline.defined());
  REQUIRE(geodesic.defined());
  CHECK(spline.degrees_of_freedom == Approx(geodesic.degrees_of_freedom).epsilon(1e-12));
  CHECK(relative(spline.residual, geodesic.residual) < 1e-9);
  for (const double t : {data.t.front(), 0.7, 1.3, data.t.back()}) {
    INFO("t = " << t);
    CHECK(relative(bireg::pose_covariance(spline, t), bireg::pose_covariance(geodesic, t)) < 0.01);
    CHECK(relative(bireg::velocity_covariance(spline, t), bireg::velocity_covariance(geodesic)) <
          0.01);
  }
}

TEST_CASE("Spline covariance is left invariant and right equivariant", "[spline]") {
  std::mt19937 rng(11);
  const bireg::Spline<SE3> truth(3, 0.0, 1.0, random_points<SE3>(rng, 7, 0.5));
  const Samples<SE3> data = sample(truth, 80, 0.05, rng);
  const SE3::Element g = SE3::exp(bireg_test::normal_tangent<SE3::Tangent>(rng, 1.0));
  Samples<SE3> left = data, right = data;
  for (std::size_t i = 0; i < data.f.size(); ++i) {
    left.f[i] = SE3::compose(g, data.f[i]);
    right.f[i] = SE3::compose(data.f[i], g);
  }
  const auto c = bireg::spline_covariance(fit_on_knots(truth, data), data.f, data.t);
  const auto cl = bireg::spline_covariance(fit_on_knots(truth, left), left.f, left.t);
  const auto cr = bireg::spline_covariance(fit_on_knots(truth, right), right.f, right.t);
  REQUIRE(c.defined());
  REQUIRE(cl.defined());
  REQUIRE(cr.defined());
  const SE3::AdMatrix a = SE3::Ad(SE3::inverse(g));
  for (const double t : {0.0, 1.5, 2.77, 4.0}) {
    INFO("t = " << t);
    CHECK(relative(bireg::pose_covariance(cl, t), bireg::pose_covariance(c, t)) < 1e-8);
    CHECK(relative(bireg::velocity_covariance(cl, t), bireg::velocity_covariance(c, t)) < 1e-8);
    CHECK(relative(bireg::pose_covariance(cr, t),
                   (a * bireg::pose_covariance(c, t) * a.transpose()).eval()) < 1e-8);
    CHECK(relative(bireg::velocity_covariance(cr, t),
                   (a * bireg::velocity_covariance(c, t) * a.transpose()).eval()) < 1e-8);
  }
}

TEST_CASE("Spline covariance refuses what it cannot estimate, saying why", "[spline]") {
  std::mt19937 rng(13);
  const bireg::Spline<SO3> truth(3, 0.0, 1.0, random_points<SO3>(rng, 7, 0.4));
  const Samples<SO3> data = sample(truth, 40, 0.05, rng);
  const auto fit = fit_on_knots(truth, data);
  REQUIRE(fit.ok());

  bireg::SplineResult<SO3> failed;
  CHECK(bireg::spline_covariance(failed, data.f, data.t).status ==
        bireg::CovarianceStatus::invalid_input);
  std::vector<double> short_t(data.t.begin(), data.t.end() - 1);
  CHECK(bireg::spline_covariance(fit, data.f, short_t).status ==
        bireg::CovarianceStatus::invalid_input);
  std::vector<double> bad_weights(data.t.size(), 1.0);
  bad_weights[7] = -1;
  const auto weighted = bireg::spline_covariance(fit, data.f, data.t, bad_weights);
  CHECK(weighted.status == bireg::CovarianceStatus::invalid_input);
  CHECK(weighted.message.find("weight 7") != std::string::npos);

  // A penalised fit (splines.md §12): its bands are not built, and say so.
  bireg::SplineOptions<double> penalised_options;
  penalised_options.knot_spacing = truth.knot_spacing();
  penalised_options.interval = std::make_pair(truth.t_min(), truth.t_max());
  penalised_options.roughness_penalty = 0.1;
  const auto penalised_fit = bireg::SplineRegression<SO3>(penalised_options).fit(data.f, data.t);
  REQUIRE(penalised_fit.ok());
  const auto penalised = bireg::spline_covariance(penalised_fit, data.f, data.t);
  CHECK(penalised.status == bireg::CovarianceStatus::undefined);
  CHECK(penalised.message.find("roughness penalty") != std::string::npos);

  // Noise-free data: the noise covariance is zero.
  const Samples<SO3> exact = sample(truth, 40, 0.0, rng);
  const auto noise_free = bireg::spline_covariance(fit_on_knots(truth, exact), exact.f, exact.t);
  CHECK(noise_free.status == bireg::CovarianceStatus::undefined);
  CHECK(noise_free.message.find("vanish") != std::string::npos);

  // As many observations as control points (degree 1, one at each knot):
  // the fit interpolates, and no degrees of freedom remain.
  Samples<SO3> few;
  for (int knot = 0; knot <= 4; ++knot) {
    few.t.push_back(knot);
    few.f.push_back(SO3::compose(truth(knot), SO3::exp(SO3::Tangent(0.05, -0.02, 0.03))));
  }
  const auto just = fit_on_knots(truth, few, 1);
  REQUIRE(just.ok());
  const auto none = bireg::spline_covariance(just, few.f, few.t);
  CHECK(none.status == bireg::CovarianceStatus::undefined);
  CHECK(none.message.find("degrees of freedom") != std::string::npos);

  // Beyond the dense limit: 1,366 control points of SO(3), 4,098 coordinates.
  const bireg::Spline<SO3> long_truth(3, 0.0, 1.0, random_points<SO3>(rng, 1366, 0.05));
  const Samples<SO3> many = sample(long_truth, 4000, 0.01, rng);
  const auto long_fit = fit_on_knots(long_truth, many);
  REQUIRE(long_fit.ok());
  const auto too_large = bireg::spline_covariance(long_fit, many.f, many.t);
  CHECK(too_large.status == bireg::CovarianceStatus::undefined);
  CHECK(too_large.message.find("1366 control points") != std::string::npos);
  // Undefined covariances are unbounded, never a number.
  CHECK(std::isinf(bireg::pose_covariance(too_large, 1.0)(0, 0)));
  CHECK(!bireg::pointwise_quantile(too_large, 0.95));
}

// Bands by simulation: 1,000 fits of a cubic SO(3) spline (7 control
// points on [0, 4], N = 100, noise 0.05 rad), and at three covariates (an
// end, inside a segment, a knot) whether the 95% ellipsoid of the pose and
// of the velocity holds the truth. Each rate is a binomial proportion of
// 1,000 (sd 0.7 % at 95 %); the 93-97 % is +-2.9 sd.
TEST_CASE("Spline bands cover the truth at their level (simulation)", "[spline][simulation]") {
  std::mt19937 rng(2026);
  const bireg::Spline<SO3> truth(3, 0.0, 1.0, random_points<SO3>(rng, 7, 0.5));
  const std::vector<double> at = {0.0, 1.37, 3.0};
  std::vector<int> pose_hits(at.size(), 0), velocity_hits(at.size(), 0);
  constexpr int kRuns = 1000;
  for (int run = 0; run < kRuns; ++run) {
    const Samples<SO3> data = sample(truth, 100, 0.05, rng);
    const auto fit = fit_on_knots(truth, data);
    REQUIRE(fit.ok());
    const auto c = bireg::spline_covariance(fit, data.f, data.t);
    REQUIRE(c.defined());
    const double q = *bireg::pointwise_quantile(c, 0.95);
    for (std::size_t p = 0; p < at.size(); ++p) {
      const double t = at[p];
      const SO3::Tangent pose_error =
          SO3::log(SO3::compose(SO3::inverse(truth(t)), (*fit.spline)(t)));
      const SO3::Tangent velocity_error = fit.spline->body_velocity(t) - truth.body_velocity(t);
      pose_hits[p] += bireg::mahalanobis_squared(bireg::pose_covariance(c, t), pose_error) <= q;
      velocity_hits[p] +=
          bireg::mahalanobis_squared(bireg::velocity_covariance(c, t), velocity_error) <= q;
    }
  }
  for (std::size_t p = 0; p < at.size(); ++p) {
    INFO("t = " << at[p] << ": pose " << pose_hits[p] << ", velocity " << velocity_hits[p] << " of "
                << kRuns);
    CHECK(pose_hits[p] >= 930);
    CHECK(pose_hits[p] <= 970);
    CHECK(velocity_hits[p] >= 930);
    CHECK(velocity_hits[p] <= 970);
  }
}

// Recovery: the RMS error of the fitted curve and of its velocity over the
// range, 40 fits each at N = 100 and N = 1600 (16x the data), falls by
// sqrt(16) = 4. Each RMS pools 40 fits x 41 covariates x 3 coordinates of
// strongly correlated errors (about 40 x 7 x 3 independent ones: relative
// sd ~ 1/sqrt(2 x 840) = 2.5 %), so the ratio is 4 within ~4 %; the bounds
// [3.5, 4.5] are 3 sd.
TEST_CASE("Spline fit error shrinks like N^-1/2 (simulation)", "[spline][simulation]") {
  std::mt19937 rng(77);
  const bireg::Spline<SO3> truth(3, 0.0, 1.0, random_points<SO3>(rng, 7, 0.5));
  const auto rms = [&](std::size_t n) {
    double pose = 0, velocity = 0;
    int count = 0;
    for (int run = 0; run < 40; ++run) {
      const Samples<SO3> data = sample(truth, n, 0.05, rng);
      const auto fit = fit_on_knots(truth, data);
      REQUIRE(fit.ok());
      for (int g = 0; g <= 40; ++g) {
        const double t = 4.0 * g / 40;
        pose += SO3::log(SO3::compose(SO3::inverse(truth(t)), (*fit.spline)(t))).squaredNorm();
        velocity += (fit.spline->body_velocity(t) - truth.body_velocity(t)).squaredNorm();
        ++count;
      }
    }
    return std::make_pair(std::sqrt(pose / count), std::sqrt(velocity / count));
  };
  const auto small = rms(100), large = rms(1600);
  INFO("N = 100: " << small.first << ", " << small.second << "; N = 1600: " << large.first << ", "
                   << large.second);
  CHECK(small.first / large.first > 3.5);
  CHECK(small.first / large.first < 4.5);
  CHECK(small.second / large.second > 3.5);
  CHECK(small.second / large.second < 4.5);
}

namespace {

// n samples of `curve` at covariates spread evenly over its whole range,
// its ends included (so that a spline fitted with the same spacing has the
// same knots), each times exp of N(0, noise^2) coordinates.
template <class G>
Samples<G> sample_evenly(const bireg::Spline<G>& curve, std::size_t n, double noise,
                         std::mt19937& rng) {
  Samples<G> out;
  for (std::size_t i = 0; i < n; ++i) {
    const double t = curve.t_min() + (curve.t_max() - curve.t_min()) * double(i) / double(n - 1);
    out.t.push_back(t);
    out.f.push_back(
        G::compose(curve(t), G::exp(bireg_test::normal_tangent<typename G::Tangent>(rng, noise))));
  }
  return out;
}

const bireg::CurveCandidate& recommended(const bireg::CurveSelection<SO3>& s) {
  return s.candidates.at(*s.recommended);
}

}  // namespace

// Each generating curve is recovered (N = 300, noise 0.03 rad, control
// points 0.6 rad apart, knots every 1 on [0, 5]): the geodesic from one
// geodesic, 5 segments of degree 1 from a piecewise geodesic, 5 segments of
// degree 3 from a cubic spline. The BIC gaps are large here: a wrong
// model's log det S_r grows by O(bias^2 / noise^2) per observation.
TEST_CASE("Curve selection recovers the generating curve", "[spline]") {
  std::mt19937 rng(21);
  const std::vector<SO3::Element> points = random_points<SO3>(rng, 8, 0.6);
  bireg::CurveSelectionOptions options;
  options.knot_spacings = {5.0, 2.5, 1.0, 0.5};
  const bireg::Spline<SO3> line(1, 0.0, 5.0, {points[0], points[3]});
  const bireg::Spline<SO3> polygon(1, 0.0, 1.0, {points.begin(), points.begin() + 6});
  const bireg::Spline<SO3> cubic(3, 0.0, 1.0, points);
  for (const auto& [truth, degree, segments] :
       {std::tuple{line, 0, std::size_t(1)}, std::tuple{polygon, 1, std::size_t(5)},
        std::tuple{cubic, 3, std::size_t(5)}}) {
    const Samples<SO3> data = sample_evenly(truth, 300, 0.03, rng);
    const auto selection = bireg::select_curve<SO3>(data.f, data.t, options);
    REQUIRE(selection.ok());
    INFO("truth degree " << degree << ": chose " << bireg::describe(recommended(selection)));
    CHECK(recommended(selection).degree == degree);
    CHECK(recommended(selection).segments == segments);
    // Candidates: the geodesic, the cubic for S = 1, then degree 1 and 3
    // for S = 2, 5, 10.
    CHECK(selection.candidates.size() == 8);
  }
}

TEST_CASE("Curve selection is left and right invariant on SO(3), and refuses bad input",
          "[spline]") {
  std::mt19937 rng(22);
  const bireg::Spline<SO3> truth(3, 0.0, 1.0, random_points<SO3>(rng, 7, 0.5));
  const Samples<SO3> data = sample(truth, 120, 0.05, rng);
  bireg::CurveSelectionOptions options;
  options.knot_spacings = {4.0, 1.0, 0.5};
  const SO3::Element g = SO3::exp(SO3::Tangent(0.4, -1.1, 2.0));
  Samples<SO3> moved = data;
  for (auto& f : moved.f)
    f = SO3::compose(SO3::compose(g, f), SO3::inverse(g));
  const auto a = bireg::select_curve<SO3>(data.f, data.t, options);
  const auto b = bireg::select_curve<SO3>(moved.f, moved.t, options);
  REQUIRE(a.ok());
  REQUIRE(b.ok());
  REQUIRE(a.candidates.size() == b.candidates.size());
  for (std::size_t c = 0; c < a.candidates.size(); ++c) {
    INFO(bireg::describe(a.candidates[c]));
    REQUIRE(a.candidates[c].fitted == b.candidates[c].fitted);
    if (!a.candidates[c].fitted) continue;
    CHECK(std::abs(a.candidates[c].criterion - b.candidates[c].criterion) <
          1e-8 * std::abs(a.candidates[c].criterion));
  }
  CHECK(*a.recommended == *b.recommended);

  std::vector<double> short_t(data.t.begin(), data.t.end() - 1);
  CHECK(bireg::select_curve<SO3>(data.f, short_t).status == bireg::SelectionStatus::invalid_input);
  options.knot_spacings = {1.0, -2.0};
  const auto bad = bireg::select_curve<SO3>(data.f, data.t, options);
  CHECK(bad.status == bireg::SelectionStatus::invalid_input);
  CHECK(bad.bad_index == 1);
  // Spacings too fine for 120 observations: those candidates are excluded
  // with the spline's own refusal, the rest still compete.
  options.knot_spacings = {1.0, 0.01};
  const auto fine = bireg::select_curve<SO3>(data.f, data.t, options);
  REQUIRE(fine.ok());
  bool excluded = false;
  for (const auto& c : fine.candidates)
    excluded = excluded || (!c.fitted && c.note.find("excluded: ") == 0);
  CHECK(excluded);
}
