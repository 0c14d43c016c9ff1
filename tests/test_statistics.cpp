// The statistics layer, deterministic checks: the covariance against
// textbook OLS on R^n, the permutation p-value against an independent F
// computation, equivariance on SO(3) and SE(3), the exact K against finite
// differences and the fit's series K, the bi-invariant mean, the quantiles,
// and every refusal. (Coverage and calibration by simulation:
// test_statistics_simulation.cpp.)
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <Eigen/LU>

#include "bireg/groups/rn.hpp"
#include "bireg/groups/se3.hpp"
#include "bireg/groups/so3.hpp"
#include "bireg/regression.hpp"
#include "bireg/statistics/inference/confidence.hpp"
#include "bireg/statistics/inference/covariance.hpp"
#include "bireg/statistics/inference/distributions.hpp"
#include "bireg/statistics/inference/explained_variance.hpp"
#include "bireg/statistics/inference/mean.hpp"
#include "bireg/statistics/inference/permutation.hpp"
#include "bireg/statistics/inference/trend_test.hpp"
#include "catch.hpp"
#include "test_support.hpp"

using bireg_test::relative_error;

namespace {

using R3 = bireg::Rn<3>;
using Matrix2 = Eigen::Matrix2d;

using bireg_test::normal_tangent;

template <class G>
struct Data {
  std::vector<typename G::Element> f;
  std::vector<double> t;
};

// N observations about g0 exp(s X) with Gaussian tangent noise of sd
// `noise`, covariates 2 + 5 s at random s in [0, 1] (both ends included).
template <class G>
Data<G> line_data(const typename G::Element& g0, const typename G::Tangent& x, int n, double noise,
                  std::mt19937& rng) {
  std::uniform_real_distribution<double> uniform(0, 1);
  Data<G> data;
  for (int i = 0; i < n; ++i) {
    const double s = i == 0 ? 0 : i == 1 ? 1 : uniform(rng);
    typename G::Element f = bireg::exp_at<G>(g0, s * x);
    if (noise > 0) f = bireg::exp_at<G>(f, normal_tangent<typename G::Tangent>(rng, noise));
    data.f.push_back(f);
    data.t.push_back(2 + 5 * s);
  }
  return data;
}

// A random element at distance ~`size` from the identity.
template <class G>
typename G::Element random_element(std::mt19937& rng, double size) {
  return G::exp(bireg_test::random_tangent<typename G::Tangent>(rng, size));
}

template <class G>
double distance(const typename G::Element& a, const typename G::Element& b) {
  return bireg::log_at<G>(a, b).norm();
}

template <class G>
typename bireg::GeodesicRegression<G>::Options tight_options() {
  typename bireg::GeodesicRegression<G>::Options options;
  options.tolerance = 1e-13;  // endpoints to rounding: comparisons at 1e-10 need it
  return options;
}

// Textbook OLS of y_i = beta0 + beta1 t_i on R^3, computed from the design
// matrix, independent of the library.
struct Ols {
  Eigen::Matrix2d xtx_inverse;
  Eigen::Matrix<double, 2, 3> beta;
  std::vector<Eigen::Vector3d> residuals;
  Eigen::Matrix3d error_scatter;  // E = sum e e^T
  Eigen::Matrix3d total_scatter;  // about the mean
};

Ols ols(const std::vector<Eigen::Vector3d>& y, const std::vector<double>& t) {
  const int n = static_cast<int>(y.size());
  Eigen::MatrixXd z(n, 2), yy(n, 3);
  for (int i = 0; i < n; ++i) {
    z(i, 0) = 1;
    z(i, 1) = t[static_cast<std::size_t>(i)];
    yy.row(i) = y[static_cast<std::size_t>(i)].transpose();
  }
  Ols o;
  o.xtx_inverse = (z.transpose() * z).inverse();
  o.beta = o.xtx_inverse * z.transpose() * yy;
  const Eigen::MatrixXd e = yy - z * o.beta;
  for (int i = 0; i < n; ++i)
    o.residuals.push_back(e.row(i).transpose());
  o.error_scatter = e.transpose() * e;
  const Eigen::MatrixXd centred = yy.rowwise() - yy.colwise().mean();
  o.total_scatter = centred.transpose() * centred;
  return o;
}

}  // namespace

TEST_CASE("quantiles match tabulated values", "[statistics][distributions]") {
  // Tabulated to 16 digits (R: qchisq, qt); the bisection resolves double.
  CHECK(std::abs(*bireg::chi_square_quantile(0.95, 1) - 3.841458820694124) < 1e-12);
  CHECK(std::abs(*bireg::chi_square_quantile(0.95, 6) - 12.591587243743977) < 1e-11);
  CHECK(std::abs(*bireg::chi_square_quantile(0.95, 12) - 21.02606981748307) < 1e-11);
  // F(1, nu) = t_nu^2: t_{0.975, 10} = 2.228138851986273.
  const double t10 = 2.228138851986273;
  CHECK(std::abs(*bireg::f_quantile(0.95, 1, 10) - t10 * t10) < 1e-11);
  // F(d1, inf) = chi2_d1 / d1.
  CHECK(std::abs(*bireg::f_quantile(0.95, 6, 1e9) - 12.591587243743977 / 6) < 1e-6);
  // McKeon's approximation is exact for q = 1 (Hotelling), and tends to
  // chi2_{pq} as nu grows.
  CHECK(*bireg::lawley_hotelling_quantile(0.95, 6, 1, 48) ==
        *bireg::hotelling_quantile(0.95, 6, 48));
  CHECK(std::abs(*bireg::lawley_hotelling_quantile(0.95, 6, 2, 1e7) - 21.02606981748307) < 1e-3);
  CHECK_FALSE(bireg::f_quantile(1.0, 2, 3));
  CHECK_FALSE(bireg::lawley_hotelling_quantile(0.95, 6, 2, 8));  // nu <= p + 3
}

