// libFuzzer target: the statistics layer on hostile data sets
// (fuzz_data.hpp) -- fit() and everything computed from a fit: the mean,
// both covariance flavours and the confidence helpers at any covariate and
// level, the explained variance, the trend test, the robust fit with any
// loss (an enumeration value outside Loss included), the two-sample test,
// and the distributions' quantiles at any arguments.
//
// The first byte selects the group (bit 0: SE(3), the poses; GL+(3), the
// deformation gradients) and the solver (bit 1); the rest is the data set
// and the options. Properties checked (abort = finding): the contract of
// docs/hostile_input.md, whatever the input --
//   * a refusal carries a message, and so does a failure status of the
//     layers above fit() (fit()'s own failure is its status);
//   * an ok result holds no NaN and no infinity (the fitted curve at every
//     finite covariate, the residuals, the mean, a defined covariance, the
//     statistics and p-values in (0, 1]);
//   * a defined covariance is symmetric and positive semi-definite;
//   * the helpers that return a bare number or matrix (pose_covariance at
//     any covariate, half_widths, mahalanobis_squared, the quantiles)
//     return no NaN: +infinity outside their domain.
//
// Build and run (clang): see fuzz_fit.cpp, target fuzz_statistics, corpus
// tests/fuzz/corpus_fuzz_statistics.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <type_traits>
#include <vector>

#include <fuzzer/FuzzedDataProvider.h>
#include <Eigen/Core>

#include "bireg/groups/matrix_group.hpp"
#include "bireg/groups/se3.hpp"
#include "bireg/regression.hpp"
#include "bireg/statistics/cohorts/two_sample.hpp"
#include "bireg/statistics/inference/confidence.hpp"
#include "bireg/statistics/inference/covariance.hpp"
#include "bireg/statistics/inference/distributions.hpp"
#include "bireg/statistics/inference/explained_variance.hpp"
#include "bireg/statistics/inference/mean.hpp"
#include "bireg/statistics/inference/trend_test.hpp"
#include "bireg/statistics/robust/regression.hpp"
#include "fuzz_data.hpp"

