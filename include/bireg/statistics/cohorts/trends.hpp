// bireg: subjects' trends in a longitudinal study (docs/cohorts.md,
// "Trends"): one geodesic per subject on a shared covariate interval
// (fit_many), two cohorts' trends compared (compare_trends; at one
// covariate, compare_trends_at; their velocities, compare_velocities), and the
// population trend with its confidence region and each subject's distance
// from it (population_trend).
//
// Parts of the trends: the fitted elements at one covariate
// (compare_trends_at, fully invariant) and the body velocities
// (compare_velocities, invariant under translations).
//
// A subject's trend is the pair (gamma(t0), gamma(t1)) of its fitted
// geodesic at the ends of one interval [t0, t1] shared by all subjects: an
// element of G x G (Product<G, G>). Endpoints at each subject's own range
// would not be comparable (a subject seen from 0 to 1 and one seen from 2
// to 5 on the same line would have different endpoints). Translating or
// inverting all data moves each fit the same way (the paper's Theorem 2.4
// and its inverse counterpart), and so each trend by the same translation
// (g, g), (h, h) or inversion of G x G: the two-sample statistics of
// two_sample.hpp on G x G inherit their invariance.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/LU>

#include "bireg/geodesic.hpp"
#include "bireg/groups/product.hpp"
#include "bireg/groups/rn.hpp"
#include "bireg/regression.hpp"
#include "bireg/regression/parallel.hpp"
#include "bireg/statistics/cohorts/two_sample.hpp"
#include "bireg/statistics/inference/distributions.hpp"
#include "bireg/statistics/inference/mean.hpp"
#include "bireg/statistics/inference/scatter.hpp"

namespace bireg {

// One subject's observations and their covariates (equal lengths).
template <class G>
struct SubjectData {
  std::vector<typename G::Element> observations;
  std::vector<typename G::Scalar> covariates;
};

// A trend: (gamma(t0), gamma(t1)), an element of Product<G, G>.
template <class G>
using Trend = typename Product<G, G>::Element;

template <class Scalar>
struct FitManyOptions {
  // The shared interval [t0, t1]; both NaN (the default): from the
  // smallest to the largest covariate of all subjects.
  Scalar t0 = std::numeric_limits<Scalar>::quiet_NaN();
  Scalar t1 = std::numeric_limits<Scalar>::quiet_NaN();
  int threads = 1;  // subjects fitted at once (1 to kMaxThreads); the result does not depend on it
  // The index of subjects[0] in its cohort, when a block of a cohort is
  // fitted apart (bireg.dask): messages name subjects by their cohort index.
  std::size_t first_subject = 0;
};

template <class G>
struct FitManyResult {
  using Scalar = typename G::Scalar;
  // converged when every subject's fit succeeded; invalid_input when the
  // options or the interval are bad (message); otherwise the status of the
  // first subject whose fit failed, with `failed` counting them all and the
  // message naming the first.
  Status status = Status::invalid_input;
  std::string message;
  Scalar t0 = 0, t1 = 0;
  std::vector<RegressionResult<G>> fits;  // per subject, input order
  std::vector<Trend<G>> trends;           // per subject; meaningful where fits[i].ok()
  std::size_t failed = 0;