TEST_CASE("on R^n the covariance is the OLS covariance of the line's end values",
          "[statistics][covariance]") {
  std::mt19937 rng(11);
  const Data<R3> data =
      line_data<R3>(Eigen::Vector3d(1, -2, 0.5), Eigen::Vector3d(3, 1, -2), 25, 0.3, rng);
  const auto fit = bireg::GeodesicRegression<R3>(tight_options<R3>()).fit(data.f, data.t);
  REQUIRE(fit.ok());
  const Ols o = ols(data.f, data.t);
  const double t_min = 2, t_max = 7;
  Eigen::Matrix2d l;
  l << 1, t_min, 1, t_max;
  const Eigen::Matrix2d ends = l * o.xtx_inverse * l.transpose();
  const Eigen::Matrix3d s = o.error_scatter / (25 - 2);
  // The OLS covariance of the end values, ends kron S.
  const auto ols_covariance = [&ends](const Eigen::Matrix3d& noise) {
    Eigen::Matrix<double, 6, 6> c;
    for (int j = 0; j < 2; ++j)
      for (int k = 0; k < 2; ++k)
        c.block<3, 3>(3 * j, 3 * k) = ends(j, k) * noise;
    return c;
  };
  const Eigen::Matrix<double, 6, 6> expected = ols_covariance(s);

  const auto homoscedastic = bireg::covariance(fit, data.t);
  REQUIRE(homoscedastic.defined());
  CHECK(homoscedastic.degrees_of_freedom == Approx(23).epsilon(1e-14));
  CHECK(relative_error(homoscedastic.endpoints, expected) < 1e-12);
  CHECK(relative_error(homoscedastic.residual, s) < 1e-12);
  // The velocity (slope) has covariance (Z^T Z)^{-1}_{11} S.
  CHECK(relative_error(bireg::velocity_covariance(homoscedastic),
                       Eigen::Matrix3d(o.xtx_inverse(1, 1) * s)) < 1e-12);
  // The pose at t: [1 t] (Z^T Z)^{-1} [1 t]^T S.
  const Eigen::Vector2d at(1, 4.2);
  CHECK(relative_error(bireg::pose_covariance(homoscedastic, 4.2),
                       Eigen::Matrix3d(at.dot(o.xtx_inverse * at) * s)) < 1e-12);

  // Robust: textbook HC2, sum_i (L A z_i)(L A z_i)^T kron e_i e_i^T / (1 - h_ii).
  Eigen::Matrix<double, 6, 6> hc2 = Eigen::Matrix<double, 6, 6>::Zero();
  for (std::size_t i = 0; i < data.t.size(); ++i) {
    const Eigen::Vector2d z(1, data.t[i]);
    const double leverage = z.dot(o.xtx_inverse * z);
    const Eigen::Vector2d a = l * o.xtx_inverse * z;
    const Eigen::Matrix3d ee = o.residuals[i] * o.residuals[i].transpose() / (1 - leverage);
    for (int j = 0; j < 2; ++j)
      for (int k = 0; k < 2; ++k)
        hc2.block<3, 3>(3 * j, 3 * k) += a[j] * a[k] * ee;
  }
  const auto robust = bireg::covariance(fit, data.t, {}, bireg::CovarianceFlavour::robust);
  REQUIRE(robust.defined());
  CHECK(relative_error(robust.endpoints, hc2) < 1e-12);

  // Noise in a plane (the third coordinate on an exact line): S has rank 2
  // and the meat rank 4 of 6, as on planar SE(3) data: the meat's square
  // root (endpoints = F F^T) must be exact on its range.
  Data<R3> planar = data;
  for (std::size_t i = 0; i < planar.t.size(); ++i)
    planar.f[i][2] = 0.5 - 0.3 * planar.t[i];
  const auto planar_fit =
      bireg::GeodesicRegression<R3>(tight_options<R3>()).fit(planar.f, planar.t);
  REQUIRE(planar_fit.ok());
  const Ols planar_ols = ols(planar.f, planar.t);
  const Eigen::Matrix3d planar_s = planar_ols.error_scatter / (25 - 2);
  const auto planar_c = bireg::covariance(planar_fit, planar.t);
  REQUIRE(planar_c.defined());
  CHECK(relative_error(planar_c.endpoints, ols_covariance(planar_s)) < 1e-12);
  CHECK(relative_error(bireg::velocity_covariance(planar_c),
                       Eigen::Matrix3d(o.xtx_inverse(1, 1) * planar_s)) < 1e-12);
}