namespace {

using bireg_fuzz::number;
using bireg_fuzz::require;
using bireg_fuzz::require_message;

// No NaN: a bare helper's number is finite or +infinity (unbounded).
template <class M>
void require_no_nan(const M& m) {
  require(!m.hasNaN());
}
void require_quantile(const std::optional<double>& q) {
  if (q) require(!std::isnan(*q) && *q >= 0);
}

template <class G>
void require_finite_fit(const bireg::RegressionResult<G>& fit, const std::vector<double>& t) {
  require(fit.geodesic.has_value());
  for (const double s : t)
    require(!std::isfinite(s) || (*fit.geodesic)(s).allFinite());
  require(fit.geodesic->body_velocity().allFinite());
  for (const auto& r : fit.residuals)
    require(r.allFinite());
}

// A defined covariance: finite, symmetric, positive semi-definite (the
// eigenvalues above -1e-9 of the largest: rounding of a PSD sandwich).
template <class G>
void check_covariance(const bireg::FitCovariance<G>& c, FuzzedDataProvider& in) {
  if (!c.defined()) {
    require_message(c.message);
    return;
  }
  const auto& m = c.endpoints;
  require(m.allFinite() && c.residual.allFinite());
  const double scale = m.cwiseAbs().maxCoeff();
  require((m - m.transpose()).cwiseAbs().maxCoeff() <= 1e-9 * scale + 1e-300);
  const auto eigen = bireg::symmetric_eigen(m);
  require(eigen.values.minCoeff() >= -1e-9 * scale);
  require(std::isfinite(c.degrees_of_freedom) && c.degrees_of_freedom > 0);

  const double at = number(in, 10.0);
  const double level = in.ConsumeBool() ? 0.95 : number(in, 1.0);
  const auto rule =
      in.ConsumeBool() ? bireg::QuantileRule::chi_square : bireg::QuantileRule::small_sample;
  const auto velocity = bireg::velocity_covariance(c);
  const auto pose = bireg::pose_covariance(c, at);
  const auto prediction = bireg::prediction_covariance(c, at);
  require_no_nan(velocity);
  require_no_nan(pose);
  require_no_nan(prediction);
  const auto q_pose = bireg::pose_quantile(c, level, rule);
  require_quantile(bireg::endpoint_quantile(c, level, rule));
  require_quantile(bireg::velocity_quantile(c, level, rule));
  require_quantile(q_pose);
  require_quantile(bireg::prediction_quantile(c, level, rule));
  require_no_nan(bireg::half_widths(pose, q_pose ? *q_pose : number(in, 10.0)));
  typename G::Tangent v;
  for (int k = 0; k < G::dof; ++k)
    v[k] = number(in, 1.0);
  const double distance = bireg::mahalanobis_squared(velocity, v);
  require(!std::isnan(distance) && distance >= 0);
}

template <class G>
void exercise(FuzzedDataProvider& in, bireg::Solver solver) {
  const auto data = bireg_fuzz::data_set<G>(in, 32);
  const auto& f = data.observations;
  const auto& t = data.covariates;
  const auto& w = data.weights;
  typename bireg::GeodesicRegression<G>::Options options;
  options.solver = solver;
  options.max_iterations = 20;
  const bireg::GeodesicRegression<G> regression(options);

  // Iterations capped as the fit's: a mean of elements spread beyond its
  // region of uniqueness, or a GL+(3) fit far from the identity (whose
  // right Jacobian's inverse is a long series of 9 x 9 products), runs to
  // the cap, which costs 50-100x its time under the instrumentation.
  bireg::MeanOptions<double> mean_options;
  mean_options.max_iterations = 20;
  const auto m = bireg::mean<G>(f, w, mean_options);
  if (m.ok()) {
    require(m.mean && m.mean->allFinite());
    for (const auto& r : m.residuals)
      require(r.allFinite());
  } else {
    require_message(m.message);
  }

  const auto fit = regression.fit(f, t, w);
  if (fit.ok()) {
    require_finite_fit(fit, t);
    // Homoscedastic, robust, or a value outside the enumeration.
    const int flavour_value = in.ConsumeIntegralInRange(0, 2);
    const auto flavour =
        static_cast<bireg::CovarianceFlavour>(flavour_value == 2 ? 7 : flavour_value);
    const auto c = bireg::covariance(fit, t, w, flavour);
    if (c.status == bireg::CovarianceStatus::invalid_input) {
      require_message(c.message);
    } else {
      check_covariance(c, in);
    }
    if (m.ok()) {
      const auto r2 = bireg::explained_variance(fit, m, w);
      if (r2.defined) {
        require(std::isfinite(r2.euclidean) && std::isfinite(r2.generalized));
      } else {
        require_message(r2.message);
      }
    }
  } else if (fit.status == bireg::Status::invalid_input) {
    require_message(fit.message);  // fit()'s message is for refusals; a failure is its status
  }

  bireg::TrendTestOptions trend_options;
  trend_options.permutations = in.ConsumeIntegralInRange(0, 4);
  trend_options.seed = in.ConsumeIntegral<std::uint64_t>();
  const auto trend = bireg::trend_test(regression, f, t, w, trend_options);
  if (trend.ok()) {
    require(std::isfinite(trend.statistic) && trend.p_value > 0 && trend.p_value <= 1);
  } else {
    require_message(trend.message);
  }

  typename bireg::RobustGeodesicRegression<G>::Options robust_options;
  robust_options.loss = static_cast<bireg::Loss>(in.ConsumeIntegralInRange(0, 3));
  robust_options.loss_scale = in.ConsumeBool() ? 0.0 : number(in, 3.0);
  robust_options.max_rounds = in.ConsumeIntegralInRange(0, 8);
  const auto robust = bireg::RobustGeodesicRegression<G>(robust_options, options).fit(f, t, w);
  if (robust.ok()) {
    require_finite_fit(robust.fit, t);
    for (const double u : robust.robust_weights)
      require(std::isfinite(u));
  } else {
    require_message(robust.message);
  }

  // The first `split` observations against the rest.
  const auto split = in.ConsumeIntegralInRange<std::size_t>(0, f.size());
  const std::vector<typename G::Element> a(f.begin(), f.begin() + std::ptrdiff_t(split));
  const std::vector<typename G::Element> b(f.begin() + std::ptrdiff_t(split), f.end());
  bireg::TwoSampleOptions<double> two_sample_options;
  two_sample_options.permutations = in.ConsumeIntegralInRange(0, 4);
  two_sample_options.mean = mean_options;
  two_sample_options.statistic =
      static_cast<bireg::TwoSampleStatistic>(in.ConsumeIntegralInRange(0, 3));
  const auto two_sample = bireg::two_sample_test<G>(a, b, two_sample_options);
  if (two_sample.ok()) {
    require(std::isfinite(two_sample.value) && two_sample.p_value > 0 && two_sample.p_value <= 1);
    require(two_sample.mean_a && two_sample.mean_a->allFinite());
    require(two_sample.mean_b && two_sample.mean_b->allFinite());
  } else {
    require_message(two_sample.message);
  }
}

// The distributions at any arguments.
void exercise_quantiles(FuzzedDataProvider& in) {
  const double level = number(in, 1.0);
  const double p = number(in, 20.0);
  const double nu = number(in, 1e3);
  require_quantile(bireg::chi_square_quantile(level, p));
  require_quantile(bireg::f_quantile(level, p, nu));
  require_quantile(bireg::hotelling_quantile(level, p, nu));
  require_quantile(bireg::lawley_hotelling_quantile(level, p, number(in, 3.0), nu));
  require_quantile(bireg::ellipsoid_quantile(level, in.ConsumeIntegralInRange(-1, 20),
                                             in.ConsumeIntegralInRange(-1, 3), nu));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzedDataProvider in(data, size);
  const auto selector = in.ConsumeIntegral<std::uint8_t>();
  const auto solver = (selector & 2) ? bireg::Solver::paper : bireg::Solver::gauss_newton;
  if (selector & 1) {
    exercise<bireg::GLp<3, double>>(in, solver);
  } else {
    exercise<bireg::SE3<double>>(in, solver);
  }
  exercise_quantiles(in);
  return 0;
}