  bool ok() const { return is_success(status); }
};

// Fits one geodesic per subject with `regression`, each in its own
// covariates, and evaluates it at t0 and t1 (extrapolating beyond a
// subject's own range). No fit fails silently: a failed subject keeps its
// status and message in `fits`, and the result is not ok().
template <class G>
FitManyResult<G> fit_many(const GeodesicRegression<G>& regression,
                          const std::vector<SubjectData<G>>& subjects,
                          const FitManyOptions<typename G::Scalar>& options = {}) {
  using Scalar = typename G::Scalar;
  using std::isfinite;
  using std::isnan;
  FitManyResult<G> result;
  if (subjects.empty()) {
    result.message = "there are no subjects";
    return result;
  }
  if (options.threads < 1 || options.threads > kMaxThreads) {
    result.message = "threads must be 1 to " + std::to_string(kMaxThreads) + ", not " +
                     std::to_string(options.threads);
    return result;
  }
  Scalar t0 = options.t0, t1 = options.t1;
  if (isnan(t0) && isnan(t1)) {
    t0 = std::numeric_limits<Scalar>::infinity();
    t1 = -t0;
    for (const auto& subject : subjects) {
      for (const Scalar t : subject.covariates) {
        if (!isfinite(t)) continue;  // fit() names it below
        t0 = std::min(t0, t);
        t1 = std::max(t1, t);
      }
    }
  }
  if (!isfinite(t0) || !isfinite(t1) || !(t0 < t1)) {
    result.message =
        "the shared interval [t0, t1] must be finite with t0 < t1 (given or from "
        "the subjects' covariates), not [" +
        std::to_string(t0) + ", " + std::to_string(t1) + "]";
    return result;
  }
  result.t0 = t0;
  result.t1 = t1;
  const std::size_t count = subjects.size();
  result.fits.resize(count);
  result.trends.resize(count);
  // Subjects in tasks of kSubjectsPerTask: one claim per task, not per fit.
  constexpr std::size_t kSubjectsPerTask = 16;
  const std::size_t tasks = chunk_count(count, kSubjectsPerTask);
  const auto fit_task = [&](std::size_t task) {
    const std::size_t end = std::min(count, (task + 1) * kSubjectsPerTask);
    for (std::size_t i = task * kSubjectsPerTask; i < end; ++i) {
      RegressionResult<G>& fit = result.fits[i];
      fit = regression.fit(subjects[i].observations, subjects[i].covariates);
      if (fit.ok()) result.trends[i] = {(*fit.geodesic)(t0), (*fit.geodesic)(t1)};
    }
  };
  if (options.threads > 1 && tasks > 1) {
    ChunkPool(options.threads, tasks).run(tasks, fit_task);
  } else {
    for (std::size_t task = 0; task < tasks; ++task)
      fit_task(task);
  }
  result.status = Status::converged;
  for (std::size_t i = 0; i < count; ++i) {
    if (result.fits[i].ok()) continue;
    if (result.failed++ == 0) {
      result.status = result.fits[i].status;
      result.message = "subject " + std::to_string(options.first_subject + i) + ": " +
                       to_string(result.fits[i].status) +
                       (result.fits[i].message.empty() ? "" : ": " + result.fits[i].message);
    }
  }
  if (result.failed > 1) {
    result.message +=
        " (" + std::to_string(result.failed) + " of " + std::to_string(count) + " subjects failed)";
  }
  return result;
}

// Two cohorts' trends compared: two_sample_test on G x G, where Ad and the
// transport act blockwise (docs/cohorts.md, "Trends").
template <class G, class TrendsA, class TrendsB>
TwoSampleResult<Product<G, G>> compare_trends(
    const TrendsA& a, const TrendsB& b, const TwoSampleOptions<typename G::Scalar>& options = {}) {
  return two_sample_test<Product<G, G>>(a, b, options);
}

namespace trends_detail {

// Why [t0, t1] cannot carry trends, or empty.
template <class Scalar>
std::string interval_refusal(Scalar t0, Scalar t1) {
  using std::isfinite;
  if (isfinite(t0) && isfinite(t1) && t0 < t1) return {};
  return "the trends' interval [t0, t1] must be finite with t0 < t1, not [" + std::to_string(t0) +
         ", " + std::to_string(t1) + "]";
}

// f(trend) for every trend of `trends`, as a vector (what two_sample_test
// reads).
template <class Out, class Trends, class F>
std::vector<Out> each(const Trends& trends, F f) {
  std::vector<Out> out;
  out.reserve(trends.size());
  for (std::size_t i = 0; i < trends.size(); ++i)
    out.push_back(f(trends[i]));
  return out;
}

}  // namespace trends_detail

// The two cohorts' fitted elements at one covariate t (t = t0: the starts),
// gamma_k(t) = g0 exp(s log(g0^{-1} g1)), s = (t - t0) / (t1 - t0), from
// trends on [t0, t1], compared by two_sample_test on G: invariant under
// left and right translation, inversion and exchange (docs/cohorts.md,
// "The trends at one covariate"). t must be finite.
template <class G, class TrendsA, class TrendsB>
TwoSampleResult<G> compare_trends_at(const TrendsA& a, const TrendsB& b, typename G::Scalar t0,
                                     typename G::Scalar t1, typename G::Scalar t,
                                     const TwoSampleOptions<typename G::Scalar>& options = {}) {
  using std::isfinite;
  TwoSampleResult<G> refused;
  refused.message = trends_detail::interval_refusal(t0, t1);
  if (refused.message.empty() && !isfinite(t)) refused.message = "the covariate t is not finite";
  if (!refused.message.empty()) return refused;
  const auto at = [&](const Trend<G>& trend) {
    return Geodesic<G>(trend.first, trend.second, t0, t1)(t);
  };
  return two_sample_test<G>(trends_detail::each<typename G::Element>(a, at),
                            trends_detail::each<typename G::Element>(b, at), options);
}

// The two cohorts' body velocities v_k = log(g0^{-1} g1) / (t1 - t0) (per
// covariate unit, the same at every t of a geodesic), compared as vectors
// of the algebra by two_sample_test on R^d (the variant does not apply:
// Ad is the identity there). Invariant under left and right translation
// and exchange, not under inversion (docs/cohorts.md, "The velocities").
template <class G, class TrendsA, class TrendsB>
TwoSampleResult<Rn<G::dof, typename G::Scalar>> compare_velocities(
    const TrendsA& a, const TrendsB& b, typename G::Scalar t0, typename G::Scalar t1,
    const TwoSampleOptions<typename G::Scalar>& options = {}) {
  using Velocities = Rn<G::dof, typename G::Scalar>;
  TwoSampleResult<Velocities> refused;
  refused.message = trends_detail::interval_refusal(t0, t1);
  if (!refused.message.empty()) return refused;
  const auto velocity = [&](const Trend<G>& trend) -> typename G::Tangent {
    return Geodesic<G>(trend.first, trend.second, t0, t1).body_velocity();
  };
  return two_sample_test<Velocities>(trends_detail::each<typename G::Tangent>(a, velocity),
                                     trends_detail::each<typename G::Tangent>(b, velocity),
                                     options);
}

template <class Scalar>
struct PopulationOptions {
  Scalar level = Scalar(0.95);  // of the confidence region for the population trend
  // A subject is flagged when its squared Mahalanobis distance from the
  // population exceeds the `outlier_level` quantile of its distribution
  // for a subject of the population (each subject on its own: about
  // (1 - outlier_level) n flags are expected among n typical subjects).
  Scalar outlier_level = Scalar(0.999);
  MeanOptions<Scalar> mean;
};

template <class G>
struct PopulationTrend {
  using Scalar = typename G::Scalar;
  using Pair = Product<G, G>;
  using PairCovariance = typename Pair::AdMatrix;
  // converged: computed; invalid_input: refused (message); another status:
  // the mean failed (message).
  Status status = Status::invalid_input;
  std::string message;
  std::size_t subjects = 0;
  std::optional<Trend<G>> mean;  // the bi-invariant mean of the trends in G x G
  // S = sum y y^T / (n - 1), y_i = log(mean^{-1} trend_i) in G x G: the
  // between-subject covariance (G's coordinates at t0 first).
  PairCovariance covariance = PairCovariance::Zero();
  // The mean's covariance, S / n, and the confidence region for the
  // population trend: the trends m exp(delta) with
  // n delta^T S^{-1} delta <= radius_squared (Hotelling's T^2 quantile,
  // dimension 2d, n - 1 degrees of freedom: exact for Gaussian
  // coordinates, first order in the group).
  PairCovariance mean_covariance = PairCovariance::Zero();
  Scalar radius_squared = 0;
  // The population's body velocity per covariate unit, log(m0^{-1} m1) /
  // (t1 - t0), and its covariance by the delta method.
  typename G::Tangent velocity = G::Tangent::Zero();
  typename G::AdMatrix velocity_covariance = G::AdMatrix::Zero();
  // Per subject: y_i^T S^{-1} y_i, and whether it exceeds the outlier
  // threshold (outlier_threshold, from the Beta distribution of that
  // distance for a subject of the population).
  std::vector<Scalar> mahalanobis_squared;
  std::vector<bool> outlying;
  Scalar outlier_threshold = 0;