TEST_CASE("the covariance does not depend on a common scale of the weights",
          "[statistics][covariance]") {
  std::mt19937 rng(12);
  const Data<R3> data =
      line_data<R3>(Eigen::Vector3d(0, 1, 2), Eigen::Vector3d(1, 1, 1), 30, 0.2, rng);
  std::uniform_real_distribution<double> uniform(0.2, 3);
  std::vector<double> w, w_scaled;
  for (std::size_t i = 0; i < data.t.size(); ++i) {
    w.push_back(uniform(rng));
    w_scaled.push_back(1e6 * w.back());
  }
  const bireg::GeodesicRegression<R3> regression(tight_options<R3>());
  const auto fit = regression.fit(data.f, data.t, w);
  const auto fit_scaled = regression.fit(data.f, data.t, w_scaled);
  for (const auto flavour :
       {bireg::CovarianceFlavour::homoscedastic, bireg::CovarianceFlavour::robust}) {
    const auto c = bireg::covariance(fit, data.t, w, flavour);
    const auto c_scaled = bireg::covariance(fit_scaled, data.t, w_scaled, flavour);
    REQUIRE(c.defined());
    CHECK(relative_error(c_scaled.endpoints, c.endpoints) < 1e-12);
    CHECK(c_scaled.degrees_of_freedom == Approx(c.degrees_of_freedom).epsilon(1e-13));
  }
  // Unequal weights: nu = W - tr(H^{-1} H_2) < N - 2 (fewer effective observations).
  const auto c = bireg::covariance(fit, data.t, w);
  CHECK(c.degrees_of_freedom < 28);
  CHECK(c.degrees_of_freedom > 10);
  // The value itself, from the documented formula evaluated here in long
  // double on the raw covariates z = (1, t) (tr(H^{-1} H_2) is unchanged by
  // the library's affine map of t to [0, 1]: H -> A H A^T, H_2 -> A H_2 A^T),
  // with the weights divided by the largest as the library does (nu scales
  // like w). A 2x2 inverse of a well-conditioned H and sums of 30 positive
  // terms: rounding ~1e-15 relative; 1e-12 leaves room for the library's
  // double. The weight-blind W - 2 is 0.69 (5%) away here, checked last so
  // that the comparison is known to discriminate.
  long double w_sum = 0, w_max = 0;
  Eigen::Matrix<long double, 2, 2> h = Eigen::Matrix<long double, 2, 2>::Zero(), h2 = h;
  for (std::size_t i = 0; i < w.size(); ++i) {
    const Eigen::Matrix<long double, 2, 1> z(1.0L, static_cast<long double>(data.t[i]));
    w_sum += w[i];
    w_max = std::max<long double>(w_max, w[i]);
    h += w[i] * z * z.transpose();
    h2 += static_cast<long double>(w[i]) * w[i] * z * z.transpose();
  }
  const long double nu = (w_sum - (h.inverse() * h2).trace()) / w_max;
  CHECK(c.degrees_of_freedom == Approx(static_cast<double>(nu)).epsilon(1e-12));
  CHECK(std::abs(static_cast<double>(nu) - (w_sum / w_max - 2)) > 0.5);
}

TEST_CASE("on R^n the permutation p-value equals the OLS F test's with the same permutations",
          "[statistics][trend]") {
  std::mt19937 rng(13);
  // A weak trend, so that p lands strictly inside (0, 1).
  const Data<R3> data =
      line_data<R3>(Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0.25, 0, -0.1), 25, 0.3, rng);
  bireg::TrendTestOptions options;
  options.permutations = 199;
  options.seed = 2024;
  const auto test = bireg::trend_test(bireg::GeodesicRegression<R3>(tight_options<R3>()), data.f,
                                      data.t, {}, options);
  REQUIRE(test.ok());

  // Independently: Wilks' Lambda and F = (1 - Lambda)/Lambda (nu - p + 1)/p
  // (exact for one predictor) from the OLS scatter matrices.
  const int n = 25, p = 3;
  const auto f_statistic = [&](const std::vector<double>& t) {
    const Ols o = ols(data.f, t);
    const double lambda = o.error_scatter.determinant() / o.total_scatter.determinant();
    return (1 - lambda) / lambda * (n - 2 - p + 1) / p;
  };
  const double f_observed = f_statistic(data.t);
  const Ols o = ols(data.f, data.t);
  CHECK(test.statistic ==
        Approx(o.error_scatter.determinant() / o.total_scatter.determinant()).epsilon(1e-12));
  int at_least = 0;
  std::vector<std::size_t> order;
  std::vector<double> permuted(data.t.size());
  for (int b = 0; b < options.permutations; ++b) {
    bireg::permutation(options.seed, static_cast<std::uint64_t>(b), data.t.size(), order);
    for (std::size_t i = 0; i < data.t.size(); ++i)
      permuted[i] = data.t[order[i]];
    if (f_statistic(permuted) >= f_observed * (1 - 1e-9)) ++at_least;
  }
  const double p_expected = (1.0 + at_least) / (options.permutations + 1);
  std::printf("R^3 trend test: Lambda = %.6f, F = %.4f, p = %.4f (independent %.4f)\n",
              test.statistic, f_observed, test.p_value, p_expected);
  CHECK(test.p_value == p_expected);
  CHECK(test.p_value > 0.005);  // the case is not degenerate
  CHECK(test.p_value < 0.9);
}

