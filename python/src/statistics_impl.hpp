// The statistics layer's work per group, for statistics.cpp's bindings:
// GroupStatistics<G> is instantiated once per group in
// statistics_rotations.cpp and statistics_matrices.cpp (explicitly, so
// that the two compile side by side and statistics.cpp instantiates none).
#pragma once

#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "fit_handle.hpp"

#include "bireg/statistics/inference/confidence.hpp"
#include "bireg/statistics/inference/covariance.hpp"
#include "bireg/statistics/inference/explained_variance.hpp"
#include "bireg/statistics/inference/mean.hpp"
#include "bireg/statistics/inference/trend_test.hpp"
#include "bireg/statistics/smoothing/local_regression.hpp"

namespace bireg_python {
namespace statistics_detail {

template <class G>
nb::dict mean_of(const Stack& y, const Vector& w, double tolerance, int max_iterations) {
  bireg::MeanOptions<double> options;
  options.tolerance = tolerance;
  options.max_iterations = max_iterations;
  const std::vector<double> weights = to_vector(w);
  bireg::MeanResult<G> result;
  {
    nb::gil_scoped_release release;
    result = bireg::mean<G>(StackView<G>(y), weights, options);
  }
  if (result.status == bireg::Status::invalid_input) refuse(result.message);
  nb::dict out;
  out["status"] = std::string(to_string(result.status));
  out["iterations"] = result.iterations;
  out["residual_norm"] = result.residual_norm;
  if (result.mean && result.mean->allFinite()) out["mean"] = matrix_array(*result.mean);
  out["residuals"] = tangent_rows<G>(result.residuals);
  return out;
}

// The weights of the fit's last solve: a robust fit's robust weights times
// the user's (the plug-in bireg_fit --loss --confidence uses), else the
// user's.
template <class G>
std::vector<double> statistics_weights(const GroupFit<G>& fit) {
  if (!fit.robust) return fit.weights;
  std::vector<double> w = fit.robust->robust_weights;
  for (std::size_t i = 0; i < fit.weights.size() && i < w.size(); ++i)
    w[i] *= fit.weights[i];
  return w;
}

inline bireg::CovarianceFlavour flavour_of(const std::string& name) {
  return parse_choice(name,
                      {bireg::CovarianceFlavour::homoscedastic, bireg::CovarianceFlavour::robust},
                      "covariance flavour");
}

template <class G>
bireg::FitCovariance<G> covariance_of(const GroupFit<G>& fit, bireg::CovarianceFlavour flavour) {
  fit.require_observations("covariance");
  bireg::FitCovariance<G> c;
  {
    nb::gil_scoped_release release;
    c = bireg::covariance(fit.result, fit.covariates, statistics_weights(fit), flavour);
  }
  if (!c.defined()) refuse("covariance: " + c.message);
  return c;
}

template <class G>
nb::dict covariance_dict(const GroupFit<G>& fit, const std::string& flavour) {
  const bireg::FitCovariance<G> c = covariance_of(fit, flavour_of(flavour));
  const typename G::AdMatrix velocity = bireg::velocity_covariance(c);
  nb::dict out;
  out["flavour"] = std::string(to_string(c.flavour));
  out["endpoints"] = matrix_array(c.endpoints);
  out["start"] = matrix_array(c.endpoints.template topLeftCorner<G::dof, G::dof>().eval());
  out["end"] = matrix_array(c.endpoints.template bottomRightCorner<G::dof, G::dof>().eval());
  out["velocity"] = matrix_array(velocity);
  out["velocity_standard_errors"] = vector_array(bireg::standard_errors(velocity));
  out["residual"] = matrix_array(c.residual);
  out["degrees_of_freedom"] = c.degrees_of_freedom;
  nb::dict effective;
  effective["endpoints"] = c.effective.endpoints;
  effective["start"] = c.effective.start;
  effective["end"] = c.effective.end;
  effective["velocity"] = c.effective.velocity;
  out["effective_degrees_of_freedom"] = effective;
  return out;
}

// Per covariate, the half-widths of the pose's `level` confidence region
// along each body-frame coordinate (pose_covariance, pose_quantile).
template <class G>
Output confidence_band(const GroupFit<G>& fit, const Vector& t, double level,
                       const std::string& flavour) {
  fit.require_observations("confidence_band");
  if (!(level > 0 && level < 1)) refuse("confidence_band: level must lie in (0, 1)");
  const bireg::FitCovariance<G> c = covariance_of(fit, flavour_of(flavour));
  const std::optional<double> q = bireg::pose_quantile(c, level);
  if (!q) refuse("confidence_band: too few degrees of freedom for a quantile at this level");
  check_covariates(t, "confidence_band");
  std::vector<typename G::Tangent> rows(t.shape(0));
  for (std::size_t i = 0; i < rows.size(); ++i)
    rows[i] = bireg::half_widths(bireg::pose_covariance(c, t.data()[i]), *q);
  return tangent_rows<G>(rows);
}

// The generalised explained variance 1 - det(S_res)/det(S_tot) of the
// fitted geodesic on (t, y): residuals about the geodesic against those
// about y's bi-invariant mean.
template <class G>
double score(const GroupFit<G>& fit, const Vector& t, const Stack& y) {
  if (!fit.result.ok() || !fit.result.geodesic) refuse("score: the fit did not succeed");
  if (t.shape(0) != y.shape(0))
    refuse("score: t and Y differ in length (" + std::to_string(t.shape(0)) + " vs " +
           std::to_string(y.shape(0)) + ")");
  const StackView<G> poses(y);
  const bireg::Geodesic<G>& geodesic = *fit.result.geodesic;
  std::vector<typename G::Tangent> residuals(poses.size());
  bireg::MeanResult<G> mean;
  {
    nb::gil_scoped_release release;
    mean = bireg::mean<G>(poses);
    for (std::size_t i = 0; i < poses.size(); ++i)
      residuals[i] = bireg::log_at<G>(geodesic(t.data()[i]), poses[i]);
  }
  if (!mean.ok()) refuse("score: the mean of Y did not converge: " + mean.message);
  for (std::size_t i = 0; i < residuals.size(); ++i)
    if (!residuals[i].allFinite())
      refuse("score: observation " + std::to_string(i) + " has no residual about the geodesic");
  const auto e = bireg::explained_variance(residuals, mean.residuals);
  if (!e.defined) refuse("score: " + e.message);
  return e.generalized;
}

template <class G>
nb::dict trend_test(const GroupFit<G>& fit, int permutations, std::uint64_t seed, int threads) {
  fit.require_observations("trend_test");
  if (fit.robust)
    refuse(
        "trend_test: not available for a robust fit (the permuted fits would need the "
        "robust reweighting); fit without loss=");
  bireg::TrendTestOptions options;
  options.permutations = permutations;
  options.seed = seed;
  options.threads = threads;
  bireg::TrendTestResult<G> r;
  {
    nb::gil_scoped_release release;
    r = bireg::trend_test(bireg::GeodesicRegression<G>(fit.options), fit.observations(),
                          fit.covariates, fit.weights, options);
  }
  if (!r.ok()) refuse("trend_test: " + r.message);
  nb::dict out;
  out["statistic"] = r.statistic;
  out["p_value"] = r.p_value;
  out["permutations"] = r.permutations;
  out["at_least_as_extreme"] = r.at_least_as_extreme;
  out["failed_permutations"] = r.failed_permutations;
  out["rank"] = r.rank;
  out["message"] = r.message;
  return out;
}

// Local regression at the queries: per query its pose, body velocity (per
// covariate unit), the velocity's standard errors, status and message.
template <class G>
nb::dict smooth(const Vector& t, const Stack& y, const Vector& queries,
                const bireg::LocalRegressionOptions<double>& options, double velocity_bandwidth,
                int velocity_degree) {
  const StackView<G> poses(y);
  const std::vector<double> covariates = to_vector(t), at = to_vector(queries);
  {
    const std::string why =
        bireg::LocalGeodesicRegression<G>(options).refusal(poses, covariates, at);
    if (!why.empty()) refuse(why);
  }
  std::vector<bireg::LocalEstimate<G>> estimates, velocities;
  {
    nb::gil_scoped_release release;
    estimates = bireg::LocalGeodesicRegression<G>(options).smooth_at(poses, covariates, at);
    if (velocity_bandwidth != options.bandwidth || velocity_degree != options.velocity_degree) {
      bireg::LocalRegressionOptions<double> velocity_options = options;
      velocity_options.bandwidth = velocity_bandwidth;
      velocity_options.velocity_degree = velocity_degree;
      velocities =
          bireg::LocalGeodesicRegression<G>(velocity_options).smooth_at(poses, covariates, at);
    }
  }
  const std::vector<bireg::LocalEstimate<G>>& v = velocities.empty() ? estimates : velocities;
  const std::size_t count = at.size(), n = std::size_t(side<G>());
  NewArray pose({count, n, n});
  std::vector<typename G::Tangent> velocity(count), error(count);
  nb::list status, message;
  NewArray ok({count}), error_defined({count});
  for (std::size_t q = 0; q < count; ++q) {
    const bireg::LocalEstimate<G>& p = estimates[q];
    const bireg::LocalEstimate<G>& w = v[q];
    const bool good = p.ok() && w.ok();
    write_row_major(p.pose, pose.data() + q * n * n);
    velocity[q] = w.velocity;
    error[q] = w.velocity_error;  // zero where undefined
    error_defined.data()[q] = w.velocity_error_defined ? 1 : 0;
    ok.data()[q] = good ? 1 : 0;
    const bireg::LocalEstimate<G>& bad = p.ok() ? w : p;
    status.append(std::string(good ? "ok" : to_string(bad.status)));
    message.append(good ? std::string() : bad.message);
  }
  nb::dict out;
  out["pose"] = pose.release();
  out["velocity"] = tangent_rows<G>(velocity);
  out["velocity_standard_error"] = tangent_rows<G>(error);
  out["velocity_standard_error_defined"] = error_defined.release();
  out["ok"] = ok.release();
  out["status"] = status;
  out["message"] = message;
  return out;
}

template <class G>
nb::dict select_bandwidth(const Vector& t, const Stack& y,
                          const bireg::LocalRegressionOptions<double>& options) {
  const std::vector<double> covariates = to_vector(t);
  bireg::BandwidthSelection<double> s;
  {
    nb::gil_scoped_release release;
    s = bireg::select_bandwidth<G>(StackView<G>(y), covariates, options,
                                   bireg::auto_bandwidth_grid(covariates));
  }
  if (!s.ok()) refuse("bandwidth auto: " + s.message);
  nb::dict out;
  out["bandwidth"] = s.bandwidth;
  out["velocity_bandwidth"] = s.velocity_bandwidth;
  out["velocity_degree"] = s.velocity_degree;
  out["grid"] = vector_array(s.grid);
  out["criterion"] = vector_array(s.criterion);
  out["velocity_criterion"] = vector_array(s.velocity_criterion);
  out["cubic_velocity_criterion"] = vector_array(s.cubic_velocity_criterion);
  out["message"] = s.message;
  return out;
}

inline bireg::LocalRegressionOptions<double> local_options(const std::string& kernel,
                                                           double bandwidth, int threads) {
  bireg::LocalRegressionOptions<double> options;
  options.kernel = parse_choice(
      kernel, {bireg::Kernel::gaussian, bireg::Kernel::epanechnikov, bireg::Kernel::tricube},
      "kernel");
  if (!(bandwidth > 0) || !std::isfinite(bandwidth))
    refuse("bandwidth must be a finite positive number or 'auto'");
  if (threads < 1) refuse("threads must be at least 1, got " + std::to_string(threads));
  options.bandwidth = bandwidth;
  options.threads = threads;
  return options;
}

}  // namespace statistics_detail

// Each function as the binding calls it, for group G.
template <class G>
struct GroupStatistics {
  static nb::dict mean(const Stack& y, const Vector& w, double tolerance, int max_iterations);
  static nb::dict covariance(const FitHandle& fit, const std::string& flavour);
  static Output confidence_band(const FitHandle& fit, const Vector& t, double level,
                                const std::string& flavour);
  static double score(const FitHandle& fit, const Vector& t, const Stack& y);
  static nb::dict trend_test(const FitHandle& fit, int permutations, std::uint64_t seed,
                             int threads);
  static nb::dict smooth(const Vector& t, const Stack& y, const Vector& queries,
                         const bireg::LocalRegressionOptions<double>& options,
                         double velocity_bandwidth, int velocity_degree);
  static nb::dict select_bandwidth(const Vector& t, const Stack& y,
                                   const bireg::LocalRegressionOptions<double>& options);
};

template <class G>
nb::dict GroupStatistics<G>::mean(const Stack& y, const Vector& w, double tolerance,
                                  int max_iterations) {
  return statistics_detail::mean_of<G>(y, w, tolerance, max_iterations);
}

template <class G>
nb::dict GroupStatistics<G>::covariance(const FitHandle& fit, const std::string& flavour) {
  return statistics_detail::covariance_dict(as_group_fit<G>(fit), flavour);
}

template <class G>
Output GroupStatistics<G>::confidence_band(const FitHandle& fit, const Vector& t, double level,
                                           const std::string& flavour) {
  return statistics_detail::confidence_band(as_group_fit<G>(fit), t, level, flavour);
}

template <class G>
double GroupStatistics<G>::score(const FitHandle& fit, const Vector& t, const Stack& y) {
  if (y.shape(1) != std::size_t(side<G>()) || y.shape(2) != std::size_t(side<G>()))
    refuse("score: Y's matrices do not match the fit's group");
  return statistics_detail::score(as_group_fit<G>(fit), t, y);
}

template <class G>
nb::dict GroupStatistics<G>::trend_test(const FitHandle& fit, int permutations, std::uint64_t seed,
                                        int threads) {
  return statistics_detail::trend_test(as_group_fit<G>(fit), permutations, seed, threads);
}

template <class G>
nb::dict GroupStatistics<G>::smooth(const Vector& t, const Stack& y, const Vector& queries,
                                    const bireg::LocalRegressionOptions<double>& options,
                                    double velocity_bandwidth, int velocity_degree) {
  return statistics_detail::smooth<G>(t, y, queries, options, velocity_bandwidth, velocity_degree);
}

template <class G>
nb::dict GroupStatistics<G>::select_bandwidth(
    const Vector& t, const Stack& y, const bireg::LocalRegressionOptions<double>& options) {
  return statistics_detail::select_bandwidth<G>(t, y, options);
}

// Instantiated in statistics_rotations.cpp and statistics_matrices.cpp only.
extern template struct GroupStatistics<bireg::SO2d>;
extern template struct GroupStatistics<bireg::SO3d>;
extern template struct GroupStatistics<bireg::SE2d>;
extern template struct GroupStatistics<bireg::SE3d>;
extern template struct GroupStatistics<bireg::Sim3d>;
extern template struct GroupStatistics<bireg::SL3<double>>;
extern template struct GroupStatistics<bireg::GLp<3, double>>;

}  // namespace bireg_python