  bool ok() const { return is_success(status); }

  // Whether `trend` lies in the confidence region.
  bool contains(const Trend<G>& trend) const {
    if (!ok()) return false;
    const typename Pair::Tangent delta = Pair::log(Pair::compose(Pair::inverse(*mean), trend));
    const Scalar n = static_cast<Scalar>(subjects);
    return n * delta.dot(covariance.ldlt().solve(delta)) <= radius_squared;
  }
};

// The population trend of subjects' trends (fit_many's, on [t0, t1]): the
// two-stage model, in which each subject's trend is the population's moved
// by its own deviation plus its fit's error, both independent between
// subjects; S estimates their sum. Needs n > 2d + 1 subjects (d = G::dof)
// for S to be invertible and the outlier distribution to exist.
template <class G, class Trends>
PopulationTrend<G> population_trend(const Trends& trends, typename G::Scalar t0,
                                    typename G::Scalar t1,
                                    const PopulationOptions<typename G::Scalar>& options = {}) {
  using Scalar = typename G::Scalar;
  using Pair = Product<G, G>;
  using std::isfinite;
  PopulationTrend<G> result;
  const std::size_t n = trends.size();
  const std::size_t p = static_cast<std::size_t>(Pair::dof);
  result.subjects = n;
  if (!(options.level > 0 && options.level < 1) ||
      !(options.outlier_level > 0 && options.outlier_level < 1)) {
    result.message = "level and outlier_level must lie strictly between 0 and 1";
    return result;
  }
  if (!isfinite(t0) || !isfinite(t1) || !(t0 < t1)) {
    result.message = "the interval [t0, t1] must be finite with t0 < t1";
    return result;
  }
  if (n < p + 2) {
    result.message = "the population trend of " + std::string(G::name) + " trends (dimension " +
                     std::to_string(p) + " in G x G) needs at least " + std::to_string(p + 2) +
                     " subjects; there are " + std::to_string(n);
    return result;
  }
  const MeanResult<Pair> mean = bireg::mean<Pair>(trends, {}, options.mean);
  if (!mean.ok()) {
    result.status = mean.status;
    result.message = mean.message;
    return result;
  }
  result.mean = *mean.mean;
  result.covariance = scatter_matrix(mean.residuals, {}) / static_cast<Scalar>(n - 1);
  if (!two_sample_detail::log_determinant(result.covariance)) {
    result.message = "the subjects' trends span fewer than " + std::to_string(p) +
                     " directions of G x G: their covariance is singular";
    return result;
  }
  result.mean_covariance = result.covariance / static_cast<Scalar>(n);
  const auto radius = hotelling_quantile(double(options.level), double(p), double(n - 1));
  // Subject i of the population: n d_i^2 / (n - 1)^2 ~ Beta(p/2, (n-p-1)/2),
  // and B ~ Beta(a, b) has (b / a) B / (1 - B) ~ F(2a, 2b).
  const auto f = f_quantile(double(options.outlier_level), double(p), double(n - p - 1));
  if (!radius || !f) {
    result.message =
        "the Hotelling or F quantile could not be computed for n = " + std::to_string(n) +
        ", dimension " + std::to_string(p);
    return result;
  }
  result.radius_squared = static_cast<Scalar>(*radius);
  const Scalar ratio = Scalar(p) / Scalar(n - p - 1) * static_cast<Scalar>(*f);
  const Scalar beta = ratio / (1 + ratio);
  result.outlier_threshold = beta * Scalar(n - 1) * Scalar(n - 1) / static_cast<Scalar>(n);
  const auto solver = result.covariance.ldlt();
  for (const auto& y : mean.residuals) {
    const Scalar d2 = y.dot(solver.solve(y));
    result.mahalanobis_squared.push_back(d2);
    result.outlying.push_back(d2 > result.outlier_threshold);
  }
  // Velocity: X = log(m0^{-1} m1). Moving m0 to m0 exp(e0) and m1 to
  // m1 exp(e1) moves X by J_r^{-1}(X) e1 - J_r^{-1}(-X) e0 to first order
  // (mean.hpp's linearisation, from either end).
  const typename G::Tangent x =
      G::log(G::compose(G::inverse(result.mean->first), result.mean->second));
  const Scalar span = t1 - t0;
  result.velocity = x / span;
  Eigen::Matrix<Scalar, G::dof, Pair::dof> derivative;
  derivative.template leftCols<G::dof>() = -right_jacobian_inverse<G>(-x);
  derivative.template rightCols<G::dof>() = right_jacobian_inverse<G>(x);
  result.velocity_covariance =
      derivative * result.mean_covariance * derivative.transpose() / (span * span);
  result.status = Status::converged;
  return result;
}

}  // namespace bireg