// A permuted fit stops as soon as its verdict is certain
// (trend_detail::LambdaDecision). The verdicts must be those of permuted
// fits run to convergence: the same count of permutations at least as
// extreme, for null data (Lambda_b near Lambda for many b: near-ties go to
// convergence), a weak trend (p inside (0, 1)) and a strong one (every
// Lambda_b far above Lambda: decided early), from every start.
TEMPLATE_TEST_CASE("early verdicts of the permuted fits are those of converged fits",
                   "[statistics][trend]", bireg::SO3d, bireg::SE3d) {
  using G = TestType;
  using Tangent = typename G::Tangent;
  std::mt19937 rng(21);
  const bireg::GeodesicRegression<G> regression;
  int decided = 0, permutations = 0;
  for (const double trend : {0.0, 0.15, 2.0}) {
    Tangent x = bireg_test::random_tangent<Tangent>(rng, 1);
    x *= trend / x.norm();
    const auto data = line_data<G>(random_element<G>(rng, 1), x, 40, 0.3, rng);
    for (const auto start : {bireg::PermutationStart::chart, bireg::PermutationStart::fitted,
                             bireg::PermutationStart::mean}) {
      bireg::TrendTestOptions options;
      options.permutations = 999;
      options.seed = 8;
      options.start = start;
      const auto early = bireg::trend_test(regression, data.f, data.t, {}, options);
      options.decide_early = false;
      const auto converged = bireg::trend_test(regression, data.f, data.t, {}, options);
      REQUIRE((early.ok() && converged.ok()));
      CHECK(converged.decided_permutations == 0);
      CHECK(early.at_least_as_extreme == converged.at_least_as_extreme);
      CHECK(early.failed_permutations == converged.failed_permutations);
      CHECK(early.p_value == converged.p_value);
      std::printf("%s trend %.2f start %d: p = %.3f, %d of 999 decided early\n", G::name, trend,
                  static_cast<int>(start), early.p_value, early.decided_permutations);
      decided += early.decided_permutations;
      permutations += options.permutations;
      if (trend == 2.0) CHECK(early.p_value == 1.0 / 1000);  // 7 noise sd per coordinate
    }
  }
  // The decision is what makes permutations cheaper than fits: most of
  // them must end early.
  CHECK(decided > permutations / 2);
}

TEST_CASE("permutations depend only on (seed, b) and are uniform", "[statistics][trend]") {
  std::vector<std::size_t> a, b;
  bireg::permutation(7, 3, 10, a);
  bireg::permutation(7, 4, 10, b);
  CHECK(a != b);
  bireg::permutation(7, 3, 10, b);
  CHECK(a == b);
  // Position of element 0 over 20000 permutations of 5: each of the 5
  // places with probability 1/5; binomial sd sqrt(20000 * 0.16) = 57, so
  // +-300 is 5 sd.
  std::vector<int> count(5, 0);
  for (std::uint64_t k = 0; k < 20000; ++k) {
    bireg::permutation(1, k, 5, a);
    for (std::size_t i = 0; i < 5; ++i)
      if (a[i] == 0) ++count[i];
  }
  for (int c : count)
    CHECK(std::abs(c - 4000) < 300);
}

TEMPLATE_TEST_CASE("covariances and the trend test keep the estimator's equivariance",
                   "[statistics][equivariance]", bireg::SO3d, bireg::SE3d) {
  using G = TestType;
  using Tangent = typename G::Tangent;
  constexpr int d = G::dof;
  std::mt19937 rng(14);
  Tangent x = bireg_test::random_tangent<Tangent>(rng, 1);
  x.template tail<3>() *= 1.0 / x.template tail<3>().norm();  // 1 rad
  const auto data = line_data<G>(random_element<G>(rng, 1), x, 30, 0.05, rng);
  const typename G::Element h = random_element<G>(rng, 1.5);
  std::vector<typename G::Element> left, right;
  for (const auto& f : data.f) {
    left.push_back(G::compose(h, f));
    right.push_back(G::compose(f, h));
  }
  const bireg::GeodesicRegression<G> regression(tight_options<G>());
  const auto fit = regression.fit(data.f, data.t);
  const auto fit_left = regression.fit(left, data.t);
  const auto fit_right = regression.fit(right, data.t);
  REQUIRE((fit.ok() && fit_left.ok() && fit_right.ok()));
  Eigen::Matrix<double, 2 * d, 2 * d> ad2 = Eigen::Matrix<double, 2 * d, 2 * d>::Zero();
  const typename G::AdMatrix ad = G::Ad(G::inverse(h));
  ad2.template topLeftCorner<d, d>() = ad;
  ad2.template bottomRightCorner<d, d>() = ad;
  for (const auto flavour :
       {bireg::CovarianceFlavour::homoscedastic, bireg::CovarianceFlavour::robust}) {
    const auto c = bireg::covariance(fit, data.t, {}, flavour);
    const auto c_left = bireg::covariance(fit_left, data.t, {}, flavour);
    const auto c_right = bireg::covariance(fit_right, data.t, {}, flavour);
    REQUIRE((c.defined() && c_left.defined() && c_right.defined()));
    CHECK(relative_error(c_left.endpoints, c.endpoints) < 1e-10);
    const Eigen::Matrix<double, 2 * d, 2 * d> moved = ad2 * c.endpoints * ad2.transpose();
    CHECK(relative_error(c_right.endpoints, moved) < 1e-10);
    CHECK(relative_error(
              bireg::velocity_covariance(c_right),
              typename G::AdMatrix(ad * bireg::velocity_covariance(c) * ad.transpose())) < 1e-10);
  }
  bireg::TrendTestOptions options;
  options.permutations = 99;
  options.seed = 5;
  const auto test = bireg::trend_test(regression, data.f, data.t, {}, options);
  const auto test_left = bireg::trend_test(regression, left, data.t, {}, options);
  const auto test_right = bireg::trend_test(regression, right, data.t, {}, options);
  REQUIRE((test.ok() && test_left.ok() && test_right.ok()));
  CHECK(std::abs(test_left.statistic - test.statistic) < 1e-10 * test.statistic);
  CHECK(std::abs(test_right.statistic - test.statistic) < 1e-10 * test.statistic);
  CHECK(test_left.p_value == test.p_value);
  CHECK(test_right.p_value == test.p_value);
  // The generalised explained variance is left and right invariant too.
  const auto e = bireg::explained_variance(fit, bireg::mean<G>(data.f));
  const auto e_right = bireg::explained_variance(fit_right, bireg::mean<G>(right));
  REQUIRE((e.defined && e_right.defined));
  CHECK(std::abs(e_right.generalized - e.generalized) < 1e-10);
  CHECK(e.generalized == Approx(1 - test.statistic).epsilon(1e-10));
}

// math/ad_algebra.hpp's contract on SO(3) and SE(3): the relations of
// A = ad_X, N1 and N2, and the Jacobians, products and inverses it computes
// from five coefficients, against the matrices. Rounding only: 1e-13
// relative (the matrices' entries grow like theta^3; up to theta = 4.5).
TEMPLATE_TEST_CASE("the algebra of ad_X: relations, Jacobians, products and inverses",
                   "[statistics][covariance]", bireg::SO3d, bireg::SE3d) {
  using G = TestType;
  using Tangent = typename G::Tangent;
  using AdMatrix = typename G::AdMatrix;
  using Function = bireg::AdFunction<double>;
  std::mt19937 rng(31);
  std::uniform_real_distribution<double> uniform(-1, 1);
  for (const double angle : {1e-4, 0.3, 1.0, 2.5, 3.1, 4.5}) {
    Tangent x = bireg_test::random_tangent<Tangent>(rng, 1);
    x.template tail<3>() *= angle / x.template tail<3>().norm();
    const bireg::AdAlgebraBasis<AdMatrix> basis = G::ad_algebra_basis(x);
    const AdMatrix a = G::ad(x);
    const double size = 1 + a.norm() * a.norm() * a.norm();
    CHECK((basis.a - a).norm() == 0);
    CHECK((basis.a2 - a * a).norm() <= 1e-14 * size);
    CHECK((a * a * a + basis.theta2 * a + 2 * basis.kappa * basis.n1).norm() <= 1e-13 * size);
    CHECK((a * basis.n1 - basis.n2).norm() <= 1e-14 * size);
    CHECK((basis.n1 * a - basis.n2).norm() <= 1e-14 * size);
    CHECK((a * basis.n2 + basis.theta2 * basis.n1).norm() <= 1e-13 * size);
    CHECK((basis.n2 * a + basis.theta2 * basis.n1).norm() <= 1e-13 * size);
    for (const double s : {-0.7, 0.4, 1.0}) {
      const Function inverse = basis.right_jacobian_inverse(s);
      CHECK(relative_error(basis.matrix(inverse), G::right_jacobian_inverse(Tangent(s * x))) <
            1e-13);
      CHECK(relative_error(basis.matrix(basis.inverse(inverse)),
                           G::right_jacobian(Tangent(s * x))) < 1e-13);
    }
    const Function f{1 + uniform(rng), uniform(rng), uniform(rng), uniform(rng), uniform(rng)};
    const Function g{1 + uniform(rng), uniform(rng), uniform(rng), uniform(rng), uniform(rng)};
    const AdMatrix product = basis.matrix(f) * basis.matrix(g);
    CHECK(relative_error(basis.matrix(basis.product(f, g)), product) < 1e-13);
    CHECK(relative_error(basis.matrix(basis.product(f, basis.inverse(f))),
                         AdMatrix(AdMatrix::Identity())) < 1e-12);
  }
}

// The covariance's pass in the algebra of ad_X (the default on SO(3) and
// SE(3)) against the pass with d x d Jacobians per observation: the same
// sums in another order, so the same covariance to rounding (1e-12
// relative; the robust degrees of freedom, through eigenvalues, 1e-10), for
// short and long geodesics, weighted, both flavours.
TEMPLATE_TEST_CASE("the covariance in the algebra of ad_X equals the matrix pass",
                   "[statistics][covariance]", bireg::SO3d, bireg::SE3d) {
  using G = TestType;
  using Tangent = typename G::Tangent;
  std::mt19937 rng(32);
  std::uniform_real_distribution<double> uniform(0.2, 2.0);
  for (const double angle : {0.01, 1.0, 3.0}) {
    Tangent x = bireg_test::random_tangent<Tangent>(rng, 1);
    x.template tail<3>() *= angle / x.template tail<3>().norm();
    const auto data = line_data<G>(random_element<G>(rng, 1), x, 40, 0.1, rng);
    std::vector<double> weights(data.t.size());
    for (double& w : weights)
      w = uniform(rng);
    const auto fit = bireg::GeodesicRegression<G>(tight_options<G>()).fit(data.f, data.t, weights);
    REQUIRE(fit.ok());
    bireg::Problem<double> problem;
    const std::pair<long double, long double> interval(fit.geodesic->t_min(),
                                                       fit.geodesic->t_max());
    REQUIRE(!bireg::make_problem(data.t, weights, std::optional(interval), problem));
    for (const auto flavour :
         {bireg::CovarianceFlavour::homoscedastic, bireg::CovarianceFlavour::robust}) {
      const auto algebra = bireg::covariance_of(*fit.geodesic, fit.residuals, problem, flavour);
      const auto matrices = bireg::covariance_of<G, bireg::CovariancePass::matrices>(
          *fit.geodesic, fit.residuals, problem, flavour);
      REQUIRE((algebra.defined() && matrices.defined()));
      CHECK(relative_error(algebra.endpoints, matrices.endpoints) < 1e-12);
      CHECK(relative_error(algebra.jacobian, matrices.jacobian) < 1e-12);
      CHECK(std::abs(algebra.effective.velocity - matrices.effective.velocity) <
            1e-10 * matrices.effective.velocity);
      CHECK(std::abs(algebra.effective.endpoints - matrices.effective.endpoints) <
            1e-10 * matrices.effective.endpoints);
    }
  }
}

TEMPLATE_TEST_CASE("the exact K matches finite differences of the force and the series K is close",
                   "[statistics][covariance]", bireg::SO3d, bireg::SE3d) {
  using G = TestType;
  using Tangent = typename G::Tangent;
  constexpr int d = G::dof;
  std::mt19937 rng(15);
  for (const double angle : {0.5, 1.0, 2.0, 3.0}) {
    Tangent x = bireg_test::random_tangent<Tangent>(rng, 1);
    x.template tail<3>() *= angle / x.template tail<3>().norm();
    const typename G::Element g0 = random_element<G>(rng, 1);
    // Noise-free data (K is -dv/d(delta) where the residuals vanish) plus a
    // copy with noise to obtain a defined covariance at the same geodesic.
    const auto clean = line_data<G>(g0, x, 40, 0, rng);
    auto noisy = clean;
    for (auto& f : noisy.f)
      f = bireg::exp_at<G>(f, normal_tangent<Tangent>(rng, 1e-3));
    const auto fit = bireg::GeodesicRegression<G>(tight_options<G>()).fit(noisy.f, noisy.t);
    REQUIRE(fit.ok());
    const auto c = bireg::covariance(fit, noisy.t);
    REQUIRE(c.defined());

    // -dv/d(delta) at the noise-free geodesic by central differences (step
    // 1e-6: truncation ~1e-12, rounding ~1e-16/1e-6 = 1e-10 relative).
    bireg::Problem<double> problem;
    REQUIRE_FALSE(bireg::make_problem(clean.t, std::vector<double>{}, {}, problem));
    const bireg::PsiEvaluation psi{};
    std::vector<Tangent> residuals(clean.f.size());
    const typename G::Element g1 = bireg::exp_at<G>(g0, x);
    Eigen::Matrix<double, 2 * d, 2 * d> k_numeric;
    const double step = 1e-6;
    for (int j = 0; j < 2 * d; ++j) {
      Eigen::Matrix<double, 2 * d, 1> e = Eigen::Matrix<double, 2 * d, 1>::Zero();
      e[j] = step;
      const auto force_at = [&](double sign) {
        const auto state = bireg::evaluate<G>(
            clean.f, problem, psi, bireg::exp_at<G>(g0, Tangent(sign * e.template head<d>())),
            bireg::exp_at<G>(g1, Tangent(sign * e.template tail<d>())), residuals);
        Eigen::Matrix<double, 2 * d, 1> v;
        v << state.force.v0, state.force.v1;
        return v;
      };
      k_numeric.col(j) = -(force_at(1) - force_at(-1)) / (2 * step);
    }
    // The exact K at the noisy fit's geodesic (1e-3 away): compare with
    // the closed form at the clean one instead.
    auto clean_fit = fit;
    clean_fit.geodesic = bireg::Geodesic<G>(g0, g1, 2, 7);
    clean_fit.residuals.assign(clean.f.size(), Tangent::Constant(1e-3));
    const auto c_clean = bireg::covariance(clean_fit, clean.t);
    REQUIRE(c_clean.defined());
    const double exact_error = static_cast<double>(relative_error(c_clean.jacobian, k_numeric));
    const double series_error = static_cast<double>(relative_error(fit.jacobian, c.jacobian));
    const double bound = std::pow(angle / (4 * std::acos(0.0)), bireg::kGaussNewtonOrder);
    std::printf(
        "%s |X| = %.1f rad: exact K vs finite differences %.1e, series-16 K vs exact %.1e "
        "(bound (rho/2pi)^16 = %.1e)\n",
        G::name, angle, exact_error, series_error, bound);
    CHECK(exact_error < 1e-8);
    CHECK(series_error < 10 * bound + 1e-13);
  }
}

TEMPLATE_TEST_CASE("the bi-invariant mean: Newton's limit, equivariance, order",
                   "[statistics][mean]", bireg::SO3d, bireg::SE3d) {
  using G = TestType;
  using Tangent = typename G::Tangent;
  std::mt19937 rng(16);
  const typename G::Element centre = random_element<G>(rng, 1);
  std::vector<typename G::Element> f;
  std::vector<double> w;
  std::uniform_real_distribution<double> uniform(0.5, 2);
  for (int i = 0; i < 40; ++i) {
    // Spread ~1 rad: entries uniform in [-0.6, 0.6].
    f.push_back(bireg::exp_at<G>(centre, bireg_test::random_tangent<Tangent>(rng, 0.6)));
    w.push_back(uniform(rng));
  }
  const auto newton = bireg::mean<G>(f, w);
  REQUIRE(newton.ok());
  bireg::MeanOptions<double> fixed_point_options;
  fixed_point_options.newton = false;
  fixed_point_options.tolerance = 1e-15;
  fixed_point_options.max_iterations = 10000;
  const auto fixed_point = bireg::mean<G>(f, w, fixed_point_options);
  REQUIRE(fixed_point.mean);
  std::printf("%s mean, spread ~1 rad: Newton %d iterations, fixed point %d\n", G::name,
              newton.iterations, fixed_point.iterations);
  CHECK(distance<G>(*newton.mean, *fixed_point.mean) < 1e-12);
  CHECK(newton.residual_norm < 1e-12);
  CHECK(3 * newton.iterations <= fixed_point.iterations);

  const typename G::Element h = random_element<G>(rng, 1.5);
  std::vector<typename G::Element> left, right, inverted, reversed(f.rbegin(), f.rend());
  for (const auto& g : f) {
    left.push_back(G::compose(h, g));
    right.push_back(G::compose(g, h));
    inverted.push_back(G::inverse(g));
  }
  const std::vector<double> w_reversed(w.rbegin(), w.rend());
  CHECK(distance<G>(*bireg::mean<G>(left, w).mean, G::compose(h, *newton.mean)) < 1e-12);
  CHECK(distance<G>(*bireg::mean<G>(right, w).mean, G::compose(*newton.mean, h)) < 1e-12);
  CHECK(distance<G>(*bireg::mean<G>(inverted, w).mean, G::inverse(*newton.mean)) < 1e-12);
  CHECK(distance<G>(*bireg::mean<G>(reversed, w_reversed).mean, *newton.mean) < 1e-12);
  // Uniform weights of any size give the unweighted mean.
  CHECK(distance<G>(*bireg::mean<G>(f, std::vector<double>(40, 1e-200)).mean,
                    *bireg::mean<G>(f).mean) < 1e-12);
}

namespace {
// SO(3) whose log is defined on the ball of radius 2.5 only (NaN beyond),
// like a matrix group's log on matrices with negative eigenvalues.
struct BallSO3 : bireg::SO3d {
  static constexpr const char* name = "BallSO3";
  static Tangent log(const Element& g) {
    Tangent x = bireg::SO3d::log(g);
    if (x.norm() > 2.5) x.setConstant(std::numeric_limits<double>::quiet_NaN());
    return x;
  }
};
}  // namespace

TEST_CASE("the mean refuses empty input and reports non-convergence", "[statistics][mean]") {
  const auto empty = bireg::mean<bireg::SO3d>(std::vector<Eigen::Matrix3d>{});
  CHECK(empty.status == bireg::Status::invalid_input);
  CHECK_FALSE(empty.message.empty());
  CHECK_FALSE(empty.mean);

  std::mt19937 rng(17);
  std::vector<Eigen::Matrix3d> spread;
  for (int i = 0; i < 10; ++i)
    spread.push_back(bireg::SO3d::exp(bireg_test::random_tangent<Eigen::Vector3d>(rng, 1)));
  bireg::MeanOptions<double> one_step;
  one_step.max_iterations = 1;
  const auto cut = bireg::mean<bireg::SO3d>(spread, {}, one_step);
  CHECK(cut.status == bireg::Status::max_iterations);
  CHECK_FALSE(cut.message.empty());
  REQUIRE(cut.mean);
  CHECK(cut.mean->allFinite());

  // Rotations of +-1.5 rad about z: 3 rad apart, beyond BallSO3's log.
  const Eigen::Vector3d z(0, 0, 1);
  const std::vector<Eigen::Matrix3d> far = {bireg::SO3d::exp(1.5 * z), bireg::SO3d::exp(-1.5 * z)};
  const auto outside = bireg::mean<BallSO3>(far);
  CHECK(outside.status == bireg::Status::diverged);
  CHECK_FALSE(outside.message.empty());
  REQUIRE(outside.mean);
  CHECK(outside.mean->allFinite());

  const auto negative = bireg::mean<bireg::SO3d>(far, {1, -1});
  CHECK(negative.status == bireg::Status::invalid_input);
  CHECK(negative.bad_index == 1);
}

TEST_CASE("covariances that cannot be estimated are refused with a message, never NaN",
          "[statistics][hostile]") {
  using G = bireg::SO3d;
  const Eigen::Vector3d x(0.3, -0.2, 0.5);
  const auto all_finite_zero = [](const bireg::FitCovariance<G>& c) {
    return c.endpoints.allFinite() && c.endpoints.isZero(0) && c.residual.allFinite();
  };
  const bireg::GeodesicRegression<G> regression;
  // N = 2: no degrees of freedom.
  const std::vector<Eigen::Matrix3d> two = {G::identity(), G::exp(x)};
  const std::vector<double> t2 = {0, 1};
  const auto fit2 = regression.fit(two, t2);
  REQUIRE(fit2.ok());
  for (const auto flavour :
       {bireg::CovarianceFlavour::homoscedastic, bireg::CovarianceFlavour::robust}) {
    const auto c = bireg::covariance(fit2, t2, {}, flavour);
    CHECK(c.status == bireg::CovarianceStatus::undefined);
    CHECK(c.message.find("degrees of freedom") != std::string::npos);
    CHECK(all_finite_zero(c));
  }
  // Zero residuals: noise-free data.
  std::vector<Eigen::Matrix3d> clean;
  std::vector<double> t;
  for (int i = 0; i < 10; ++i) {
    t.push_back(i);
    clean.push_back(G::exp(i / 9.0 * x));
  }
  const auto fit_clean = regression.fit(clean, t);
  REQUIRE(fit_clean.ok());
  const auto c_clean = bireg::covariance(fit_clean, t);
  CHECK(c_clean.status == bireg::CovarianceStatus::undefined);
  CHECK(c_clean.message.find("residuals vanish") != std::string::npos);
  CHECK(all_finite_zero(c_clean));
  // Robust flavour, a quantity every observation of which fits exactly:
  // two identical observations at t = 0 pin the start (zero residuals and
  // zero robust covariance); the homoscedastic flavour pools the residuals
  // at t = 1 and stays defined.
  const std::vector<Eigen::Matrix3d> pinned = {G::identity(), G::exp(x), G::identity(),
                                               G::exp(1.001 * x)};
  const std::vector<double> t_pinned = {0, 1, 0, 1};
  const auto fit_pinned = regression.fit(pinned, t_pinned);
  REQUIRE(fit_pinned.ok());
  CHECK(bireg::covariance(fit_pinned, t_pinned).defined());
  const auto c_pinned =
      bireg::covariance(fit_pinned, t_pinned, {}, bireg::CovarianceFlavour::robust);
  CHECK(c_pinned.status == bireg::CovarianceStatus::undefined);
  CHECK(c_pinned.message.find("robust covariance of the start is zero") != std::string::npos);
  CHECK(all_finite_zero(c_pinned));
  // A failed fit, and covariates that are not the fit's.
  bireg::RegressionResult<G> failed;
  CHECK(bireg::covariance(failed, t).status == bireg::CovarianceStatus::invalid_input);
  CHECK(bireg::covariance(fit_clean, t2).status == bireg::CovarianceStatus::invalid_input);
  // Permutation counts below 1.
  for (const int b : {0, -3}) {
    bireg::TrendTestOptions options;
    options.permutations = b;
    const auto test = bireg::trend_test(regression, clean, t, {}, options);
    CHECK(test.status == bireg::Status::invalid_input);
    CHECK(test.message.find("permutations") != std::string::npos);
    CHECK(test.p_value == 1);
  }
}

TEST_CASE("the covariance stays positive semi-definite when the sandwich's bread is huge",
          "[statistics][hostile]") {
  // A fuzzer's EuRoC input: three poses, the first 9.1e15 m from the other
  // two, which lie 5 ms apart 1.4e9 s later. K^{-1} D then has entries near
  // 1e19 that cancel; bread * meat * bread^T came out with an eigenvalue of
  // -5% of the largest. Formed as the Gram matrix (bread R)(bread R)^T,
  // meat = R R^T, its eigenvalues are >= -gamma_12 * 12 * lambda_max
  // (about 2e-14 lambda_max): 1e-12 leaves a margin of 50.
  using G = bireg::SE3d;
  const auto pose = [](double x, double y, double z, double qw, double qx, double qy, double qz) {
    Eigen::Matrix4d g = Eigen::Matrix4d::Identity();
    g.topLeftCorner<3, 3>() = Eigen::Quaterniond(qw, qx, qy, qz).normalized().toRotationMatrix();
    g.topRightCorner<3, 1>() = Eigen::Vector3d(x, y, z);
    return g;
  };
  const std::vector<Eigen::Matrix4d> poses = {
      pose(9.124868548934227e15, -0.06850753331747607, 0.3150191124732355, 0.9455427467358475,
           0.20792539390782702, -0.07567889778781337, 0.23872295468413973),
      pose(1.1746243795998712, -0.10889464389080061, 0.31359871122050165, 0.9462293090021733,
           0.21986772857801867, -0.022656211382351635, 0.23620959506550668),
      pose(1.2109982056753175, -0.1347974620049659, 0.30588515418110673, 0.9319344973553353,
           0.2793734139399386, -0.0036421902114731263, 0.2311608156091031)};
  const std::vector<double> t = {0, 1403496216.1155787, 1403496216.1205785};
  const auto fit = bireg::GeodesicRegression<G>().fit(poses, t);
  REQUIRE(fit.ok());
  const auto c = bireg::covariance(fit, t);
  REQUIRE(c.defined());
  REQUIRE(c.endpoints.allFinite());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 12, 12>> eigen(c.endpoints,
                                                                           Eigen::EigenvaluesOnly);
  const double largest = eigen.eigenvalues().maxCoeff();
  CHECK(largest > 0);
  CHECK(eigen.eigenvalues().minCoeff() >= -1e-12 * largest);
  // So are the velocity's and the poses' covariances, formed from the
  // factor F (endpoints = F F^T) by the same argument.
  const auto positive_semidefinite = [](const Eigen::Matrix<double, 6, 6>& m) {
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> e(m, Eigen::EigenvaluesOnly);
    return e.eigenvalues().maxCoeff() > 0 &&
           e.eigenvalues().minCoeff() >= -1e-12 * e.eigenvalues().maxCoeff();
  };
  CHECK(positive_semidefinite(bireg::velocity_covariance(c)));
  for (const double at : {0.0, 7e8, 1403496216.1205785})
    CHECK(positive_semidefinite(bireg::pose_covariance(c, at)));
}

TEST_CASE("planar SE(3) data: pseudo-determinants, said so", "[statistics][trend]") {
  using G = bireg::SE3d;
  std::mt19937 rng(18);
  std::vector<Eigen::Matrix4d> f;
  std::vector<double> t;
  for (int i = 0; i < 30; ++i) {
    G::Tangent xi = G::Tangent::Zero();  // rho = (x, y, 0), omega = (0, 0, w)
    xi[0] = 0.5 * i / 29.0 + normal_tangent<Eigen::Vector3d>(rng, 0.05)[0];
    xi[1] = normal_tangent<Eigen::Vector3d>(rng, 0.05)[0];
    xi[5] = 0.8 * i / 29.0 + normal_tangent<Eigen::Vector3d>(rng, 0.05)[0];
    f.push_back(G::exp(xi));
    t.push_back(i);
  }
  bireg::TrendTestOptions options;
  options.permutations = 49;
  const auto test = bireg::trend_test(bireg::GeodesicRegression<G>(), f, t, {}, options);
  REQUIRE(test.ok());
  CHECK(test.rank == 3);
  CHECK(test.pseudo_determinant);
  CHECK(test.message.find("pseudo-determinant") != std::string::npos);
  CHECK(test.statistic > 0);
  CHECK(test.statistic < 0.2);
  CHECK(test.p_value == Approx(0.02));  // 1/(49 + 1): the trend is strong
  const auto c = bireg::covariance(test.fit, t);
  REQUIRE(c.defined());
  CHECK(bireg::covariance_rank(c.endpoints) == 6);
  CHECK(c.endpoints.allFinite());
}
